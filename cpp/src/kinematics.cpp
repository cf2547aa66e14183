#include "dynid/kinematics.hpp"

#include <algorithm>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/batch.hpp"
#include "dynid/detail/kinematics.hpp"

namespace dynid {
namespace detail {

void update_joint_transforms(const Model& model, WorkspaceBuffers& ws, const VectorIn& q) {
  // All joint angles' sin and cos in one vectorised call (detail::sincos_many: SIMD lanes, a few
  // ulp) instead of one libm call per joint, which costs as much as the rest of a small kernel.
  constexpr int kChunk = 16;
  double angle[kChunk], s[kChunk], c[kChunk];
  for (int first = 1; first <= ws.n; first += kChunk) {
    const int last = std::min(ws.n, first + kChunk - 1);
    for (int i = first; i <= last; ++i) {
      const JointGeometry& j = model.joint(i - 1);
      angle[i - first] = j.revolute ? q[i - 1] + j.theta : j.theta;
    }
    sincos_many(angle, s, c, last - first + 1);
    for (int i = first; i <= last; ++i) {
      const JointGeometry& j = model.joint(i - 1);
      const double d = j.revolute ? j.d : q[i - 1] + j.d;
      ws.X[i].set(j.cos_alpha, j.sin_alpha, j.a, c[i - first], s[i - first], d);
    }
  }
}

void update_world_frames(const Model& model, WorkspaceBuffers& ws) {
  ws.R_world[0] = model.base().topLeftCorner<3, 3>();
  ws.p_world[0] = model.base().topRightCorner<3, 1>();
  for (int i = 1; i <= ws.n; ++i) {
    const JointTransform& X = ws.X[i];
    const Matrix3& P = ws.R_world[i - 1];
    Matrix3& R = ws.R_world[i];
    ws.p_world[i] = ws.p_world[i - 1] + P * X.p;
    // R = P Rx(alpha) Rz(theta), as two plane rotations of P's columns.
    const Vector3 c1 = X.ca * P.col(1) + X.sa * P.col(2);
    R.col(2) = -X.sa * P.col(1) + X.ca * P.col(2);
    R.col(0) = X.ct * P.col(0) + X.st * c1;
    R.col(1) = -X.st * P.col(0) + X.ct * c1;
  }
}

namespace {

Matrix4 tool_pose(const Model& model, const WorkspaceBuffers& ws) {
  Matrix4 flange = Matrix4::Identity();
  flange.topLeftCorner<3, 3>() = ws.R_world[ws.n];
  flange.topRightCorner<3, 1>() = ws.p_world[ws.n];
  return flange * model.flange_to_tool();
}

}  // namespace
}  // namespace detail

void fkine(const Model& model, Workspace& workspace, const VectorIn& q, MatrixOut T) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_SHAPE(T, 4, 4);
  detail::update_joint_transforms(model, ws, q);
  detail::update_world_frames(model, ws);
  T = detail::tool_pose(model, ws);
}

void link_frames(const Model& model, Workspace& workspace, const VectorIn& q, RowMajorOut frames) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_SHAPE(frames, model.n(), 16);
  detail::update_joint_transforms(model, ws, q);
  detail::update_world_frames(model, ws);
  for (int i = 1; i <= ws.n; ++i) {
    // DH frame i = J_i * link_offset(i) (model.hpp): Tx(a_i) Rx(alpha_i) for standard DH.
    const detail::LinkOffset& offset = model.link_offset(i - 1);
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> pose(frames.row(i - 1).data());
    pose.topLeftCorner<3, 3>() = ws.R_world[i] * offset.rotation();
    pose.topRightCorner<3, 1>() = ws.p_world[i] + ws.R_world[i] * offset.translation();
    pose.row(3) << 0.0, 0.0, 0.0, 1.0;
  }
}

void jacobian(const Model& model, Workspace& workspace, const VectorIn& q, MatrixOut J) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_SHAPE(J, 6, model.n());
  detail::update_joint_transforms(model, ws, q);
  detail::update_world_frames(model, ws);
  const Vector3 tool_point = detail::tool_pose(model, ws).topRightCorner<3, 1>();
  for (int i = 1; i <= ws.n; ++i) {
    // Joint i acts along z of J_i (joint_transform.hpp).
    const Vector3 z = ws.R_world[i].col(2);
    if (model.joint(i - 1).revolute) {
      J.col(i - 1).head<3>() = z.cross(tool_point - ws.p_world[i]);
      J.col(i - 1).tail<3>() = z;
    } else {
      J.col(i - 1).head<3>() = z;
      J.col(i - 1).tail<3>().setZero();
    }
  }
}

}  // namespace dynid
