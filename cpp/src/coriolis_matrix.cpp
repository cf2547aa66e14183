// Christoffel-consistent Coriolis matrix without differentiating M (Echeandia & Wensing, "A
// numerical method for computing the Coriolis matrix and Christoffel symbols for rigid-body
// systems", 2021). With world-frame spatial quantities ([angular; linear] about the world origin):
//   S = sum_i J_i^T (B_i J_i + I_i Jdot_i),  B_i = 1/2 [ (v_i x*) I_i - I_i (v_i x) + (I_i v_i) xbar ]
// where J_i's columns are the joint axes S_k (k <= i), Jdot_i's are Sdot_k = v_k x S_k and
// (f xbar) m = m x* f. Because every term of body i only involves joints k <= i, entry (j, k)
// needs the sums of B_i and I_i over the links outboard of max(j, k).
#include "dynid/coriolis_matrix.hpp"

#include "dynid/kinematics.hpp"

namespace dynid {
namespace {

// v x (motion cross product) for v = [w; u].
Matrix6 motion_cross(const Vector6& v) {
  Matrix6 X = Matrix6::Zero();
  const Matrix3 w = skew(v.head<3>());
  X.topLeftCorner<3, 3>() = w;
  X.bottomLeftCorner<3, 3>() = skew(v.tail<3>());
  X.bottomRightCorner<3, 3>() = w;
  return X;
}

// f xbar for f = [n; f]: the matrix with (f xbar) m = m x* f.
Matrix6 force_cross_bar(const Vector6& f) {
  Matrix6 X = Matrix6::Zero();
  const Matrix3 fl = skew(f.tail<3>());
  X.topLeftCorner<3, 3>() = -skew(f.head<3>());
  X.topRightCorner<3, 3>() = -fl;
  X.bottomLeftCorner<3, 3>() = -fl;
  return X;
}

Matrix6 spatial_inertia(const RigidBodyParameters& b) {
  Matrix6 I6;
  const Matrix3 h = skew(b.h);
  I6.topLeftCorner<3, 3>() = b.I;
  I6.topRightCorner<3, 3>() = h;
  I6.bottomLeftCorner<3, 3>() = h.transpose();
  I6.bottomRightCorner<3, 3>() = b.m * Matrix3::Identity();
  return I6;
}

}  // namespace

void coriolis_matrix(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
                     MatrixOut S) {
  const int n = ws.n;
  update_joint_transforms(model, ws, q);
  update_world_frames(model, ws);

  ws.body_velocity[0].setZero();
  for (int i = 1; i <= n; ++i) {
    const Vector3 z = ws.R_world[i].col(2);
    if (model.joint(i - 1).revolute)
      ws.S[i] << z, ws.p_world[i].cross(z);
    else
      ws.S[i] << Vector3::Zero(), z;
    ws.body_velocity[i] = ws.body_velocity[i - 1] + ws.S[i] * qd[i - 1];
    ws.Sdot[i] = motion_cross(ws.body_velocity[i]) * ws.S[i];

    const Matrix6 I6 =
        spatial_inertia(model.body(i - 1).expressed_in_parent(ws.R_world[i], ws.p_world[i]));
    const Vector6& v = ws.body_velocity[i];
    const Matrix6 vx = motion_cross(v);
    // (v x*) = -(v x)^T
    ws.coriolis_sum[i] = 0.5 * (-vx.transpose() * I6 - I6 * vx + force_cross_bar(I6 * v));
    ws.inertia_sum[i] = I6;
  }
  for (int i = n - 1; i >= 1; --i) {
    ws.coriolis_sum[i] += ws.coriolis_sum[i + 1];
    ws.inertia_sum[i] += ws.inertia_sum[i + 1];
  }

  for (int i = 1; i <= n; ++i) {
    ws.column_wrench[i] = ws.coriolis_sum[i] * ws.S[i] + ws.inertia_sum[i] * ws.Sdot[i];
    ws.row_coriolis[i] = ws.coriolis_sum[i].transpose() * ws.S[i];
    ws.row_inertia[i] = ws.inertia_sum[i] * ws.S[i];
  }
  for (int j = 1; j <= n; ++j) {
    for (int k = 1; k <= n; ++k) {
      S(j - 1, k - 1) = j <= k ? ws.S[j].dot(ws.column_wrench[k])
                               : ws.row_coriolis[j].dot(ws.S[k]) + ws.row_inertia[j].dot(ws.Sdot[k]);
    }
  }
}

}  // namespace dynid
