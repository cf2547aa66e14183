// Per-call buffers of the analytic derivative algorithms (rnea_derivatives.cpp), held by the
// Workspace so that a call allocates nothing. Index i (1..n) is link/joint i, as in Workspace.
#pragma once

#include <vector>

#include "dynid/rigid_body.hpp"
#include "dynid/types.hpp"

namespace dynid::detail {

struct DerivativeBuffers {
  explicit DerivativeBuffers(int n)
      : S(n + 1, Vector6::Zero()),
        dVdq(n + 1, Vector6::Zero()),
        dAdq(n + 1, Vector6::Zero()),
        inertia(n + 1),
        coriolis_block(n + 1, Matrix3::Zero()),
        momentum(n + 1, Vector3::Zero()),
        force(n + 1, Vector6::Zero()),
        column_q(n + 1, Vector6::Zero()),
        column_qd(n + 1, Vector6::Zero()) {}

  // Forward pass, world axes about the world origin ([angular; linear]): joint axis S_k and the
  // non-rigid parts of the velocity/acceleration variations, dV/dq_k = v_{k-1} x S_k and
  // dA/dq_k = a_{k-1} x S_k + v_{k-1} x dV/dq_k (dA/dqd_k = 2 dV/dq_k).
  std::vector<Vector6> S, dVdq, dAdq;
  // Backward pass: composite (links i..n) spatial inertia, the 3x3 block and vector of the
  // velocity-dependent factor D (D y = [T y_w; y_w x P]), and the composite force.
  std::vector<RigidBodyParameters> inertia;
  std::vector<Matrix3> coriolis_block;
  std::vector<Vector3> momentum;
  std::vector<Vector6> force;
  // Column k's wrench (entries above the diagonal are S_j . column_k).
  std::vector<Vector6> column_q, column_qd;
};

}  // namespace dynid::detail
