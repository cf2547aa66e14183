#include "dynid/friction.hpp"

namespace dynid {

void friction(const Model& model, const VectorIn& qd, VectorOut tau) {
  for (int i = 0; i < model.n(); ++i) tau[i] = friction_torque(model, i, qd[i]);
}

}  // namespace dynid
