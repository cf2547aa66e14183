// Christoffel-consistent Coriolis matrix without differentiating M (Echeandia & Wensing, "A
// numerical method for computing the Coriolis matrix and Christoffel symbols for rigid-body
// systems", 2021). With world-frame spatial quantities ([angular; linear] about the world origin):
//   S = sum_i J_i^T (B_i J_i + I_i Jdot_i),  B_i = 1/2 [ (v_i x*) I_i - I_i (v_i x) + (I_i v_i)
//   xbar ]
// where J_i's columns are the joint axes S_k (k <= i), Jdot_i's are Sdot_k = v_k x S_k and
// (f xbar) m = m x* f. Because body i only involves joints k <= i, entry (j, k) needs only the
// sums of B_i and I_i over the links outboard of max(j, k).
//
// Writing I = [[Ib, h^], [h^T, m E]] and v = [w; u], the 6x6 factor reduces to
//   B = [[T, 0], [-f^, 0]],  T = 1/2 [A + A^T - (h u^T + u h^T) + 2 (u.h) E - n^],  A = w^ Ib,
// with n = Ib w + h x u and f = w x h + m u the body's angular and linear momentum: only a 3x3
// block and a vector are summed per link.
#include "dynid/coriolis_matrix.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/kinematics.hpp"

namespace dynid {

void coriolis_matrix(const Model& model, Workspace& workspace, const VectorIn& q,
                     const VectorIn& qd, MatrixOut S) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  const int n = ws.n;
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_SHAPE(S, n, n);
  detail::update_joint_transforms(model, ws, q);
  detail::update_world_frames(model, ws);

  Vector3 w = Vector3::Zero(), u = Vector3::Zero();  // body velocity [w; u] about the world origin
  for (int i = 1; i <= n; ++i) {
    const Vector3 z = ws.R_world[i].col(2);
    Vector6& Si = ws.axis_world[i];
    if (model.joint(i - 1).revolute)
      Si << z, ws.p_world[i].cross(z);
    else
      Si << Vector3::Zero(), z;
    w += Si.head<3>() * qd[i - 1];
    u += Si.tail<3>() * qd[i - 1];
    // Sdot = v x S (motion cross product).
    ws.axis_world_dot[i] << w.cross(Si.head<3>()), w.cross(Si.tail<3>()) + u.cross(Si.head<3>());

    const RigidBodyParameters b =
        model.body(i - 1).expressed_in_parent(ws.R_world[i], ws.p_world[i]);
    const Vector3 angular_momentum = b.I * w + b.h.cross(u);
    const Vector3 linear_momentum = w.cross(b.h) + b.m * u;
    Matrix3 A;
    for (int c = 0; c < 3; ++c) A.col(c) = w.cross(b.I.col(c));
    const Matrix3 hu = b.h * u.transpose();
    ws.coriolis_block_sum[i] =
        0.5 * (A + A.transpose() - hu - hu.transpose() - skew(angular_momentum));
    ws.coriolis_block_sum[i].diagonal().array() += u.dot(b.h);
    ws.momentum_sum[i] = linear_momentum;
    ws.inertia_sum[i] = b;
  }
  for (int i = n - 1; i >= 1; --i) {
    ws.coriolis_block_sum[i] += ws.coriolis_block_sum[i + 1];
    ws.momentum_sum[i] += ws.momentum_sum[i + 1];
    ws.inertia_sum[i] += ws.inertia_sum[i + 1];
  }

  // Composite spatial inertia times a motion vector [a; b]: [Ib a + h x b; m b - h x a].
  auto inertia_times = [](const RigidBodyParameters& c, const Vector6& x) {
    Vector6 out;
    out << c.I * x.head<3>() + c.h.cross(x.tail<3>()), c.m * x.tail<3>() - c.h.cross(x.head<3>());
    return out;
  };
  for (int i = 1; i <= n; ++i) {
    const Vector3 s = ws.axis_world[i].head<3>(), l = ws.axis_world[i].tail<3>();
    // Column k = i: (B_sum S_k + I_sum Sdot_k), dotted with S_j for j <= k.
    ws.column_wrench[i] = inertia_times(ws.inertia_sum[i], ws.axis_world_dot[i]);
    ws.column_wrench[i].head<3>() += ws.coriolis_block_sum[i] * s;
    ws.column_wrench[i].tail<3>() -= ws.momentum_sum[i].cross(s);
    // Row j = i for k < j: S_j^T B_sum S_k = (T^T s_j + f_sum x l_j) . s_k, S_j^T I_sum Sdot_k.
    ws.row_coriolis[i] = ws.coriolis_block_sum[i].transpose() * s + ws.momentum_sum[i].cross(l);
    ws.row_inertia[i] = inertia_times(ws.inertia_sum[i], ws.axis_world[i]);
  }
  for (int j = 1; j <= n; ++j) {
    for (int k = 1; k <= n; ++k) {
      S(j - 1, k - 1) = j <= k ? ws.axis_world[j].dot(ws.column_wrench[k])
                               : ws.row_coriolis[j].dot(ws.axis_world[k].head<3>()) +
                                     ws.row_inertia[j].dot(ws.axis_world_dot[k]);
    }
  }
}

}  // namespace dynid
