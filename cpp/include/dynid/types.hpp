// Fixed-size Eigen types used across dynid, and the small 3-D helpers the algorithms share.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynid {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Matrix4 = Eigen::Matrix4d;
using VectorX = Eigen::VectorXd;
using MatrixX = Eigen::MatrixXd;

// Inputs are read through Ref so that NumPy rows (Map) and Eigen vectors pass without copies.
using VectorIn = Eigen::Ref<const VectorX>;
using VectorOut = Eigen::Ref<VectorX>;
// Matrix outputs take any strides, so row-major NumPy blocks are written in place.
using MatrixOut = Eigen::Ref<MatrixX, 0, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;
// Regressors are written row by row (one joint's row holds its 1 x 10 blocks contiguously).
using RowMajorMatrixX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMajorOut = Eigen::Ref<RowMajorMatrixX>;

// S(v) of the notes: skew(v) * x == v.cross(x).
inline Matrix3 skew(const Vector3& v) {
  Matrix3 s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

}  // namespace dynid
