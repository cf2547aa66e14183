// M by CRBA, the bias by Newton-Euler with qdd = 0, then a Cholesky solve: the whole M must be
// inverted, not its diagonal (notes, "... an incorrect realization").
#include "dynid/forward_dynamics.hpp"

#include <stdexcept>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/composite_rigid_body.hpp"
#include "dynid/detail/drive_terms.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/newton_euler.hpp"

namespace dynid {

void forward_dynamics(const Model& model, Workspace& workspace, const VectorIn& q,
                      const VectorIn& qd, const VectorIn& tau, VectorOut qdd) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(tau, model);
  DYNID_CHECK_JOINT_VECTOR(qdd, model);
  // The bias c + g + friction: Newton-Euler with qdd = 0.
  detail::update_joint_transforms(model, ws, q);
  detail::newton_euler(model, ws, qd, ws.zeros, -model.gravity_base(), ws.bias);
  detail::add_drive_friction(model, qd, ws.bias);
  detail::composite_rigid_body(model, ws, ws.M);
  detail::add_drive_inertia(model, ws.M);
  ws.cholesky.compute(ws.M);
  if (ws.cholesky.info() != Eigen::Success)
    throw std::domain_error(
        "forward_dynamics: the mass matrix is not positive definite at this q (are the "
        "parameters physically consistent?)");
  qdd = tau - ws.bias;
  ws.cholesky.solveInPlace(qdd);
}

}  // namespace dynid
