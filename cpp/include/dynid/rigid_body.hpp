// The ten standard inertial parameters of one rigid body (notes, "Dynamic parameters of robots 3"):
// pi = [m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz], (mx, my, mz) = m * r_c and the inertia
// tensor taken about the ORIGIN of the frame the body is described in.
#pragma once

#include <string>

#include "dynid/types.hpp"

namespace dynid {

struct RigidBodyParameters {
  double m = 0.0;
  Vector3 h = Vector3::Zero();  // first moment m * r_c
  Matrix3 I = Matrix3::Zero();  // second moment about the frame origin

  static RigidBodyParameters from_standard(const double* pi10);
  void to_standard(double* pi10) const;

  // Physical form: mass, centre of mass and inertia about the centre of mass, all in the
  // frame's axes; Steiner's theorem I = I_c + m (|r|^2 E - r r^T) (notes, "Dynamic parameters 2").
  static RigidBodyParameters from_physical(double mass, const Vector3& com,
                                           const Matrix3& inertia_com);

  // The same body described in frame A, when these parameters are about frame B and
  // x_A = R x_B + p. Linear in (m, h, I): rotation plus the generalised Steiner terms.
  RigidBodyParameters expressed_in_parent(const Matrix3& R, const Vector3& p) const;

  // Inertia about the centre of mass (inverse Steiner); requires m != 0.
  Matrix3 inertia_about_com() const;

  RigidBodyParameters& operator+=(const RigidBodyParameters& other) {
    m += other.m;
    h += other.h;
    I += other.I;
    return *this;
  }
};

// Why a body with this mass and inertia about its centre of mass cannot exist ("" when it can):
// m > 0, inertia symmetric and positive definite, principal moments obeying the triangle
// inequalities.
std::string physical_inconsistency(double mass, const Matrix3& inertia_com);

// The same for a body given by its standard parameters (about any frame origin): its inertia is
// moved to the centre of mass first (inverse Steiner), which needs m > 0.
std::string physical_inconsistency(const RigidBodyParameters& body);

}  // namespace dynid
