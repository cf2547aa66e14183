#include "dynid/friction.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/drive_terms.hpp"

namespace dynid {

void friction(const Model& model, const VectorIn& qd, VectorOut tau) {
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(tau, model);
  tau.setZero();
  detail::add_drive_friction(model, qd, tau);
}

}  // namespace dynid
