"""Least-squares identification of the base parameters from a linear model Y theta = tau.

Lecture (Robotics 2, "Least Squares (LS) identification", p. 27): evaluate the regressor on
N = nc * n equations, with N >> p, stack them into Y theta = u and solve by pseudoinversion;
a weighted pseudoinverse accounts for different noise levels. "Additional remarks on LS
identification" (p. 28): stack "all time evaluations sequenced by the rows" of the original Y
(all samples of joint 1, then joint 2, ...), and check full column rank numerically.

The pseudoinverse is never formed from the normal equations (Y^T Y)^-1 Y^T, which square the
condition number: [A | b] is factored by Householder QR, keeping only the triangular factor R
(per joint, chunk by chunk: _qr.py, so neither Q nor the stacked matrix is ever formed), and R's
first p columns, scaled to unit norm, by the SVD R D^-1 = U S V^T; the one factorisation
A D^-1 = (Q U) S V^T serves the rank test, the solution and the covariance alike.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from .._equality import ValueEquality
from .._threads import blas_single_threaded
from ._qr import GroupedTriangularFactors, solve_triangular_system

METHODS = ("ols", "wls")
ON_RANK_DEFICIENT = ("raise", "warn")

#: WLS: a joint's noise variance is floored at this fraction of the largest one, so a joint fitted
#: exactly (noise-free data, or rows that are identically zero) gets a weight at most 1000 times
#: that of the noisiest joint instead of an infinite one.
VARIANCE_FLOOR = 1e-6

#: A parameter is not identifiable when its entry in a null-space direction (column-scaled
#: coordinates, unit vectors) exceeds this; exact structural dependencies leave ~1e-15 elsewhere.
IDENTIFIABLE_TOLERANCE = 1e-8


def relative_std(theta: NDArray[np.float64], std: NDArray[np.float64]) -> NDArray[np.float64]:
    """100 std / |theta| in percent; inf where theta is exactly zero."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(theta != 0, 100.0 * std / np.abs(theta), np.inf)


class RankDeficientError(ValueError):
    """The data do not excite all base parameters: the stacked regressor has rank < p."""


@dataclass(frozen=True, eq=False)
class LeastSquaresResult(ValueEquality):
    """An estimate theta of the p parameters with its uncertainty (see :func:`least_squares`)."""

    theta: NDArray[np.float64]  #: (p,) estimate
    std: NDArray[np.float64]  #: (p,) standard deviations, sqrt of the covariance diagonal
    relative_std: NDArray[np.float64]  #: (p,) 100 std / |theta| in percent, inf where theta == 0
    covariance: NDArray[np.float64]  #: (p, p)
    condition_number: float  #: of the stacked, weighted matrix solved (unscaled columns)
    rank: int  #: numerical rank of the column-scaled stacked matrix
    method: str  #: "ols" or "wls"
    noise_variance: NDArray[np.float64]  #: (n_groups,) per joint, from the OLS residuals
    residual_rms: NDArray[np.float64]  #: (n_groups,) per joint RMS of tau - Y theta
    names: list[str] | None  #: parameter names, if given
    excluded: tuple[int, ...]  #: joints (0-based) whose rows were left out
    joints: tuple[int, ...] = ()  #: the joint (0-based) of each entry of the per-joint arrays

    def predict(self, Y: ArrayLike) -> NDArray[np.float64]:
        """Y (..., p) @ theta: the torques predicted by the estimate."""
        Y = _finite(Y, "Y")
        if Y.ndim == 0 or Y.shape[-1] != self.theta.size:
            raise ValueError(f"Y: expected shape (..., {self.theta.size}), got {Y.shape}")
        with np.errstate(over="ignore", invalid="ignore"):
            tau = Y @ self.theta
        if not np.all(np.isfinite(tau)):
            raise ValueError(
                f"Y: the predicted torque Y @ theta overflows float64 (max |Y| "
                f"{np.abs(Y).max():.3g}, max |theta| {np.abs(self.theta).max():.3g})"
            )
        return tau

    def table(self) -> str:
        """An aligned text table: name, value, standard deviation, relative std in percent."""
        names = self.names or [f"theta[{k}]" for k in range(self.theta.size)]
        width = max(9, *(len(name) for name in names))
        lines = [f"{'parameter':<{width}}  {'value':>13}  {'std':>11}  {'rel.std %':>10}"]
        for name, value, std, rel in zip(names, self.theta, self.std, self.relative_std):
            lines.append(f"{name:<{width}}  {value:>13.6g}  {std:>11.4g}  {rel:>10.3g}")
        return "\n".join(lines)


def stack_by_joint(
    Y: ArrayLike, tau: ArrayLike, exclude_joints: Sequence[int] = ()
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Stack T samples of an n-joint model into A theta = b, sorted by joint (lecture p. 28).

    ``Y`` is (T, n, p) and ``tau`` (T, n); one sample (n, p) / (n,) counts as T = 1. Returns
    A (rows, p), b (rows,) and group (rows,), the joint of each row: all T samples of the first
    kept joint in time order, then the next joint, ... The joints (0-based second-axis indices)
    in ``exclude_joints`` are left out, e.g. ``(0,)`` drops joint 1's gravity row as the paper.
    """
    Y3, tau2 = _samples(Y, tau)
    T, n, p = Y3.shape
    keep = [j for j in range(n) if j not in _excluded(exclude_joints, n)]
    A = Y3[:, keep, :].transpose(1, 0, 2).reshape(-1, p)
    b = tau2[:, keep].T.reshape(-1)
    group: NDArray[np.int64] = np.repeat(np.array(keep, dtype=np.int64), T)
    return np.ascontiguousarray(A), np.ascontiguousarray(b), group


@blas_single_threaded  # QR blocks of ~1000 x p: faster on one thread (_threads.py)
def least_squares(
    Y: ArrayLike,
    tau: ArrayLike,
    *,
    method: str = "ols",
    exclude_joints: Sequence[int] = (),
    names: Sequence[str] | None = None,
    on_rank_deficient: str = "raise",
    rank_tolerance: float = 1e-10,
) -> LeastSquaresResult:
    """Estimate theta in Y theta = tau by ordinary or weighted least squares (lecture p. 27).

    Two forms of input:

    - per joint: ``Y`` (T, n, p) and ``tau`` (T, n), T samples of an n-joint model. The rows are
      stacked by :func:`stack_by_joint` (N = T n rows minus the excluded joints', p columns,
      N_j rows of joint j); each joint is a group with its own noise level for WLS. One sample
      is ``Y[np.newaxis]`` (1, n, p) with ``tau`` (1, n) or (n,).
    - stacked: ``Y`` (N, p) and ``tau`` (N,), one system of N rows with one noise level, as for
      numpy.linalg.lstsq; identical to ``Y[:, np.newaxis]``, ``tau[:, np.newaxis]`` (one joint,
      N samples). There is a single group, so ``method="wls"`` has a single sigma and gives the
      estimate and covariance of OLS; ``exclude_joints`` must be empty.

    ``method="ols"``: theta minimises ||b - A theta||; covariance sigma^2 (A^T A)^-1 with
    sigma^2 = ||r||^2 / (N - p), with (A^T A)^-1 = D^-1 V S^-2 V^T D^-1 from the factors
    (p becomes the rank in the rank-deficient case, here and below).

    ``method="wls"``: the per-joint noise variance is estimated from the OLS residuals,
    sigma_j^2 = ||r_j||^2 / (N_j - p N_j / N): the N - p residual degrees of freedom shared among
    the joints in proportion to their rows, so the row-weighted mean of the sigma_j^2 is the
    pooled estimate. Each is unbiased when all joints share the same noise level and leverage;
    the exact share (N_j minus the trace of joint j's block of the hat matrix) differs little
    for N >> p, but a much noisier joint leaks into the others' OLS residuals and makes their
    variances, hence the WLS std, conservative. Variances below ``VARIANCE_FLOOR`` times the
    largest are raised to it (a joint with exactly zero residual would get an infinite weight); if
    all are zero, the weights are 1. Rows of joint j are then divided by sigma_j and solved again
    by the same QR + SVD; the covariance is (A^T W A)^-1 with W = diag(1 / sigma_j^2), taking the
    estimated variances as known.

    ``noise_variance`` holds the sigma_j^2 above (before the floor) for both methods, and
    ``residual_rms`` the per-joint RMS residual of the final fit, in torque units; both follow
    ``joints``, the kept joints in increasing order (a stacked Y: one entry, ``joints == (0,)``).

    Rank (lecture p. 28, "numerical check of full column rank"): the number of singular values of
    the column-scaled matrix above ``rank_tolerance`` times the largest. When it is below p,
    ``on_rank_deficient="raise"`` raises :class:`RankDeficientError` naming the parameters that
    carry the unexcited directions; ``"warn"`` issues a RuntimeWarning and returns the truncated-
    SVD solution, which is the minimum-norm one in column-scaled coordinates (it minimises
    ||D theta|| with D the column norms, so it does not depend on the parameters' units), with
    std, relative_std and the covariance rows/columns set to inf for the parameters that enter a
    null-space direction; the others are identifiable and keep their (pseudo-inverse)
    covariance. Fewer rows than parameters always raise. With exactly as many rows as the rank
    there are no degrees of freedom left for the noise: a RuntimeWarning, std = inf.

    ``condition_number`` is the 2-norm condition number of the matrix actually solved (after row
    exclusion and, for WLS, weighting), with its columns as given, so it depends on the
    parameters' units; the column-scaled one (unit norms), on which the rank test and the
    solution are computed, is at most sqrt(p) times the smallest achievable by any column scaling
    (van der Sluis), and can be much smaller than this one.
    """
    method, on_rank_deficient = _check_options(method, on_rank_deficient, rank_tolerance)
    Y, tau, excluded = _grouped(Y, tau, exclude_joints)
    T, n, p = Y.shape
    factors = GroupedTriangularFactors(n, p, tuple(j for j in range(n) if j not in excluded))
    for begin in range(0, T, CHUNK_SAMPLES):  # bounded scratch memory, whatever T
        factors.add(Y[begin : begin + CHUNK_SAMPLES], tau[begin : begin + CHUNK_SAMPLES])
    return solve_factors(
        factors,
        method=method,
        names=names,
        on_rank_deficient=on_rank_deficient,
        rank_tolerance=rank_tolerance,
        excluded=excluded,
    )


#: Samples per QR update: large enough for blocked Householder QR, small enough for the cache.
CHUNK_SAMPLES = 4096


def _check_options(method: str, on_rank_deficient: str, rank_tolerance: float) -> tuple[str, str]:
    method = _choice(method, METHODS, "method")
    on_rank_deficient = _choice(on_rank_deficient, ON_RANK_DEFICIENT, "on_rank_deficient")
    _check_rank_tolerance(rank_tolerance)
    return method, on_rank_deficient


def _check_rank_tolerance(rank_tolerance: float) -> float:
    if not (isinstance(rank_tolerance, (int, float)) and 0.0 < rank_tolerance < 1.0):
        raise ValueError(f"rank_tolerance: expected a number in (0, 1), got {rank_tolerance!r}")
    return float(rank_tolerance)


def solve_factors(
    factors: GroupedTriangularFactors,
    *,
    method: str,
    names: Sequence[str] | None,
    on_rank_deficient: str,
    rank_tolerance: float,
    excluded: tuple[int, ...],
) -> LeastSquaresResult:
    """The OLS or WLS estimate of :func:`least_squares` from accumulated triangular factors."""
    rows, p = factors.rows, factors.p
    if names is not None:
        names = checks.names(names, "names", p)
    if rows < p:
        raise RankDeficientError(
            f"Y: {rows} stacked rows for {p} parameters; at least {p} rows are needed "
            f"(the lecture asks for N >> p): use more samples"
        )
    joints = np.array(factors.joints, dtype=np.int64)
    counts = np.array([factors.counts[j] for j in factors.joints], dtype=float)
    # Factors are in units where max |A| and max |b| are in [0.5, 1) (_qr.py): squares and norms
    # of values near the float64 limits would overflow, tiny ones underflow. Everything is
    # scaled back at the end.
    a_exp, b_exp = factors.a_exp or 0, factors.b_exp or 0
    sizes = f"max |Y| {factors.max_a:.3g}, max |tau| {factors.max_b:.3g}"

    def check_rank(rank: int, null: NDArray[np.float64], previous: int) -> None:
        if rank < min(p, previous):  # warn once per drop (WLS re-checks its weighted matrix)
            message = _rank_message(rank, p, null, names)
            if on_rank_deficient == "raise":
                raise RankDeficientError(message)
            warnings.warn(message, RuntimeWarning, stacklevel=4)

    # OLS (p. 27): theta = Y^# u through QR + SVD, never the normal equations.
    theta, unit_cov, rank, null, cond = solve_triangular_system(
        factors.combined(), p, rank_tolerance
    )
    check_rank(rank, null, p)
    squares = factors.residual_squares(theta)
    dof = rows - rank
    if dof == 0:
        warnings.warn(
            f"Y: {rows} rows for rank {rank} leave no degrees of freedom to estimate the noise; "
            "std set to inf (use more samples)",
            RuntimeWarning,
            stacklevel=3,
        )
        variance = np.full(joints.size, np.inf)
    else:  # sigma_j^2 = ||r_j||^2 / (N_j - p N_j / N)
        variance = squares / (counts * dof / rows)

    if dof == 0:
        covariance = np.full((p, p), np.inf)
    elif method == "ols":
        covariance = (squares.sum() / dof) * unit_cov
    else:  # WLS (p. 27, weighted pseudoinverse): rows of joint j divided by sigma_j
        largest = variance.max()
        floored = np.maximum(variance, VARIANCE_FLOOR * largest)
        if largest == 0:  # every joint fitted exactly: equal weights
            floored = np.ones_like(variance)
        ols_rank = rank
        theta, unit_cov, rank, null, cond = solve_triangular_system(
            factors.combined(1.0 / np.sqrt(floored)), p, rank_tolerance
        )
        check_rank(rank, null, ols_rank)
        covariance = unit_cov if largest > 0 else np.zeros((p, p))
        squares = factors.residual_squares(theta)

    if rank < p:  # parameters entering a null direction have no finite variance
        free = np.abs(null).max(axis=1) > IDENTIFIABLE_TOLERANCE
        covariance = covariance.copy()
        covariance[free, :] = np.inf
        covariance[:, free] = np.inf
    residual_rms = np.sqrt(squares / counts)
    # Back to the units given: theta scales by 2^(b_exp - a_exp), the variances by its square.
    std = np.sqrt(np.maximum(np.diag(covariance), 0.0))  # before its square can underflow
    theta = _unscale(theta, b_exp - a_exp, "Y, tau", "the estimate theta ~ tau / Y", sizes)
    std = _unscale(std, b_exp - a_exp, "Y, tau", "the standard deviation of theta", sizes)
    covariance = _unscale(
        covariance, 2 * (b_exp - a_exp), "Y, tau", "the covariance of theta", sizes
    )
    variance = _unscale(variance, 2 * b_exp, "tau", "the noise variance", sizes)
    residual_rms = _unscale(residual_rms, b_exp, "tau", "the residual RMS", sizes)
    relative = relative_std(theta, std)
    return LeastSquaresResult(
        theta=theta,
        std=std,
        relative_std=relative,
        covariance=covariance,
        condition_number=cond,
        rank=rank,
        method=method,
        noise_variance=variance,
        residual_rms=residual_rms,
        names=names,
        excluded=excluded,
        joints=tuple(int(j) for j in joints),
    )


def _unscale(
    x: NDArray[np.float64], exponent: int, names: str, what: str, sizes: str
) -> NDArray[np.float64]:
    """x * 2^exponent (exact), or a ValueError naming ``names`` if a finite value overflows."""
    with np.errstate(over="ignore", under="ignore"):
        out = np.ldexp(x, exponent)
    if np.any(np.isfinite(x) & ~np.isfinite(out)):
        raise ValueError(
            f"{names}: {what} overflows float64 ({sizes}): express Y and tau in other units"
        )
    return out


def _rank_message(rank: int, p: int, null: NDArray[np.float64], names: list[str] | None) -> str:
    # The right-singular vectors of the zero singular values are the parameter combinations the
    # data cannot see; their largest entries name the least excited parameters.
    label = names or [f"theta[{k}]" for k in range(p)]
    weight = np.linalg.norm(null, axis=1)
    order = [k for k in np.argsort(-weight, kind="stable") if weight[k] > 0.3 * weight.max()][:8]
    direction = null[:, 0]
    terms = [
        k for k in np.argsort(-np.abs(direction), kind="stable")[:4] if abs(direction[k]) > 0.1
    ]
    combination = " ".join(f"{direction[k]:+.3g}*{label[k]}" for k in terms)
    return (
        f"the data do not excite all base parameters: the stacked regressor has rank {rank} < {p} "
        f"({p - rank} unexcited direction(s)); least excited: {', '.join(label[k] for k in order)} "
        f"(e.g. the combination {combination} of the column-scaled parameters has no effect on "
        "the data). Use more varied data (more configurations, different values of every "
        "joint, richer velocities and accelerations)."
    )


def _grouped(
    Y: ArrayLike, tau: ArrayLike, exclude_joints: Sequence[int]
) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[int, ...]]:
    """least_squares' input as Y (T, n, p), tau (T, n) and the excluded joints (sorted)."""
    Y = _finite(Y, "Y")
    if Y.ndim == 2:
        Y, tau = _stacked(Y, tau, exclude_joints)
        return Y, tau, ()
    Y, tau = _samples(Y, tau)
    return Y, tau, tuple(sorted(_excluded(exclude_joints, Y.shape[1])))


def _stacked(
    Y: NDArray[np.float64], tau: ArrayLike, exclude_joints: Sequence[int]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A stacked system Y (N, p), tau (N,) as one joint of N samples: (N, 1, p), (N, 1).

    One group, so one noise level: read as one sample of N joints, every row would be its own
    group, with its own 1-row QR factor and (for WLS) its own noise variance (issue 22).
    """
    if 0 in Y.shape:
        raise ValueError(f"Y: expected a non-empty (N, p) or (T, n, p) array, got shape {Y.shape}")
    tau = _finite(tau, "tau")
    if tau.shape != Y.shape[:1]:
        raise ValueError(
            f"tau: expected shape ({Y.shape[0]},) to match the stacked Y {Y.shape}, got {tau.shape}"
        )
    empty = not isinstance(exclude_joints, (str, bytes)) and np.size(exclude_joints) == 0
    if not empty:
        raise ValueError(
            f"exclude_joints: a stacked Y (N, p) has no joints to exclude, got "
            f"{exclude_joints!r}; pass Y (T, n, p) and tau (T, n) to leave joints out"
        )
    return Y[:, np.newaxis, :], tau[:, np.newaxis]


def _samples(Y: ArrayLike, tau: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    Y = _finite(Y, "Y")
    tau = _finite(tau, "tau")
    if Y.ndim == 2:  # one sample (n, p)
        Y = Y[np.newaxis]
    if Y.ndim != 3 or 0 in Y.shape:
        raise ValueError(f"Y: expected a non-empty (T, n, p) or (n, p) array, got shape {Y.shape}")
    expected = Y.shape[:2]
    if tau.ndim == 1 and expected[0] == 1:
        tau = tau[np.newaxis]
    if tau.shape != expected:
        raise ValueError(f"tau: expected shape {expected} to match Y {Y.shape}, got {tau.shape}")
    return Y, tau


def _excluded(exclude_joints: Sequence[int], n: int) -> set[int]:
    values = checks.indices(exclude_joints, "exclude_joints", n)
    if len(set(values)) == n:
        raise ValueError(f"exclude_joints: {exclude_joints!r} leaves no joint of {n}")
    return {int(j) for j in values}


def _choice(value: object, options: tuple[str, ...], name: str) -> str:
    if not isinstance(value, str) or value not in options:
        raise ValueError(f"{name}: expected one of {options}, got {value!r}")
    return value


def _finite(value: ArrayLike, name: str) -> NDArray[np.float64]:
    return real_array(value, name)
