// Inverse dynamics by the recursive Newton-Euler algorithm.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// tau = M(q) qdd + c(q, qd) + g(q) + Fv qd + Fs sign(qd), M = B + diag(Ia) (docs/conventions.md,
// "Drive terms and the torque model"; notes, "Resulting dynamic model"). q, qd, qdd and tau have n
// entries; throws std::invalid_argument naming the first argument (or ws) that does not fit the
// model.
void rnea(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
          const VectorIn& qdd, VectorOut tau);

}  // namespace dynid
