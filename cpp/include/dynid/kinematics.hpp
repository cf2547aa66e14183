// Forward kinematics of the DH chain: the tool pose and the geometric Jacobian.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// World pose of the tool, base * A_1 ... A_n * tool, as a 4x4 homogeneous matrix T.
void fkine(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut T);

// Geometric Jacobian (6 x n) of the tool point in world axes, rows [v; omega].
void jacobian(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut J);

// Both throw std::invalid_argument naming q, T, J or ws when its size does not fit the model.

}  // namespace dynid
