// Internal (dynid::detail, not API): the passes of the recursive Newton-Euler algorithm, shared
// by rnea, gravity, coriolis, forward dynamics and the regressors. They assume sizes already
// checked by the public algorithm that calls them, and joint transforms for q already in ws.X.
#pragma once

#include "dynid/detail/workspace_buffers.hpp"
#include "dynid/model.hpp"

namespace dynid::detail {

// The links' share B(q) qdd + c(q, qd) [+ g(q)]. base_acceleration is the linear acceleration of
// frame 0 in its own axes: -gravity_base() includes gravity (the usual fictitious upward
// acceleration), zero leaves it out.
void newton_euler(const Model& model, WorkspaceBuffers& ws, const VectorIn& qd, const VectorIn& qdd,
                  const Vector3& base_acceleration, VectorOut tau);

// Forward pass: ws.omega, ws.omegad and ws.a (linear acceleration of each joint-frame origin).
void propagate_motion(const Model& model, WorkspaceBuffers& ws, const VectorIn& qd,
                      const VectorIn& qdd, const Vector3& base_acceleration);

// Backward pass: adds each link's wrench (ws.f, ws.mu, about the origin of J_i) to its
// parent's, from link n inwards, and projects it on the joint axis.
void accumulate_wrenches(const Model& model, WorkspaceBuffers& ws, VectorOut tau);

}  // namespace dynid::detail
