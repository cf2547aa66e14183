#include "dynid/coriolis.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/newton_euler.hpp"

namespace dynid {

void coriolis(const Model& model, Workspace& workspace, const VectorIn& q, const VectorIn& qd,
              VectorOut c) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(c, model);
  detail::update_joint_transforms(model, ws, q);
  detail::newton_euler(model, ws, qd, ws.zeros, Vector3::Zero(), c);
}

}  // namespace dynid
