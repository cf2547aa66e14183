// Per-call buffers of the time-derivative Newton-Euler recursion (rnea_time_derivatives.cpp),
// held by the Workspace so that a call allocates nothing. Index i (1..n) is link/joint i.
#pragma once

#include <vector>

#include "dynid/types.hpp"

namespace dynid::detail {

struct TimeDerivativeBuffers {
  explicit TimeDerivativeBuffers(int n)
      : S(n + 1, Vector6::Zero()),
        S_dot(n + 1, Vector6::Zero()),
        S_ddot(n + 1, Vector6::Zero()),
        force(n + 1, Vector6::Zero()),
        force_dot(n + 1, Vector6::Zero()),
        force_ddot(n + 1, Vector6::Zero()) {}

  // World axis of joint k ([angular; linear] about the world origin) and its first two time
  // derivatives along the motion.
  std::vector<Vector6> S, S_dot, S_ddot;
  // Link i's wrench and its two time derivatives; after the backward pass, the sums over i..n.
  std::vector<Vector6> force, force_dot, force_ddot;
};

}  // namespace dynid::detail
