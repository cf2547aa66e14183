// Internal (dynid::detail, not API): one joint of a DH chain in the form every algorithm uses:
//   frame J_i = J_{i-1} * Rx(alpha) Tx(a) * Rz(theta) Tz(d)
// i.e. the modified (Craig) transform. A standard-DH chain is brought to this form by the
// model (Rx and Tx commute, so Tx(a_{i-1}) Rx(alpha_{i-1}) of row i-1 becomes the constant part of
// joint i). The joint always acts along z of its own frame, which keeps every projection onto
// the joint axis a single component read.
#pragma once

#include <cmath>

#include "dynid/types.hpp"

namespace dynid::detail {

// x_parent = R x_child + p with R = Rx(alpha) Rz(theta), p = Rx(alpha) (a, 0, d).
struct JointTransform {
  double ca = 1.0, sa = 0.0;  // cos/sin alpha (constant)
  double ct = 1.0, st = 0.0;  // cos/sin theta (joint dependent for revolute joints)
  double d = 0.0;             // joint dependent for prismatic joints
  Vector3 p = Vector3::Zero();

  void set(double cos_alpha, double sin_alpha, double a, double theta, double d);
  // The same with cos/sin theta already computed.
  void set(double cos_alpha, double sin_alpha, double a, double cos_theta, double sin_theta,
           double d_value) {
    ca = cos_alpha;
    sa = sin_alpha;
    ct = cos_theta;
    st = sin_theta;
    d = d_value;
    p = Vector3(a, -sa * d, ca * d);
  }

  // R x: Rz(theta) first, then Rx(alpha).
  Vector3 rotate_to_parent(const Vector3& x) const {
    const double y0 = ct * x.x() - st * x.y();
    const double y1 = st * x.x() + ct * x.y();
    return Vector3(y0, ca * y1 - sa * x.z(), sa * y1 + ca * x.z());
  }
  // R^T x: Rx(-alpha) first, then Rz(-theta).
  Vector3 rotate_to_child(const Vector3& x) const {
    const double y1 = ca * x.y() + sa * x.z();
    const double y2 = -sa * x.y() + ca * x.z();
    return Vector3(ct * x.x() + st * y1, -st * x.x() + ct * y1, y2);
  }
};

inline void JointTransform::set(double cos_alpha, double sin_alpha, double a, double theta,
                                double d_value) {
  ca = cos_alpha;
  sa = sin_alpha;
  ct = std::cos(theta);
  st = std::sin(theta);
  d = d_value;
  p = Vector3(a, -sa * d, ca * d);
}

}  // namespace dynid::detail
