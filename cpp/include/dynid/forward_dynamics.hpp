// Forward dynamics qdd = M(q)^-1 (tau - c(q, qd) - g(q) - friction(qd)) (notes, "State equations").
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// q, qd, tau, qdd: n entries each (std::invalid_argument naming the argument or ws otherwise).
// Throws std::domain_error when M(q) is not positive definite (inconsistent parameters).
void forward_dynamics(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
                      const VectorIn& tau, VectorOut qdd);

}  // namespace dynid
