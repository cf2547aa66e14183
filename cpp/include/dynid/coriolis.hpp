// The Coriolis and centrifugal torque vector c(q, qd).
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// c(q, qd) = S(q, qd) qd: Newton-Euler with qdd = 0 and no gravity (links only; the rotors spin
// about fixed axes and add nothing, notes "Resulting dynamic model").
void coriolis(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
              VectorOut c);
// q, qd, c: n entries each; std::invalid_argument naming the argument (or ws) otherwise.

}  // namespace dynid
