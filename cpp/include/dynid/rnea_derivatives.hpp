// Analytic partial derivatives of inverse dynamics (Carpentier & Mansard, "Analytical
// derivatives of rigid body dynamics algorithms", RSS 2018).
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// dtau/dq and dtau/dqd (n x n each) of the full torque of docs/conventions.md,
// "Drive terms and the torque model", tau = M(q) qdd + c(q, qd) + g(q) + Fv qd + Fs sign(qd):
// dtau_dqd includes diag(Fv), Coulomb friction contributes nothing away from qd = 0, and dtau/dqdd
// is M(q) (crba). No allocation; throws std::invalid_argument naming the argument whose size does
// not fit the model.
void rnea_derivatives(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
                      const VectorIn& qdd, MatrixOut dtau_dq, MatrixOut dtau_dqd);

}  // namespace dynid
