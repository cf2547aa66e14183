// Inverse dynamics by the recursive Newton-Euler algorithm.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// tau = M(q) qdd + c(q, qd) + g(q) + Fv qd + Fs sign(qd), M = B + diag(Ia) (SPEC section 2;
// notes, "Resulting dynamic model").
void rnea(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
          const VectorIn& qdd, VectorOut tau);

// The links' share B(q) qdd + c(q, qd) [+ g(q)], for joint transforms already in ws.X.
// base_acceleration is the linear acceleration of frame 0 in its own axes: -gravity_base()
// includes gravity (the usual fictitious upward acceleration), zero leaves it out.
void newton_euler(const Model& model, Workspace& ws, const VectorIn& qd, const VectorIn& qdd,
                  const Vector3& base_acceleration, VectorOut tau);

// Forward pass shared by Newton-Euler and the regressors: ws.omega, ws.omegad and ws.a (linear
// acceleration of each joint-frame origin) for joint transforms already in ws.X.
void propagate_motion(const Model& model, Workspace& ws, const VectorIn& qd, const VectorIn& qdd,
                      const Vector3& base_acceleration);

// Backward pass shared by the Newton-Euler variants: adds each link's wrench (ws.f, ws.mu, about
// the origin of J_i) to its parent's, from link n inwards, and projects it on the joint axis.
void accumulate_wrenches(const Model& model, Workspace& ws, VectorOut tau);


}  // namespace dynid
