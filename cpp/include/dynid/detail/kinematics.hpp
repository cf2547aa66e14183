// Internal (dynid::detail, not API): the kinematic passes every algorithm starts with. They
// assume sizes already checked by the public algorithm that calls them.
#pragma once

#include "dynid/detail/workspace_buffers.hpp"
#include "dynid/model.hpp"

namespace dynid::detail {

// ws.X[i] = J_{i-1} -> J_i at q (theta = q + offset for revolute, d = q + offset for prismatic).
void update_joint_transforms(const Model& model, WorkspaceBuffers& ws, const VectorIn& q);

// ws.R_world[i], ws.p_world[i]: world pose of J_i (index 0: the base), from ws.X.
void update_world_frames(const Model& model, WorkspaceBuffers& ws);

}  // namespace dynid::detail
