// Internal (dynid::detail, not API): joint i's friction, for algorithms that add it sample by
// sample (rnea, forward dynamics, the public friction()).
#pragma once

#include "dynid/model.hpp"

namespace dynid::detail {

// Fv_i qd + Fs_i sign(qd), sign(0) = 0 (notes, "Adding dynamic terms").
inline double friction_torque(const Model& model, int i, double qd) {
  const double sign = (qd > 0.0) - (qd < 0.0);
  return model.viscous_friction()[i] * qd + model.coulomb_friction()[i] * sign;
}

}  // namespace dynid::detail
