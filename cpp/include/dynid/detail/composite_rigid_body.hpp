// Internal (dynid::detail, not API): the composite-rigid-body pass of crba.cpp, also used by
// forward dynamics.
#pragma once

#include "dynid/detail/workspace_buffers.hpp"
#include "dynid/model.hpp"

namespace dynid::detail {

// B(q) only (no rotor inertia), for joint transforms already in ws.X; B is n x n (unchecked).
void composite_rigid_body(const Model& model, WorkspaceBuffers& ws, MatrixOut B);

}  // namespace dynid::detail
