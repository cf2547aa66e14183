#include "dynid/coriolis.hpp"

#include "dynid/kinematics.hpp"
#include "dynid/rnea.hpp"

namespace dynid {

void coriolis(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
              VectorOut c) {
  update_joint_transforms(model, ws, q);
  newton_euler(model, ws, qd, ws.zeros, Vector3::Zero(), c);
}

}  // namespace dynid
