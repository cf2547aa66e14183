#include "dynid/detail/workspace_buffers.hpp"

namespace dynid::detail {

WorkspaceBuffers::WorkspaceBuffers(int joints)
    : n(joints),
      X(n + 1),
      omega(n + 1, Vector3::Zero()),
      omegad(n + 1, Vector3::Zero()),
      v(n + 1, Vector3::Zero()),
      a(n + 1, Vector3::Zero()),
      f(n + 1, Vector3::Zero()),
      mu(n + 1, Vector3::Zero()),
      R_world(n + 1, Matrix3::Identity()),
      p_world(n + 1, Vector3::Zero()),
      composite(n + 1),
      axis_world(n + 1, Vector6::Zero()),
      axis_world_dot(n + 1, Vector6::Zero()),
      inertia_sum(n + 1),
      coriolis_block_sum(n + 1, Matrix3::Zero()),
      momentum_sum(n + 1, Vector3::Zero()),
      column_wrench(n + 1, Vector6::Zero()),
      row_inertia(n + 1, Vector6::Zero()),
      row_coriolis(n + 1, Vector3::Zero()),
      axes(n + 1, Vector6::Zero()),
      zeros(VectorX::Zero(n)),
      M(MatrixX::Zero(n, n)),
      bias(VectorX::Zero(n)),
      cholesky(n),
      derivatives(n),
      time_derivatives(n) {}

}  // namespace dynid::detail
