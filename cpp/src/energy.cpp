#include "dynid/energy.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/drive_terms.hpp"
#include "dynid/detail/kinematics.hpp"

namespace dynid {

double kinetic_energy(const Model& model, Workspace& workspace, const VectorIn& q,
                      const VectorIn& qd) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  detail::update_joint_transforms(model, ws, q);
  const Vector3 z = Vector3::UnitZ();
  ws.omega[0].setZero();
  ws.v[0].setZero();
  // Decoupled rotors are summed joint by joint as before the transmission existed; coupled ones
  // spin at T qd (detail/drive_terms.hpp).
  const bool decoupled = model.transmission_is_identity();
  double T = 0.0;
  for (int i = 1; i <= ws.n; ++i) {
    const detail::JointTransform& X = ws.X[i];
    const Vector3& w = ws.omega[i - 1];
    ws.omega[i] = X.rotate_to_child(w);
    ws.v[i] = X.rotate_to_child(ws.v[i - 1] + w.cross(X.p));
    if (model.joint(i - 1).revolute)
      ws.omega[i] += qd[i - 1] * z;
    else
      ws.v[i] += qd[i - 1] * z;
    const RigidBodyParameters& b = model.body(i - 1);
    const Vector3& wi = ws.omega[i];
    const Vector3& vi = ws.v[i];
    T += 0.5 * (b.m * vi.squaredNorm() + wi.dot(b.I * wi)) + vi.dot(wi.cross(b.h));
    if (decoupled) T += detail::rotor_energy(model, i - 1, qd[i - 1]);
  }
  if (!decoupled) T += detail::rotor_kinetic_energy(model, qd);
  return T;
}

double potential_energy(const Model& model, Workspace& workspace, const VectorIn& q) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  detail::update_joint_transforms(model, ws, q);
  detail::update_world_frames(model, ws);
  double U = 0.0;
  for (int i = 1; i <= ws.n; ++i) {
    const RigidBodyParameters& b = model.body(i - 1);
    U -= model.gravity().dot(b.m * ws.p_world[i] + ws.R_world[i] * b.h);
  }
  return U;
}

}  // namespace dynid
