"""IDIM-IV: the inverse dynamic identification model with instrumental variables, the
instruments from the model simulated in closed loop (Janot, Vandanjon & Gautier, "A generic
instrumental variable approach for industrial robot identification", IEEE TCST 22(1), 2014;
Gautier, Janot & Vandanjon, IEEE TCST 21(2), 2013, section II).

Closed-loop data defeat least squares: the controller feeds the measurement noise back into the
torque, and the regressor Y is built from the same noisy positions (velocities and accelerations
differentiated from them), so Y is correlated with the error tau - Y theta and OLS/WLS are
biased. Instruments Z correlated with the true regressor but not with the noise remove the bias:
Z is the regressor of the run *simulated* with the current estimate, under the same controller
and reference (:mod:`.closed_loop_model`), noise-free by construction. Iterated from the WLS
estimate theta_0:

    Z_k = Y(q_s(theta_k), qd_s(theta_k), qdd_s(theta_k)),
    theta_{k+1} = (Z_k^T W Y)^-1 Z_k^T W tau,

W = diag(1 / sigma_j^2) per joint as WLS, the sigma_j from the residuals of theta_k; until no
coefficient moves by more than SETTLED_STD of its std (measured: 4 iterations typically), at most
``iterations`` times (:func:`.closed_loop_fit.iterate`: relaxed where Coulomb friction makes
the map jump). The covariance is the IV sandwich of :mod:`.closed_loop_fit`.

The columns of the blocks (offsets, asymmetric friction, position torque) are no part of the
simulated robot; their instruments are their own columns at the simulated states, which stay
uncorrelated with the noise, so the estimate keeps its consistency, the simulated run only
following the real one less closely.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .base import EstimatorFit, Problem
from .closed_loop_fit import WeightedSolve, finished, iterate, solve
from .closed_loop_model import SETTLED_STD, closed_loop, plant, simulate_runs, simulated_columns

NAME = "iv"


def instrumental_variables(problem: Problem) -> EstimatorFit:
    """IDIM-IV on ``problem`` (module docstring); options of :mod:`.closed_loop_model`."""
    loop = closed_loop(problem)

    def instruments(theta: NDArray[np.float64]) -> NDArray[np.float64]:
        return simulated_columns(problem, simulate_runs(problem, loop, plant(problem, theta)))

    def one_solve(Z: NDArray[np.float64], variance: NDArray[np.float64]) -> WeightedSolve:
        return solve(problem, Z, variance)

    run = iterate(problem, loop.iterations, instruments, one_solve, SETTLED_STD)
    notes = []
    if problem.model.blocks:
        keys = ", ".join(b.key for b in problem.model.blocks)
        notes.append(
            f"{NAME}: the columns of {keys} are not simulated; their own columns at the "
            "simulated states are their instruments"
        )
    return finished(NAME, problem, run, loop.report(problem.options), notes)
