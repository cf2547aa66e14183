// g(q) as Newton-Euler at rest: with zero velocity and acceleration every link only feels the
// fictitious base acceleration -g, so the forward pass is a chain of rotations and each link's
// wrench is (m a, h x a) (notes, "Dynamic parameters of robots 3": U_i linear in m_i and m_i r_ci).
#include "dynid/gravity.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/newton_euler.hpp"

namespace dynid {

void gravity(const Model& model, Workspace& workspace, const VectorIn& q, VectorOut g) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  const int n = ws.n;
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_JOINT_VECTOR(g, model);
  detail::update_joint_transforms(model, ws, q);
  ws.a[0] = -model.gravity_base();
  for (int i = 1; i <= n; ++i) {
    ws.a[i] = ws.X[i].rotate_to_child(ws.a[i - 1]);
    const RigidBodyParameters& b = model.body(i - 1);
    ws.f[i] = b.m * ws.a[i];
    ws.mu[i] = b.h.cross(ws.a[i]);
  }
  detail::accumulate_wrenches(model, ws, g);
}

}  // namespace dynid
