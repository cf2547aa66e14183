// Internal (dynid::detail, not API): the constant geometry the Model derives from its DH table
// for the algorithms (model.cpp): each joint in the modified form of joint_transform.hpp, and
// where each link's DH frame sits relative to its joint frame.
#pragma once

#include "dynid/types.hpp"

namespace dynid::detail {

// DH frame i relative to joint frame J_i: Tx(a) Rx(alpha) (standard DH), identity (modified).
struct LinkOffset {
  bool identity = true;
  double cos_alpha = 1.0, sin_alpha = 0.0, a = 0.0;

  Matrix3 rotation() const {  // Rx(alpha)
    Matrix3 R;
    R << 1.0, 0.0, 0.0, 0.0, cos_alpha, -sin_alpha, 0.0, sin_alpha, cos_alpha;
    return R;
  }
  Vector3 translation() const { return Vector3(a, 0.0, 0.0); }

  // Rx(alpha)^T x: a vector of J_i in the axes of DH frame i.
  Vector3 rotate_to_link(const Vector3& x) const {
    return Vector3(x.x(), cos_alpha * x.y() + sin_alpha * x.z(),
                   -sin_alpha * x.y() + cos_alpha * x.z());
  }
};

// Constant part of joint i in the modified form used by the algorithms (joint_transform.hpp).
struct JointGeometry {
  double cos_alpha = 1.0, sin_alpha = 0.0, a = 0.0;
  double theta = 0.0, d = 0.0;  // offsets to which q adds
  bool revolute = true;
};

}  // namespace dynid::detail
