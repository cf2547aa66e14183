"""Essential parameters: the base parameters the data determine well, the others set to zero
(Pham & Gautier, ICRA 1991; Gautier & Khalil; as in FloBaRoID, Bethge et al., and FIGAROH).

From the WLS fit of all coefficients, the one with the largest relative standard deviation is
removed (its theta set to 0) and the rest fitted again by WLS, one at a time, while

- the largest relative standard deviation is above ``essential_threshold`` percent (default 10),
- and the fit holds: the weighted residual RMS (each joint's rows divided by its noise level in
  the full model's WLS fit, so the joints count as in WLS) stays within 1 % of the full
  model's; a removal that would raise it more is undone and the search stops.

A parameter with relative std s % moves the weighted residual sum of squares by about
(100 / s)^2 noise variances when removed, so one above the threshold costs little; the 1 %
bound keeps many such small costs from adding up. The result is the reduced model's WLS fit:
its theta and covariance, zeros (value and std) for the removed coefficients, which the report
lists in the order of removal with their relative std at that step.

Each refit re-solves the triangular factors of the kept columns: the factor of [A_S | b] is the
R of the columns S and b of the full factor (Q^T [A | b] = R), so the samples are read once.
"""

from __future__ import annotations

import numpy as np

from .._qr import GroupedTriangularFactors, upper_triangle
from ..identify import LeastSquaresResult, relative_std, solve_factors
from ._rows import RANK_TOLERANCE, Rows, positive_number, stacked_rows
from .base import EstimatorFit, Problem

#: Default threshold on the relative standard deviation, percent.
THRESHOLD = 10.0
#: The fit holds while the weighted residual RMS is within this fraction of the full model's.
FIT_HOLDS = 0.01


def essential(problem: Problem) -> EstimatorFit:
    """The essential parameters' WLS fit (module docstring)."""
    value = problem.options.get("essential_threshold")
    threshold = THRESHOLD if value is None else positive_number(value, "essential_threshold")
    rows = stacked_rows(problem)
    factors = GroupedTriangularFactors(problem.n, problem.p, problem.joints)
    factors.add(problem.Y, problem.tau, problem.keep)
    kept = list(range(problem.p))
    fit = _fit(problem, factors, kept)
    sigma = np.sqrt(np.maximum(fit.noise_variance, 1e-300))  # the full model's noise levels
    full = _weighted_rms(rows, kept, fit.theta, sigma)
    removed: list[dict[str, object]] = []
    stopped = "every relative std below the threshold"
    while len(kept) > 1:
        worst = int(np.argmax(fit.relative_std))
        if not fit.relative_std[worst] > threshold:
            break
        trial = kept[:worst] + kept[worst + 1 :]
        refit = _fit(problem, factors, trial)
        growth = _weighted_rms(rows, trial, refit.theta, sigma) / full - 1.0
        name = problem.names[kept[worst]]
        if growth > FIT_HOLDS:
            stopped = (
                f"removing {name} (relative std {fit.relative_std[worst]:.3g} %) would raise "
                f"the weighted residual RMS by {100 * growth:.3g} % (> {100 * FIT_HOLDS:g} %)"
            )
            break
        removed.append(
            {
                "name": name,
                "relative_std": float(fit.relative_std[worst]),
                "value": float(fit.theta[worst]),
            }
        )
        kept, fit = trial, refit
    if len(kept) == 1:
        stopped = "one coefficient left"
    result = _expanded(problem, fit, kept)
    growth = _weighted_rms(rows, kept, fit.theta, sigma) / full - 1.0
    report = {
        "threshold": threshold,
        "removed": removed,
        "kept": [problem.names[k] for k in kept],
        "residual_growth": float(growth),
        "stopped": stopped,
    }
    notes: tuple[str, ...] = ()
    if removed:
        notes = (
            f"essential parameters: {len(removed)} of {problem.p} coefficients removed "
            f"(relative std > {threshold:g} %): {', '.join(str(r['name']) for r in removed)}",
        )
    return EstimatorFit(result, None, report, notes)


def _fit(
    problem: Problem, factors: GroupedTriangularFactors, columns: list[int]
) -> LeastSquaresResult:
    """WLS on the coefficients ``columns`` only, from the full triangular factors."""
    p = problem.p
    sub = GroupedTriangularFactors(factors.n, len(columns), factors.joints)
    sub.a_exp, sub.b_exp, sub.samples = factors.a_exp, factors.b_exp, factors.samples
    sub.counts, sub.max_a, sub.max_b = dict(factors.counts), factors.max_a, factors.max_b
    for j, R in factors.factors.items():
        sub.factors[j] = upper_triangle(R[:, [*columns, p]])
    return solve_factors(
        sub,
        method="wls",
        names=[problem.names[k] for k in columns],
        on_rank_deficient="raise",
        rank_tolerance=RANK_TOLERANCE,
        excluded=tuple(problem.excluded),
    )


def _weighted_rms(rows: Rows, columns: list[int], theta: np.ndarray, sigma: np.ndarray) -> float:
    """RMS of the residuals divided by the joints' noise levels ``sigma``."""
    r = (rows.b - rows.A[:, columns] @ theta) / sigma[rows.joint]
    return float(np.sqrt(np.mean(r**2)))


def _expanded(problem: Problem, fit: LeastSquaresResult, kept: list[int]) -> LeastSquaresResult:
    """The reduced fit with every coefficient: the removed ones 0, std 0, covariance 0."""
    p = problem.p
    theta, covariance = np.zeros(p), np.zeros((p, p))
    theta[kept] = fit.theta
    covariance[np.ix_(kept, kept)] = fit.covariance
    std = np.zeros(p)
    std[kept] = fit.std
    return LeastSquaresResult(
        theta=theta,
        std=std,
        relative_std=relative_std(theta, std),
        covariance=covariance,
        condition_number=fit.condition_number,
        rank=fit.rank,
        method="essential",
        noise_variance=fit.noise_variance,
        residual_rms=fit.residual_rms,
        names=list(problem.names),
        excluded=tuple(problem.excluded),
        joints=fit.joints,
    )
