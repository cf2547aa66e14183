"""Online identification: recursive least squares with forgetting, in C++.

:class:`RecursiveLeastSquares` refines the base-parameter estimate theta one sample at a time,
for use inside a control loop (one update of a 7 x 43 block takes a few microseconds and never
allocates), or over a whole log in one call::

    import dynid

    robot = dynid.models.kuka_lwr4()
    base = dynid.base_parameters(robot)
    rls = dynid.RecursiveLeastSquares(base.count, forgetting=0.995)
    Y = base.reduce(robot.regressor(q, qd, qdd))   # (T, n, p) base regressor blocks
    history = rls.update_batch(Y, tau, history=True)   # (T, p): the estimate after each sample
    rls.update(Y_k, tau_k)                          # later: one new sample (n, p), (n,)
    rls.theta, rls.covariance

One update with the block Y_k (m, p) and torques tau_k (m,), forgetting factor lambda in (0, 1]::

    K     = P Y_k^T (lambda I + Y_k P Y_k^T)^-1
    theta = theta + K (tau_k - Y_k theta)
    P     = (P - K Y_k P) / lambda

It is the least-squares solution of the notes (p. 27, theta = (Y^T Y)^-1 Y^T tau over the
stacked samples) computed recursively. Choosing the parameters:

- ``forgetting=1`` keeps every sample: on stationary data the estimate equals the batch
  solution with the ridge prior of ``initial_covariance`` c, (sum Y^T Y + I/c)^-1 sum Y^T tau,
  which tends to plain least squares as c grows (the default 1e6 is negligible against the
  information of a few samples of a robot regressor).
- ``forgetting < 1`` lets the estimate follow parameters that change, e.g. a payload grasped by
  the last link (notes pp. 32-33, "rule of change in dynamic parameters"): a sample k blocks
  old weighs lambda^k, so the memory is about 1 / (1 - lambda) samples (0.995 at 1 kHz: 0.2 s).
- While the robot rests, nothing is learnt and, with forgetting < 1, the covariance of the
  unexcited directions grows ("windup"); ``max_variance`` caps the variances of the UD factors,
  by default at the initial ones (c for ``initial_covariance=c``).

The covariance is held in UD-factored form (Bierman's update), so it stays symmetric and
positive definite over any number of updates. ``copy.copy`` / ``copy.deepcopy`` give an
independent estimator; one estimator must not be updated from two threads at once.
"""

from __future__ import annotations

from .._core import RecursiveLeastSquares

__all__ = ["RecursiveLeastSquares"]
