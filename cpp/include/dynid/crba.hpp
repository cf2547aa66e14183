// Joint-space inertia matrix by the composite-rigid-body algorithm.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// M(q) = B(q) + diag(Ia), full symmetric n x n. q has n entries, M is n x n; throws
// std::invalid_argument naming the argument (or ws) that does not fit the model.
void crba(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut M);

}  // namespace dynid
