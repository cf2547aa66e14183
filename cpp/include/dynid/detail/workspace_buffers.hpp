// Internal (dynid::detail, not API): the buffers behind a Workspace. The algorithms write them
// during a call and nothing in them is meaningful between calls; callers hold a Workspace, whose
// only public members are its constructor and n(), and never see these fields.
#pragma once

#include <Eigen/Cholesky>
#include <vector>

#include "dynid/detail/derivative_buffers.hpp"
#include "dynid/detail/joint_transform.hpp"
#include "dynid/detail/time_derivative_buffers.hpp"
#include "dynid/rigid_body.hpp"
#include "dynid/types.hpp"

namespace dynid::detail {

struct WorkspaceBuffers {
  explicit WorkspaceBuffers(int joints);

  // Per-link arrays hold n + 1 entries: index 0 is the base (frame 0), index i is link i
  // (1-based, as in the notes); X[i] is joint i.
  int n;
  // Joint transforms J_{i-1} -> J_i at the current q (detail/kinematics.hpp).
  std::vector<JointTransform> X;

  // Newton-Euler recursion, all in the joint frames J_i: angular velocity and acceleration,
  // linear velocity and acceleration of the frame origin, force and moment (about the origin)
  // that link i-1 exerts on link i.
  std::vector<Vector3> omega, omegad, v, a, f, mu;

  // World poses of the joint frames (rotation, origin).
  std::vector<Matrix3> R_world;
  std::vector<Vector3> p_world;

  // CRBA: composite bodies in the joint frames (mass, first moment, the six entries of the
  // symmetric inertia xx, xy, xz, yy, yz, zz about the frame origin).
  struct Composite {
    double m;
    Vector3 h;
    double I[6];
  };
  std::vector<Composite> composite;

  // Coriolis matrix (coriolis_matrix.cpp): world-frame joint axes (motion subspaces) and their
  // time derivatives, and per link the sums over the outboard links of the spatial inertias and
  // of the Coriolis factors' non-zero blocks (a 3x3 block and a momentum vector).
  std::vector<Vector6> axis_world, axis_world_dot;
  std::vector<RigidBodyParameters> inertia_sum;
  std::vector<Matrix3> coriolis_block_sum;
  std::vector<Vector3> momentum_sum;
  std::vector<Vector6> column_wrench, row_inertia;
  std::vector<Vector3> row_coriolis;

  // Regressors: the joint axes i <= j as spatial motion vectors [s; l] in the frame of link j's
  // parameters.
  std::vector<Vector6> axes;

  // Forward dynamics and scratch.
  VectorX zeros;  // n zeros, for the recursions called without velocity or acceleration
  MatrixX M;
  VectorX bias;
  Eigen::LLT<MatrixX> cholesky;

  // Analytic derivatives (rnea_derivatives.cpp).
  DerivativeBuffers derivatives;

  // Time derivatives of inverse dynamics (rnea_time_derivatives.cpp).
  TimeDerivativeBuffers time_derivatives;
};

}  // namespace dynid::detail
