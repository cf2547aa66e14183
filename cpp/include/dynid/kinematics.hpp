// Forward kinematics of the DH chain: the tool pose, every link frame and the geometric Jacobian.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// World pose of the tool, base * A_1 ... A_n * tool, as a 4x4 homogeneous matrix T.
void fkine(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut T);

// Geometric Jacobian (6 x n) of the tool point in world axes, rows [v; omega].
void jacobian(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut J);

// World poses of the DH frames 1..n, base * A_1 ... A_i (the tool transform excluded): row i-1
// of `frames` (n x 16) is the pose of frame i as a row-major 4x4 matrix. One forward pass; the
// last frame times the tool is fkine's T.
void link_frames(const Model& model, Workspace& ws, const VectorIn& q, RowMajorOut frames);

// All throw std::invalid_argument naming q, T, J, frames or ws when its size does not fit the
// model.

}  // namespace dynid
