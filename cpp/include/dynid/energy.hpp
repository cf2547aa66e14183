// Kinetic and potential energy, computed from link velocities and positions (not from M or g,
// so that the tests can check M and g against their derivatives).
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// T = sum_i 1/2 (m v.v + 2 v.(w x h) + w^T I w) + 1/2 sum_i Ia_i qd_i^2  (notes, "Dynamic
// parameters of robots 3"), equal to 1/2 qd^T M(q) qd.
double kinetic_energy(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd);

// U = -sum_i g^T (m_i p_i + R_i h_i) in world coordinates, zero at the world origin.
double potential_energy(const Model& model, Workspace& ws, const VectorIn& q);

// q, qd: n entries each; std::invalid_argument naming the argument (or ws) otherwise.

}  // namespace dynid
