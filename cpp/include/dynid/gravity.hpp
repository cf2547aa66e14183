// Gravity torques g(q) = (dU/dq)^T.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// q, g: n entries each; std::invalid_argument naming the argument (or ws) otherwise.
void gravity(const Model& model, Workspace& ws, const VectorIn& q, VectorOut g);

}  // namespace dynid
