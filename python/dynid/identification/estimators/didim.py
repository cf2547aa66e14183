"""DIDIM: the direct and inverse dynamic identification model, a closed-loop output error method
whose output is the controller's torque (Gautier, Janot & Vandanjon, "A new closed-loop output
error method for parameter identification of robot dynamics", IEEE TCST 21(2), 2013).

The estimate minimises ||tau - tau_s(theta)||_W, tau the measured (commanded) torque and
tau_s(theta) the torque of the controller in the run simulated with theta, under the same
controller and reference (:mod:`.closed_loop_model`). The simulator integrates the direct model,
so tau_s = Y_s(theta) theta, Y_s the regressor of the simulated states (exactly but for the
plant's Coulomb law, tanh(qd / 1e-3) for the column's sign(qd)); Gauss-Newton with Y_s as the
Jacobian (as the paper: the sensitivity of the simulated states to theta neglected) makes each
iteration a weighted least squares on the simulated regressor,

    theta_{k+1} = (Y_s(theta_k)^T W Y_s(theta_k))^-1 Y_s(theta_k)^T W tau,

started from the WLS estimate, W = diag(1 / sigma_j^2) per joint as WLS, the sigma_j from the
residuals of theta_k; until no coefficient moves by more than SETTLED_STD of its std (measured:
5 iterations typically), at most ``iterations`` times (:func:`.closed_loop_fit.iterate`). The
covariance is the WLS one of the last iteration (:mod:`.closed_loop_fit` with Z = Y_s and the
noise model of each joint's residual). Noise on the measured positions never enters
the regressor, only tau, which is why the estimate is unbiased on closed-loop data.

Unlike IDIM-IV, the simulated run must be the model's exact output: the columns of the blocks
(offsets, asymmetric friction, position torque) have no place in the simulated robot, so DIDIM
refuses them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from .base import EstimatorFit, Problem
from .closed_loop_fit import WeightedSolve, finished, iterate, solve
from .closed_loop_model import SETTLED_STD, closed_loop, plant, simulate_runs, simulated_columns

NAME = "didim"


def didim(problem: Problem) -> EstimatorFit:
    """DIDIM on ``problem`` (module docstring); options of :mod:`.closed_loop_model`."""
    if problem.model.blocks:
        keys = ", ".join(b.key for b in problem.model.blocks)
        raise ValueError(
            f"method: 'didim' simulates the robot's own dynamics, without the columns of "
            f"{keys}; leave them out (offset, asymmetric friction, position torque) or use 'iv'"
        )
    loop = closed_loop(problem)

    def regressor(theta: NDArray[np.float64]) -> NDArray[np.float64]:
        return simulated_columns(problem, simulate_runs(problem, loop, plant(problem, theta)))

    def one_solve(Y_s: NDArray[np.float64], variance: NDArray[np.float64]) -> WeightedSolve:
        # Y_s is both the instrument and the regressor: the LS of tau on the simulated run.
        return solve(replace(problem, Y=Y_s), Y_s, variance)

    run = iterate(problem, loop.iterations, regressor, one_solve, SETTLED_STD)
    return finished(NAME, problem, run, loop.report(problem.options), [])
