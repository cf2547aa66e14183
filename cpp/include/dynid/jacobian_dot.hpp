// Time derivative of the geometric Jacobian, for operational-space dynamics (Khatib 1987:
// xdd = J qdd + Jdot qd).
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// Jdot (6 x n) = d/dt jacobian(q) along qd: tool point, world axes, rows [v; omega], as
// jacobian(). No allocation; throws std::invalid_argument naming a badly sized argument.
void jacobian_dot(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
                  MatrixOut Jdot);

}  // namespace dynid
