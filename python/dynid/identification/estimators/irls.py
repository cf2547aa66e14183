"""IRLS: the M-estimator of the base parameters with a robust loss (Huber, Tukey's bisquare),
by iteratively reweighted least squares (Holland & Welsch, Commun. Statist. A6(9), 1977; Huber,
Robust Statistics, 1981, ch. 7).

Each row i (a sample of joint j) has the residual r_i = tau_i - Y_i theta, scaled by the joint's
robust noise level s_j = 1.4826 MAD_j (the median absolute deviation of joint j's residuals
from their median; 1.4826 makes it the standard deviation of Gaussian noise): u_i = r_i / s_j.
theta solves sum_i psi(u_i) Y_i^T / s_j = 0 with

    Huber:  psi(u) = clip(u, -c, c)                      c = 1.345 (95 % efficiency)
    Tukey:  psi(u) = u (1 - (u/c)^2)^2 for |u| <= c, 0    c = 4.685 (95 % efficiency)

solved by weighted least squares with w_i = psi(u_i) / u_i, re-weighting until the fitted
torques change by less than 1e-13 of their norm. Huber's loss is convex: it starts from the WLS
fit, the scales re-estimated at every step. Tukey's redescends (an outlier beyond c gets weight
0) and has local minima: it starts from the converged Huber fit and keeps that fit's scales
(as the MM-estimator of Yohai, Ann. Statist. 15(2), 1987, keeps its S-scale). With the scale
fixed each IRLS step lowers Tukey's objective; re-estimating the median at every step instead
made it cycle on the LWR4+ log (relative changes ~1e-6 after 200 iterations).

Covariance: the sandwich H^-1 V H^-1 (Huber 1981, sect. 7.6), H = sum_i psi'(u_i) Y_i^T Y_i /
s_j^2 and V from the scores psi(u_i) Y_i / s_j summed over blocks of contiguous samples
(:mod:`._rows`). The final weights (their square roots, per row) are the row weights of the
physically consistent fit of the same method, whose per-joint weights are 1 / s_j.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._rows import (
    Rows,
    block_sums,
    estimate,
    positive_number,
    sandwich,
    stacked_rows,
    weighted_solve,
)
from .base import EstimatorFit, Problem

#: Tuning constants of 95 % efficiency at Gaussian noise (Holland & Welsch 1977).
TUNING = {"huber": 1.345, "tukey": 4.685}
#: The consistency factor of the MAD for Gaussian noise, 1 / Phi^-1(3/4).
MAD_FACTOR = 1.482602218505602
MAX_ITERATIONS = 200
#: Converged when the fitted torques change by less than this fraction of their norm.
TOLERANCE = 1e-13

Psi = Callable[[NDArray[np.float64], float], NDArray[np.float64]]


def huber_psi(u: NDArray[np.float64], c: float) -> NDArray[np.float64]:
    return np.clip(u, -c, c)


def huber_dpsi(u: NDArray[np.float64], c: float) -> NDArray[np.float64]:
    return (np.abs(u) <= c).astype(float)


def tukey_psi(u: NDArray[np.float64], c: float) -> NDArray[np.float64]:
    return np.where(np.abs(u) <= c, u * (1 - (u / c) ** 2) ** 2, 0.0)


def tukey_dpsi(u: NDArray[np.float64], c: float) -> NDArray[np.float64]:
    v = (u / c) ** 2
    return np.where(np.abs(u) <= c, (1 - v) * (1 - 5 * v), 0.0)


LOSSES: dict[str, tuple[Psi, Psi]] = {
    "huber": (huber_psi, huber_dpsi),
    "tukey": (tukey_psi, tukey_dpsi),
}


def irls(problem: Problem) -> EstimatorFit:
    """The M-estimate with the loss ``options["loss"]`` ("huber", default, or "tukey") and
    tuning constant ``options["tuning"]`` (in robust standard deviations; default 1.345 /
    4.685), its sandwich covariance and its final weights (module docstring)."""
    loss, c = _options(problem.options)
    rows = stacked_rows(problem)
    theta = np.asarray(problem.start.theta, dtype=float)
    huber_c = c if loss == "huber" else TUNING["huber"]
    theta, iterations, converged = _iterate(rows, theta, huber_psi, huber_c)
    s = _scales(rows, rows.b - rows.A @ theta)
    if loss == "tukey":  # from the converged Huber fit, with its scale fixed (module docstring)
        theta, count, done = _iterate(rows, theta, tukey_psi, c, fixed=s)
        iterations, converged = iterations + count, converged and done
    psi, dpsi = LOSSES[loss]
    r = rows.b - rows.A @ theta
    u = r / s[rows.joint]
    weight = _weights(u, psi, c)
    _, rank, cond = weighted_solve(rows.A, rows.b, np.sqrt(weight) / s[rows.joint], "irls")
    # Sandwich (Huber 1981, 7.6): scores psi(u) a / s, H = sum psi'(u) a a^T / s^2.
    scaled = rows.A / s[rows.joint, None]
    H = scaled.T @ (dpsi(u, c)[:, None] * scaled)
    sums = block_sums(rows, psi(u, c)[:, None] * scaled)
    covariance = sandwich(H, sums, rows.N, problem.p)
    result = estimate(
        problem, rows, theta, covariance, s**2, method="irls", rank=rank, condition_number=cond
    )
    row_weights = np.zeros(problem.tau.shape)
    row_weights[rows.sample, np.array(rows.joints)[rows.joint]] = np.sqrt(weight)
    per_joint = [(np.abs(x) > c) for x in rows.per_joint(u)]
    report = {
        "loss": loss,
        "tuning": c,
        "iterations": iterations,
        "converged": converged,
        "scale": [float(x) for x in s],
        "outliers": [int(x.sum()) for x in per_joint],  # rows beyond c (Tukey: weight 0)
        "outlier_fraction": float(sum(int(x.sum()) for x in per_joint) / max(rows.N, 1)),
    }
    notes = []
    if not converged:
        notes.append(
            f"irls: not converged after {MAX_ITERATIONS} iterations ({loss} loss); the estimate "
            "is the last iterate"
        )
    return EstimatorFit(result, row_weights, report, tuple(notes))


def _options(options: Mapping[str, Any]) -> tuple[str, float]:
    """``loss`` and ``tuning`` checked, the default tuning constant of the loss filled in."""
    loss = options.get("loss")
    if loss is None:
        loss = "huber"
    if loss not in LOSSES:
        raise ValueError(f"loss: expected 'huber' or 'tukey', got {loss!r}")
    tuning = options.get("tuning")
    c = TUNING[loss] if tuning is None else positive_number(tuning, "tuning")
    return str(loss), c


def _scales(rows: Rows, r: NDArray[np.float64]) -> NDArray[np.float64]:
    """s_j = 1.4826 median |r - median r| per joint; a joint fitted exactly (MAD 0) gets the
    largest scale times 1e-3 (as least squares' variance floor of 1e-6), so that it keeps a
    finite weight."""
    s = np.array(
        [
            MAD_FACTOR * np.median(np.abs(x - np.median(x))) if x.size else 0.0
            for x in rows.per_joint(r)
        ]
    )
    largest = s.max() if s.size else 0.0
    if largest == 0:
        return np.ones_like(s)
    return np.maximum(s, 1e-3 * largest)


def _weights(u: NDArray[np.float64], psi: Psi, c: float) -> NDArray[np.float64]:
    """w = psi(u) / u, and psi'(0) = 1 at u = 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(u != 0, psi(u, c) / u, 1.0)
    return np.maximum(w, 0.0)


def _iterate(
    rows: Rows,
    theta: NDArray[np.float64],
    psi: Psi,
    c: float,
    fixed: NDArray[np.float64] | None = None,
) -> tuple[NDArray[np.float64], int, bool]:
    """IRLS from ``theta``: scale (re-estimated, or ``fixed``), weights, weighted least
    squares, until the fitted torques settle. Returns theta, the iterations and whether it
    converged."""
    fitted = rows.A @ theta
    for iteration in range(1, MAX_ITERATIONS + 1):
        r = rows.b - fitted
        s = _scales(rows, r) if fixed is None else fixed
        u = r / s[rows.joint]
        w = _weights(u, psi, c)
        theta, _, _ = weighted_solve(rows.A, rows.b, np.sqrt(w) / s[rows.joint], "irls")
        new = rows.A @ theta
        change = np.linalg.norm(new - fitted)
        fitted = new
        if change <= TOLERANCE * max(np.linalg.norm(new), np.finfo(float).tiny):
            return theta, iteration, True
    return theta, MAX_ITERATIONS, False
