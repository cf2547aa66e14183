// Joint friction of the drive model (notes, "Adding dynamic terms").
#pragma once

#include "dynid/model.hpp"

namespace dynid {

// Fv qd + Fs sign(qd), sign(0) = 0. qd and tau have n entries (std::invalid_argument otherwise).
void friction(const Model& model, const VectorIn& qd, VectorOut tau);

}  // namespace dynid
