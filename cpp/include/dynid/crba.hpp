// Joint-space inertia matrix by the composite-rigid-body algorithm.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// M(q) = B(q) + diag(Ia), full symmetric n x n.
void crba(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut M);

// B(q) only, for joint transforms already in ws.X (no rotor inertia).
void composite_rigid_body(const Model& model, Workspace& ws, MatrixOut B);

}  // namespace dynid
