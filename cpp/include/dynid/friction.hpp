// Joint friction of the drive model (notes, "Adding dynamic terms").
#pragma once

#include "dynid/model.hpp"

namespace dynid {

// Fv qd + Fs sign(qd), sign(0) = 0.
void friction(const Model& model, const VectorIn& qd, VectorOut tau);

// Joint i's share, for algorithms that add it sample by sample.
inline double friction_torque(const Model& model, int i, double qd) {
  const double sign = (qd > 0.0) - (qd < 0.0);
  return model.viscous_friction()[i] * qd + model.coulomb_friction()[i] * sign;
}

}  // namespace dynid
