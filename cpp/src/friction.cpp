#include "dynid/friction.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/friction_torque.hpp"

namespace dynid {

void friction(const Model& model, const VectorIn& qd, VectorOut tau) {
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(tau, model);
  for (int i = 0; i < model.n(); ++i) tau[i] = detail::friction_torque(model, i, qd[i]);
}

}  // namespace dynid
