// Jdot by differentiating the Jacobian's columns in world axes. With S_i = [s; l] joint i's axis
// as a spatial motion about the world origin (revolute [z; p_i x z], prismatic [0; z]), the
// tool point's Jacobian column is J_i = [l + s x p_t; s]. The axis is fixed in link i, so
// Sdot_i = v_i x S_i (motion cross product, v_i the link's spatial velocity), and the tool point
// moves with pdot_t = u_n + w_n x p_t; hence
//   Jdot_i = [ldot + sdot x p_t + s x pdot_t; sdot].
#include "dynid/jacobian_dot.hpp"

#include <stdexcept>
#include <string>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/spatial.hpp"

namespace dynid {

void jacobian_dot(const Model& model, Workspace& workspace, const VectorIn& q, const VectorIn& qd,
                  MatrixOut Jdot) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  const int n = model.n();
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_SHAPE(Jdot, 6, n);
  detail::update_joint_transforms(model, ws, q);
  detail::update_world_frames(model, ws);
  detail::DerivativeBuffers& d = ws.derivatives;
  // Axes and their derivatives (d.dVdq holds Sdot_i = v_{i-1} x S_i = v_i x S_i here).
  Vector6 v = Vector6::Zero();
  for (int i = 1; i <= n; ++i) {
    const Vector3 z = ws.R_world[i].col(2);
    Vector6& S = d.S[i];
    if (model.joint(i - 1).revolute)
      S << z, ws.p_world[i].cross(z);
    else
      S << Vector3::Zero(), z;
    d.dVdq[i] = detail::motion_cross(v, S);
    v += S * qd[i - 1];
  }
  Matrix4 flange = Matrix4::Identity();
  flange.topLeftCorner<3, 3>() = ws.R_world[n];
  flange.topRightCorner<3, 1>() = ws.p_world[n];
  const Vector3 p_t = (flange * model.flange_to_tool()).topRightCorner<3, 1>();
  const Vector3 pdot_t = v.tail<3>() + v.head<3>().cross(p_t);
  for (int i = 1; i <= n; ++i) {
    const Vector6& S = d.S[i];
    const Vector6& Sdot = d.dVdq[i];
    Jdot.col(i - 1).head<3>() =
        Sdot.tail<3>() + Sdot.head<3>().cross(p_t) + S.head<3>().cross(pdot_t);
    Jdot.col(i - 1).tail<3>() = Sdot.head<3>();
  }
}

}  // namespace dynid
