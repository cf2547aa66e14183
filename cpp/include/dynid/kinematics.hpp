// Forward kinematics of the DH chain: joint transforms, world poses, tool pose and the
// geometric Jacobian.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// ws.X[i] = J_{i-1} -> J_i at q (theta = q + offset for revolute, d = q + offset for prismatic).
// Throws std::invalid_argument when q or the workspace do not fit the model.
void update_joint_transforms(const Model& model, Workspace& ws, const VectorIn& q);

// ws.R_world[i], ws.p_world[i]: world pose of J_i (index 0: the base), from ws.X.
void update_world_frames(const Model& model, Workspace& ws);

// World pose of the tool, base * A_1 ... A_n * tool, as a 4x4 homogeneous matrix.
void fkine(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut T);

// Geometric Jacobian (6 x n) of the tool point in world axes, rows [v; omega].
void jacobian(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut J);

}  // namespace dynid
