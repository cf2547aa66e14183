// Gravity torques g(q) = (dU/dq)^T.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

void gravity(const Model& model, Workspace& ws, const VectorIn& q, VectorOut g);

}  // namespace dynid
