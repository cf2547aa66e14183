// Recursive Newton-Euler in the joint frames J_i (Luh-Walker-Paul form, moments about the frame
// origin so that each link enters through its ten standard parameters, notes "Dynamic parameters
// of robots 3"). Joint i acts along z of J_i; X[i] maps J_i to J_{i-1}.
#include "dynid/rnea.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/drive_terms.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/newton_euler.hpp"

namespace dynid {
namespace detail {

void propagate_motion(const Model& model, WorkspaceBuffers& ws, const VectorIn& qd,
                      const VectorIn& qdd, const Vector3& base_acceleration) {
  const Vector3 z = Vector3::UnitZ();
  ws.omega[0].setZero();
  ws.omegad[0].setZero();
  ws.a[0] = base_acceleration;
  for (int i = 1; i <= ws.n; ++i) {
    const JointTransform& X = ws.X[i];
    const Vector3& w = ws.omega[i - 1];
    const Vector3 origin_acc = ws.a[i - 1] + ws.omegad[i - 1].cross(X.p) + w.cross(w.cross(X.p));
    const Vector3 w_in_i = X.rotate_to_child(w);
    const Vector3 wd_in_i = X.rotate_to_child(ws.omegad[i - 1]);
    const double qdi = qd[i - 1], qddi = qdd[i - 1];
    if (model.joint(i - 1).revolute) {
      ws.omega[i] = w_in_i + qdi * z;
      ws.omegad[i] = wd_in_i + qddi * z + qdi * w_in_i.cross(z);
      ws.a[i] = X.rotate_to_child(origin_acc);
    } else {
      ws.omega[i] = w_in_i;
      ws.omegad[i] = wd_in_i;
      ws.a[i] = X.rotate_to_child(origin_acc) + 2.0 * qdi * w_in_i.cross(z) + qddi * z;
    }
  }
}

void newton_euler(const Model& model, WorkspaceBuffers& ws, const VectorIn& qd, const VectorIn& qdd,
                  const Vector3& base_acceleration, VectorOut tau) {
  propagate_motion(model, ws, qd, qdd, base_acceleration);
  // Wrench needed to move link i alone, about the origin of J_i.
  for (int i = 1; i <= ws.n; ++i) {
    const RigidBodyParameters& b = model.body(i - 1);
    const Vector3& w = ws.omega[i];
    ws.f[i] = b.m * ws.a[i] + ws.omegad[i].cross(b.h) + w.cross(w.cross(b.h));
    ws.mu[i] = b.I * ws.omegad[i] + w.cross(b.I * w) + b.h.cross(ws.a[i]);
  }
  accumulate_wrenches(model, ws, tau);
}

void accumulate_wrenches(const Model& model, WorkspaceBuffers& ws, VectorOut tau) {
  for (int i = ws.n; i >= 1; --i) {
    tau[i - 1] = model.joint(i - 1).revolute ? ws.mu[i].z() : ws.f[i].z();
    if (i > 1) {
      const JointTransform& X = ws.X[i];
      const Vector3 f_parent = X.rotate_to_parent(ws.f[i]);
      ws.f[i - 1] += f_parent;
      ws.mu[i - 1] += X.rotate_to_parent(ws.mu[i]) + X.p.cross(f_parent);
    }
  }
}

}  // namespace detail

void rnea(const Model& model, Workspace& workspace, const VectorIn& q, const VectorIn& qd,
          const VectorIn& qdd, VectorOut tau) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(qdd, model);
  DYNID_CHECK_JOINT_VECTOR(tau, model);
  detail::update_joint_transforms(model, ws, q);
  detail::newton_euler(model, ws, qd, qdd, -model.gravity_base(), tau);
  detail::add_drive_torque(model, qd, qdd, tau);
}

}  // namespace dynid
