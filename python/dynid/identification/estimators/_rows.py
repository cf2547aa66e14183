"""What the robust, errors-in-variables and essential-parameter estimators share: the stacked rows
of a :class:`~.base.Problem`, a column-scaled weighted solve, the sandwich covariance over
contiguous blocks of samples, and the :class:`LeastSquaresResult` they return.

The sandwich (Huber 1967; Huber, Robust Statistics, 1981, sect. 7.6) of an estimator defined by
sum_i psi_i(theta) = 0 is H^-1 V H^-1 with H = -sum_i d psi_i / d theta and V the covariance of
sum_i psi_i. V is estimated from the scores summed over B contiguous blocks of samples (batch
means; the idea of Kuensch's block jackknife, Ann. Statist. 17(3), 1989, which
``identification/gain_consistency.py`` uses): residuals of filtered logs and accelerations
differentiated from positions are correlated over neighbouring samples, and all joints' rows of
one sample share its state, so rows are not independent. Blocks much longer than the
correlation time make the block sums independent; with independent rows the estimate equals
the row-wise sandwich up to its sampling error (B - 1 degrees of freedom, so B >> p).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .._qr import solve_triangular_system, upper_triangle
from ..identify import LeastSquaresResult, RankDeficientError, relative_std
from .base import Problem

#: Blocks of the sandwich's middle matrix: at least this many, and at least 4 p (V has p (p+1)/2
#: entries to estimate from the B block sums).
MIN_BLOCKS = 100
#: Rank test of the column-scaled weighted matrix, as least_squares' default.
RANK_TOLERANCE = 1e-10


@dataclass(frozen=True)
class Rows:
    """The rows that take part (kept, joint not excluded): A theta = b, the joint and the sample
    of each row, and the contiguous block of samples it belongs to."""

    A: NDArray[np.float64]  #: (N, p)
    b: NDArray[np.float64]  #: (N,)
    joint: NDArray[np.int64]  #: (N,) position of the row's joint in ``joints``
    sample: NDArray[np.int64]  #: (N,) the row's sample in the stacked logs
    block: NDArray[np.int64]  #: (N,) its block of contiguous samples
    joints: tuple[int, ...]  #: the joints that take part (0-based)

    @property
    def N(self) -> int:
        return int(self.b.size)

    def per_joint(self, values: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        """``values`` (N,) split by joint, in the order of ``joints``."""
        return [values[self.joint == k] for k in range(len(self.joints))]


def stacked_rows(problem: Problem) -> Rows:
    """The kept rows of ``problem`` stacked joint by joint (as ``stack_by_joint``)."""
    joints = problem.joints
    T, p = problem.tau.shape[0], problem.p
    parts_A, parts_b, parts_j, parts_t = [], [], [], []
    for k, j in enumerate(joints):
        t = np.flatnonzero(problem.keep[:, j])
        parts_A.append(problem.Y[t, j, :])
        parts_b.append(problem.tau[t, j])
        parts_j.append(np.full(t.size, k, dtype=np.int64))
        parts_t.append(t.astype(np.int64))
    sample = np.concatenate(parts_t)
    blocks = min(T, max(MIN_BLOCKS, 4 * p))
    return Rows(
        A=np.concatenate(parts_A).reshape(-1, p),
        b=np.concatenate(parts_b),
        joint=np.concatenate(parts_j),
        sample=sample,
        block=sample * blocks // max(T, 1),
        joints=joints,
    )


def weighted_solve(
    A: NDArray[np.float64], b: NDArray[np.float64], w: NDArray[np.float64], what: str
) -> tuple[NDArray[np.float64], int, float]:
    """theta minimising sum_i (w_i (b_i - a_i theta))^2 by QR and the SVD of the column-scaled
    factor (``solve_triangular_system``, as least_squares), its rank and condition number;
    RankDeficientError naming ``what`` below full rank."""
    p = A.shape[1]
    R = upper_triangle(np.column_stack([A * w[:, None], b * w]))
    if R.shape[0] < p + 1:
        raise RankDeficientError(f"{what}: {R.shape[0]} weighted rows for {p} parameters")
    theta, _, rank, _, cond = solve_triangular_system(R, p, RANK_TOLERANCE)
    if rank < p:
        raise RankDeficientError(
            f"{what}: the weighted rows have rank {rank} < {p} (too many rows weighted 0?)"
        )
    return theta, rank, cond


def block_sums(rows: Rows, scores: NDArray[np.float64]) -> NDArray[np.float64]:
    """(B, k) the scores (N, k) summed over each block of contiguous samples."""
    count = int(rows.block.max()) + 1 if rows.N else 0
    sums = np.zeros((count, scores.shape[1]))
    np.add.at(sums, rows.block, scores)
    return sums


def sandwich(
    H: NDArray[np.float64], sums: NDArray[np.float64], N: int, p: int
) -> NDArray[np.float64]:
    """H^-1 V H^-1 with V = N / (N - p) sum_b s_b s_b^T (the block sums ``sums``; the factor is
    the usual degrees-of-freedom correction), H inverted with its diagonal scaled to 1."""
    d = np.sqrt(np.abs(np.diag(H)))
    d[d == 0] = 1.0
    inverse = np.linalg.inv(H / np.outer(d, d)) / np.outer(d, d)
    V = (N / max(N - p, 1)) * (sums.T @ sums)
    covariance = inverse @ V @ inverse.T
    return 0.5 * (covariance + covariance.T)


def estimate(
    problem: Problem,
    rows: Rows,
    theta: NDArray[np.float64],
    covariance: NDArray[np.float64],
    noise_variance: NDArray[np.float64],
    *,
    method: str,
    rank: int,
    condition_number: float,
) -> LeastSquaresResult:
    """The estimator's answer in the fields of least squares (residual RMS per joint from the
    raw residuals of the rows that take part)."""
    r = rows.b - rows.A @ theta
    rms = np.array([np.sqrt(np.mean(x**2)) if x.size else 0.0 for x in rows.per_joint(r)])
    std = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    return LeastSquaresResult(
        theta=theta,
        std=std,
        relative_std=relative_std(theta, std),
        covariance=covariance,
        condition_number=float(condition_number),
        rank=int(rank),
        method=method,
        noise_variance=np.asarray(noise_variance, dtype=float),
        residual_rms=rms,
        names=list(problem.names),
        excluded=tuple(problem.excluded),
        joints=rows.joints,
    )


def positive_number(value: object, name: str) -> float:
    """An option that must be a finite number > 0; ValueError naming it otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < np.inf:
        raise ValueError(f"{name}: expected a finite number > 0, got {value!r}")
    return float(value)
