"""The weighted solve shared by IDIM-IV and DIDIM: theta = (Z^T W Y)^-1 Z^T W tau over the rows
taking part, with each joint's rows weighted 1 / sigma_j^2 as WLS does, and its covariance.

IDIM-IV solves it with the instruments Z of the simulated closed loop; DIDIM with Z = Y = the
simulated regressor. With the noise covariance Omega = diag(sigma_j^2) per joint (from the
residuals tau - Y theta, with the N - p degrees of freedom shared among the joints as in
``dynid.least_squares``), the covariance of the estimate is the instrumental-variable sandwich

    C = (Z^T W Y)^-1 Z^T W Omega W Z (Y^T W Z)^-1

(the IV covariance of Janot, Vandanjon & Gautier, IEEE TCST 2014, with WLS's per-joint
weighting); for Z = Y and W = Omega^-1 it is the WLS covariance (Y^T Omega^-1 Y)^-1. The noise
of closed-loop data, filtered and differentiated, is far from white; the middle factor is
therefore computed with a noise model per joint (:func:`_noise_moment`), which for white noise
is the formula above.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..identify import VARIANCE_FLOOR, LeastSquaresResult, relative_std
from .base import EstimatorFit, Problem

#: Order of the autoregressive model of each joint's residual (the covariance's noise model).
AR_ORDER = 10


@dataclass(frozen=True, eq=False)
class WeightedSolve:
    """One solve: the estimate, its covariance and the per-joint noise of its residuals."""

    theta: NDArray[np.float64]
    covariance: NDArray[np.float64]
    noise_variance: NDArray[np.float64]  #: (joints,) sigma_j^2 of tau - Y theta
    residual_rms: NDArray[np.float64]  #: (joints,)
    condition_number: float  #: of the weighted Z^T W Y, the matrix inverted
    rank: int


def rows(problem: Problem) -> NDArray[np.bool_]:
    """(T, n) the rows that take part: kept, of a joint not excluded."""
    taking = problem.keep.copy()
    taking[:, list(problem.excluded)] = False
    return taking


def solve(
    problem: Problem,
    Z: NDArray[np.float64],
    variance: NDArray[np.float64],
) -> WeightedSolve:
    """theta = (Z^T W Y)^-1 Z^T W tau with W = 1 / sigma_j^2 on joint j's rows (``variance``
    per joint of ``problem.joints``, floored as WLS floors it); ValueError when Z^T W Y is
    singular (the instruments do not excite every coefficient)."""
    taking = rows(problem)
    joints = list(problem.joints)
    weight = np.zeros(problem.n)
    weight[joints] = 1.0 / _floored(variance)
    w = np.where(taking, weight, 0.0)
    Zw = Z * w[:, :, None]
    Y, tau = problem.Y, problem.tau
    A = np.einsum("tjp,tjq->pq", Zw, Y)
    scale = np.sqrt(np.abs(np.diag(A))) + (np.abs(np.diag(A)) == 0)  # column scaling
    scaled = A / scale[:, None] / scale[None, :]
    singular = np.linalg.svd(scaled, compute_uv=False)
    rank = int(np.sum(singular > 1e-10 * singular[0]))
    if rank < problem.p:
        raise ValueError(
            f"method: the simulated closed loop does not excite every coefficient (rank {rank} "
            f"of {problem.p} of Z^T W Y); check the controller, the reference and the log"
        )
    theta = np.linalg.solve(A, np.einsum("tjp,tj->p", Zw, tau))
    residual = np.where(taking, tau - Y @ theta, 0.0)
    noise = noise_variance(problem, residual)
    middle = _noise_moment(problem, Zw, residual)
    inverse = np.linalg.inv(A)
    covariance = inverse @ middle @ inverse.T
    covariance = 0.5 * (covariance + covariance.T)
    counts = taking[:, joints].sum(axis=0)
    rms = np.sqrt((residual[:, joints] ** 2).sum(axis=0) / counts)
    return WeightedSolve(theta, covariance, noise, rms, float(singular[0] / singular[-1]), rank)


def _noise_moment(
    problem: Problem, Zw: NDArray[np.float64], residual: NDArray[np.float64]
) -> NDArray[np.float64]:
    """E[(Z^T W e)(Z^T W e)^T] for the residual e of each joint modelled as AR noise,
    e = H u with H = 1 / (1 - a_1 z^-1 - ... - a_m z^-m) fitted to the residual by least
    squares and u white of variance s_u^2 (the noise model of the refined IV, Young 2011;
    Brunot, Janot, Young & Carrillo, Control Eng. Practice 2018). Then Z^T W e = sum_s
    (H* Zw)_s u_s, H* the time-reversed filter (:func:`adjoint_filter`), so the moment is
    s_u^2 (H* Zw)^T (H* Zw) per joint and run. For white residuals (a = 0) it is the textbook
    sigma^2 Z^T W^2 Z; for the coloured residuals of filtered, differentiated positions it is
    what counts: their power at the instruments' frequencies, not their total power."""
    taking = rows(problem)
    moment = np.zeros((problem.p, problem.p))
    for begin, end in zip(problem.starts[:-1], problem.starts[1:]):
        for j in problem.joints:
            e = np.where(taking[begin:end, j], residual[begin:end, j], 0.0)
            a, innovation = _autoregression(e)
            filtered = adjoint_filter(a, Zw[begin:end, j, :])
            moment += innovation * filtered.T @ filtered
    return moment


def adjoint_filter(a: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64]:
    """(H* x)_s = sum_{k >= 0} h_k x_{s+k} along axis 0, h the impulse response of
    H = 1 / (1 - a_1 z^-1 - ... - a_m z^-m) (stable): the time-reversed all-pole filter. h is
    computed until it has decayed below 1e-13 of its peak (at most len(x) samples), the sum by
    FFT convolution."""
    T = x.shape[0]
    m = a.size
    h = [1.0]
    peak = 1.0
    while len(h) < T:
        value = sum(a[k] * h[-1 - k] for k in range(min(m, len(h))))
        h.append(value)
        peak = max(peak, abs(value))
        if len(h) > m and max(abs(v) for v in h[-max(m, 1) :]) < 1e-13 * peak:
            break
    response = np.asarray(h)
    size = 1 << int(np.ceil(np.log2(T + response.size)))
    spectrum = np.fft.rfft(x[::-1], size, axis=0) * np.fft.rfft(response, size)[:, None]
    out: NDArray[np.float64] = np.fft.irfft(spectrum, size, axis=0)[:T][::-1]
    return out


def _autoregression(e: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """AR(m) coefficients a and innovation variance of the series ``e`` by least squares,
    m = min(AR_ORDER, len(e) // 10) (0: white)."""
    m = min(AR_ORDER, len(e) // 10)
    if m == 0:
        return np.zeros(0), float(e @ e / max(len(e), 1))
    lagged = np.column_stack([e[m - k : len(e) - k] for k in range(1, m + 1)])
    solution, *_ = np.linalg.lstsq(lagged, e[m:], rcond=None)
    a: NDArray[np.float64] = np.asarray(solution, dtype=np.float64)
    u = e[m:] - lagged @ a
    # A fit with a pole on or outside the unit circle would make H unstable: white instead.
    if a.size and np.max(np.abs(np.roots(np.concatenate([[1.0], -a])))) >= 1.0:
        return np.zeros(0), float(e @ e / len(e))
    return a, float(u @ u / max(len(u) - m, 1))


def noise_variance(problem: Problem, residual: NDArray[np.float64]) -> NDArray[np.float64]:
    """sigma_j^2 = ||r_j||^2 / (N_j - p N_j / N) per joint of ``problem.joints`` (the N - p
    degrees of freedom shared in proportion to the rows, as ``dynid.least_squares``)."""
    taking = rows(problem)
    joints = list(problem.joints)
    counts = taking[:, joints].sum(axis=0).astype(float)
    total = counts.sum()
    if total <= problem.p:
        raise ValueError(f"log: {int(total)} rows for {problem.p} coefficients; more are needed")
    squares = (np.where(taking, residual, 0.0)[:, joints] ** 2).sum(axis=0)
    variance: NDArray[np.float64] = squares / (counts * (total - problem.p) / total)
    return variance


def result(problem: Problem, fit: WeightedSolve, method: str) -> LeastSquaresResult:
    """The estimate as the log identification's result holds it."""
    std = np.sqrt(np.maximum(np.diag(fit.covariance), 0.0))
    return LeastSquaresResult(
        theta=fit.theta,
        std=std,
        relative_std=relative_std(fit.theta, std),
        covariance=fit.covariance,
        condition_number=fit.condition_number,
        rank=fit.rank,
        method=method,
        noise_variance=fit.noise_variance,
        residual_rms=fit.residual_rms,
        names=list(problem.names),
        excluded=problem.excluded,
        joints=problem.joints,
    )


def settled(old: NDArray[np.float64], new: WeightedSolve, threshold: float) -> tuple[bool, float]:
    """Whether no coefficient moved by more than ``threshold`` of its std, and the largest
    move in std units."""
    # A std below rounding (exact data) is raised to it: moves of the last digits are no moves.
    rounding = 1e-12 * max(float(np.abs(new.theta).max()), float(np.finfo(float).tiny))
    std = np.maximum(np.sqrt(np.maximum(np.diag(new.covariance), 0.0)), rounding)
    moved = np.abs(new.theta - old)
    scaled = moved / std
    step = float(scaled.max())
    return step <= threshold, step


def _floored(variance: NDArray[np.float64]) -> NDArray[np.float64]:
    """The variances as WLS uses them: at least VARIANCE_FLOOR times the largest; all ones when
    every joint fits exactly."""
    largest = float(np.max(variance))
    if not np.isfinite(largest) or largest <= 0:
        return np.ones_like(variance)
    return np.maximum(variance, VARIANCE_FLOOR * largest)


#: Relaxation of the iteration: halved down to this when a step does not halve the one before.
SMALLEST_RELAXATION = 1 / 64

#: At the smallest relaxation, an iterate that moves by less than this many std per iteration
#: has settled at a jump of the map (see :func:`iterate`).
SETTLED_AT_JUMP_STD = 0.01


@dataclass(frozen=True, eq=False)
class Iterated:
    """The last solve of an iteration and how it went."""

    fit: WeightedSolve
    steps: list[float]  #: |F(theta_k) - theta_k| of each iteration, largest in std
    settled: bool
    at_jump: bool  #: settled where F jumps over theta (the last step is the jump's size)
    simulation_s: float  #: wall time spent simulating the loop (and its regressor)


def iterate(
    problem: Problem,
    iterations: int,
    simulated: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    one_solve: Callable[[NDArray[np.float64], NDArray[np.float64]], WeightedSolve],
    threshold: float,
) -> Iterated:
    """theta_{k+1} = F(theta_k) from the WLS estimate: ``simulated(theta)`` the regressor of
    the loop simulated with theta, ``one_solve(Z, variance)`` the solve on it; settled when
    no coefficient moves by more than ``threshold`` std.

    Coulomb friction makes F piecewise continuous only: a simulated velocity that crosses zero
    on the other side of a sample instant flips a sign(qd) entry of the simulated regressor,
    and near the solution F may jump over it, the plain iteration then cycling between points
    a fraction of a std apart. So when a step does not halve the one before, the next ones are
    relaxed, theta + lambda (F(theta) - theta), lambda halved down to SMALLEST_RELAXATION
    (Krasnoselskii-Mann averaging); the iterate then converges to the point where F jumps over
    it, taken as settled when it moves by less than SETTLED_AT_JUMP_STD per iteration (the
    report keeps the jump's size, the last step)."""
    theta = problem.start.theta
    variance = problem.start.noise_variance
    steps: list[float] = []
    spent = 0.0
    relax = 1.0
    done = at_jump = False
    fit = None
    for _ in range(iterations):
        began = time.perf_counter()
        Z = simulated(theta)
        spent += time.perf_counter() - began
        fit = one_solve(Z, variance)
        done, step = settled(theta, fit, threshold)
        steps.append(step)
        if done:
            break
        if relax == SMALLEST_RELAXATION and relax * step <= SETTLED_AT_JUMP_STD:
            # The estimate is the iterate itself, between F's values on the two sides.
            fit = replace(fit, theta=theta)
            done = at_jump = True
            break
        if len(steps) > 1 and step > 0.5 * steps[-2]:
            relax = max(relax / 2, SMALLEST_RELAXATION)
        theta = theta + relax * (fit.theta - theta)
        variance = fit.noise_variance
    assert fit is not None  # iterations >= 1
    return Iterated(fit, steps, done, at_jump, spent)


def finished(
    name: str, problem: Problem, run: Iterated, options_report: dict[str, Any], notes: list[str]
) -> EstimatorFit:
    """The estimator's answer after :func:`iterate`: the result, its report (the loop's
    ``options_report``, the iterations, how they settled) and ``notes`` with what the iteration
    says (not settled, settled at a jump of the map)."""
    steps = run.steps
    notes = list(notes)
    if not run.settled:
        notes.insert(
            0,
            f"{name}: not settled after {len(steps)} iterations (last step {steps[-1]:.3g} "
            "std); raise iterations or check the controller's description",
        )
    if run.at_jump:
        notes.append(
            f"{name}: settled where the iteration's map jumps (a simulated velocity's sign "
            f"flips between two samples): the jump is {steps[-1]:.2g} std"
        )
    report = {
        **options_report,
        "iterations": len(steps),
        "settled": run.settled,
        "settled_at_jump": run.at_jump,
        "steps_std": steps,
        "simulation_s": run.simulation_s,
    }
    return EstimatorFit(result(problem, run.fit, name), None, report, tuple(notes))
