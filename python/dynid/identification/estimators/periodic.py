"""Periodic-data maximum likelihood (Swevers, Ganseman, Tukel, De Schutter, Van Brussel, "Optimal
robot excitation and identification", IEEE T-RA 13(5), 1997, sec. IV; Olsen, Swevers, Verdonck,
"Maximum likelihood identification of a dynamic robot model", Int. J. Robot. Res. 21(2), 2002).

A periodic exciting trajectory measured over M whole periods repeats its motion M times; what
differs from one period to the next is the noise. So, per training log:

1. cut the log into M >= 2 whole periods of K samples (the period given, or found from the
   autocorrelation of q, :mod:`.period`);
2. average q, qd, qdd and tau over the periods (the averaged positions and their derivatives
   carry M times less noise into the regressor, the averaged torque M times less variance);
3. estimate the noise covariance from the period-to-period scatter,
   Sigma = sum_m sum_k e_mk e_mk^T / (K (M - 1)),  e_mk = tau_m(k) - mean_m tau_m(k)
   (unbiased; independent of the model, so a model error does not inflate it);
4. weighted least squares on the averaged data, joint j's rows weighted by M / Sigma_jj (the
   maximum-likelihood estimate for independent joints; logs pooled by their degrees of
   freedom), with the covariance of the estimate from Sigma / M, cross-joint terms included:
   (A^T A)^-1 A^T C A (A^T A)^-1, C the correlation of the weighted noise of one sample.

The std assumes the noise is white from sample to sample and the model right; the report's
``cost_ratio`` (weighted residual sum of squares over its expectation, N - p) is ~1 then and
measures the lack of fit otherwise: above 1 the std are too small by about its square root.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ... import _checks as checks
from ..identify import IDENTIFIABLE_TOLERANCE, LeastSquaresResult, relative_std
from .base import EstimatorFit, Problem
from .period import MIN_CORRELATION, detect_period, period_starts

#: Singular values of the column-scaled averaged system below this fraction of the largest are
#: null (the tolerance of dynid.least_squares).
RANK_TOLERANCE = 1e-10

#: A joint whose period-to-period scatter is below this fraction of its RMS torque repeats
#: exactly (a simulated log without noise): refused, there is no noise level to weigh by.
EXACT = 1e-10

#: A log whose sample k is further than this many steps from t0 + k dt (dt the mean step) is
#: refused: a period is a number of samples.
TIME_DRIFT = 0.5


@dataclass(frozen=True)
class Averaged:
    """One log's whole periods averaged: the regressor at the averaged states, the averaged
    torques, the scatter's second moment and its degrees of freedom, and the rows used."""

    Y: NDArray[np.float64]  #: (K, n, p)
    tau: NDArray[np.float64]  #: (K, n)
    scatter: NDArray[np.float64]  #: (n, n) sum of e e^T over the periods and samples
    dof: int  #: K (M - 1)
    periods: int  #: M
    used: NDArray[np.bool_]  #: (T,) the log's samples inside a whole period
    report: dict[str, Any]


def periodic(problem: Problem) -> EstimatorFit:
    """The periodic-data ML estimate of ``problem`` (see the module's docstring)."""
    period = problem.options.get("period")
    if period is not None:
        period = checks.positive(period, "period")
    joints = list(problem.joints)
    if not problem.keep[:, joints].all():
        raise ValueError(
            "min_velocity: method 'periodic' averages whole periods and cannot leave rows out; "
            "drop --min-velocity"
        )
    logs = [_average(problem, k, period) for k in range(len(problem.runs))]
    dof = sum(a.dof for a in logs)
    Sigma = np.sum([a.scatter for a in logs], axis=0)[np.ix_(joints, joints)] / dof
    variance = np.diag(Sigma).copy()
    # Rounding alone differs by ~1e-16 of the torque between periods: no noise to weigh by.
    size = np.sqrt(np.mean(np.concatenate([a.tau[:, joints] for a in logs]) ** 2, axis=0))
    if not np.all(variance > (EXACT * size) ** 2):
        zero = [j + 1 for j, v, s in zip(joints, variance, size) if not v > (EXACT * s) ** 2]
        raise ValueError(
            f"period: the torques of joints {zero} repeat exactly from period to period: no "
            "noise to estimate (a simulated log without noise?); use method 'wls'"
        )
    sigma = np.sqrt(variance)
    # Rows of joint j in log k divided by sigma_j / sqrt(M_k): unit noise variance each.
    A = np.concatenate([a.Y[:, joints, :] * (np.sqrt(a.periods) / sigma)[:, None] for a in logs])
    b = np.concatenate([a.tau[:, joints] * (np.sqrt(a.periods) / sigma) for a in logs])
    theta, inverse, rank, condition, free = _solve(A.reshape(-1, problem.p), b.reshape(-1))
    correlation = Sigma / np.outer(sigma, sigma)
    middle = np.einsum("kip,ij,kjq->pq", A, correlation, A)
    covariance = inverse @ middle @ inverse
    covariance[free, :] = covariance[:, free] = np.inf  # as dynid.least_squares: not identified
    std = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    residual = b - A @ theta  # (samples, joints), unit variance each if the model is right
    rows = residual.size
    cost_ratio = float(np.sum(residual**2) / max(rows - rank, 1))
    notes = []
    if rank < problem.p:
        notes.append(
            f"periodic: the averaged data have rank {rank} of {problem.p}; the minimum-norm "
            "estimate is returned (directions no period excites)"
        )
        warnings.warn(notes[-1], RuntimeWarning, stacklevel=2)
    residual_rms = np.sqrt(
        np.mean(
            np.concatenate([a.tau[:, joints] - a.Y[:, joints, :] @ theta for a in logs]) ** 2,
            axis=0,
        )
    )
    result = LeastSquaresResult(
        theta=theta,
        std=std,
        relative_std=relative_std(theta, std),
        covariance=covariance,
        condition_number=condition,
        rank=rank,
        method="periodic",
        noise_variance=variance,
        residual_rms=residual_rms,
        names=problem.names,
        excluded=problem.excluded,
        joints=problem.joints,
    )
    row_weights = np.zeros(problem.tau.shape)  # the physical fit: the whole periods' rows only
    for k, a in enumerate(logs):
        row_weights[problem.starts[k] : problem.starts[k + 1]][a.used] = 1.0
    report = {
        "logs": [a.report for a in logs],
        "noise_std": sigma.tolist(),
        "noise_correlation": correlation.tolist(),
        "noise_dof": int(dof),
        "cost_ratio": cost_ratio,
    }
    return EstimatorFit(result, row_weights, report, tuple(notes))


def _average(problem: Problem, k: int, period: float | None) -> Averaged:
    """Log k of ``problem`` cut into whole periods and averaged (steps 1-3)."""
    log = problem.runs[k]
    label = f"log {k + 1}" + (f" ({log.source})" if log.source else "")
    T = log.t.size
    # A period is a number of samples: sample k must be at t0 + k dt to within half a step
    # (a jittery clock is fine, a drifting or gapped one is not).
    dt = float(log.t[-1] - log.t[0]) / (T - 1)
    drift = float(np.max(np.abs(log.t - log.t[0] - dt * np.arange(T))))
    if drift > TIME_DRIFT * dt:
        raise ValueError(
            f"period: {label}'s sample k is up to {drift / dt:.2g} steps away from t0 + k dt: "
            "resample it to a uniform time base (the default preparation) before method "
            "'periodic'"
        )
    if period is None:
        found = detect_period(log.q)
        if found is None:
            raise ValueError(
                f"period: {label} is not periodic: the autocorrelation of q never comes back "
                f"above {MIN_CORRELATION} within the log ({T * dt:.3g} s); give the period "
                "(--period, in s) if it is periodic, or use another method"
            )
        samples, correlation = float(found[0]), found[1]
    else:
        samples, correlation = period / dt, None
    starts = period_starts(T, samples)
    M = len(starts)
    if M < 2 or int(samples) < 2:
        raise ValueError(
            f"period: {label} holds {T / samples:.2f} periods of {samples * dt:.4g} s; method "
            "'periodic' needs at least 2 whole periods (the noise is their scatter)"
        )
    K = int(samples)
    index = starts[:, None] + np.arange(K)  # (M, K)
    assert log.qd is not None and log.qdd is not None  # a prepared log has them
    q, qd, qdd = (x[index].mean(axis=0) for x in (log.q, log.qd, log.qdd))
    tau = log.tau[index].mean(axis=0)
    e = (log.tau[index] - tau).reshape(-1, log.tau.shape[1])
    used = np.zeros(T, dtype=bool)
    used[index.ravel()] = True
    report = {
        "period_s": samples * dt,
        "period_samples": samples,
        "periods": M,
        "detected": period is None,
        "samples_used": int(used.sum()),
        "samples": T,
    }
    if correlation is not None:
        report["autocorrelation"] = correlation
    return Averaged(
        Y=problem.model.regressor(q, qd, qdd),
        tau=tau,
        scatter=e.T @ e,
        dof=K * (M - 1),
        periods=M,
        used=used,
        report=report,
    )


def _solve(
    A: NDArray[np.float64], b: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], int, float, NDArray[np.bool_]]:
    """theta = A^# b by the SVD of the column-scaled A (truncated at RANK_TOLERANCE), with
    (A^T A)^-1 (the pseudo-inverse when rank deficient), the rank, cond(A) and the parameters
    that enter a null direction (entry above IDENTIFIABLE_TOLERANCE, as dynid.least_squares)."""
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    U, s, Vt = np.linalg.svd(A / norms, full_matrices=False)
    rank = int(np.sum(s > RANK_TOLERANCE * s[0]))
    free = np.abs(Vt[rank:]).max(axis=0, initial=0.0) > IDENTIFIABLE_TOLERANCE
    U, s, Vt = U[:, :rank], s[:rank], Vt[:rank]
    theta = (Vt.T @ ((U.T @ b) / s)) / norms
    inverse = ((Vt.T / s**2) @ Vt) / np.outer(norms, norms)
    singular = np.linalg.svd(A, compute_uv=False)
    condition = float(singular[0] / singular[-1]) if singular[-1] > 0 else float("inf")
    return theta, inverse, rank, condition, free
