// Exact first and second time derivatives of inverse dynamics along a motion ("jerk/snap RNEA"):
// the Newton-Euler recursion with velocities, accelerations, jerks and snaps propagated
// outwards and the wrenches and their two time derivatives inwards. Needed where the torque's
// derivatives enter a model, e.g. the motor trajectory of a robot with elastic joints
// (theta = q + K^-1 tau_l, thetadd = qdd + K^-1 d2tau_l/dt2; paper eqs. (1)-(4), notes p. 16).
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// tau = M(q) qdd + c(q, qd) + g(q) + Fv qd + Fs sign(qd) (the full torque of docs/conventions.md,
// "Drive terms and the torque model", identical to rnea) and its time derivatives along q(t) with
// derivatives qd, qdd, qddd, qdddd:
//   tau_dot  = dtau/dq qd + dtau/dqd qdd + M qddd
//   tau_ddot = d/dt tau_dot.
// Drive terms are included: Ia qddd and Fv qdd in tau_dot, Ia qdddd and Fv qddd in tau_ddot;
// Coulomb friction Fs sign(qd) is constant away from qd = 0 and contributes nothing there.
// No allocation; throws std::invalid_argument naming the argument whose size does not fit.
void rnea_time_derivatives(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
                           const VectorIn& qdd, const VectorIn& qddd, const VectorIn& qdddd,
                           VectorOut tau, VectorOut tau_dot, VectorOut tau_ddot);

}  // namespace dynid
