"""Least squares from triangular factors only: the R of QR([A_j | b_j]) per joint, accumulated
chunk by chunk, never the orthogonal factor Q nor the whole stacked matrix.

For any x, ||[A_j | b_j] x|| = ||R_j x||, so the R_j carry everything the solver needs: stacked
(and, for WLS, each divided by sigma_j) and factored once more they give the R of the whole
(weighted) system, whose first p columns are the R of A and whose last column is Q^T b; the
per-joint residual norms are ||R_j [theta; -1]||. Each chunk costs one Householder QR of
(rows of R_j + chunk rows) x (p + 1) per joint (LAPACK geqrf, no Q formed), so memory is bounded
by the chunk and the time is about 2 N p^2 flops for N stacked rows (a blocked, streaming TSQR).

Values are kept in units where max |A| and max |b| are below 1 (powers of two, exact): when a
chunk brings larger values, the factors so far are rescaled by the power of two instead.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.linalg.lapack
from numpy.typing import NDArray


def exponent(x: NDArray[np.float64]) -> int | None:
    """The e with max |x| / 2^e in [0.5, 1), None for an empty or all-zero x."""
    largest = float(np.abs(x).max()) if x.size else 0.0
    return int(np.frexp(largest)[1]) if largest > 0 else None


class GroupedTriangularFactors:
    """The R factors of [A_j | b_j] of each joint j of ``joints``, in scaled units.

    ``add`` takes the regressor of T samples (T, n, p) and their torques (T, n) (finite, already
    checked); joint j's rows are Y[:, j, :] and tau[:, j] (the stacking of ``stack_by_joint``),
    those where ``keep[:, j]`` is True when a (T, n) row mask is given (e.g. joint j moving:
    ``--min-velocity``); ``counts`` holds the rows of each joint.
    """

    def __init__(self, n: int, p: int, joints: tuple[int, ...]) -> None:
        self.n, self.p, self.joints = n, p, joints
        self.factors: dict[int, NDArray[np.float64]] = {j: np.zeros((0, p + 1)) for j in joints}
        self.samples = 0
        self.counts: dict[int, int] = dict.fromkeys(joints, 0)
        self.a_exp: int | None = None  # scaled A = A / 2^a_exp
        self.b_exp: int | None = None
        self.max_a = 0.0
        self.max_b = 0.0

    @property
    def rows(self) -> int:
        return sum(self.counts.values())

    def add(
        self,
        Y: NDArray[np.float64],
        tau: NDArray[np.float64],
        keep: NDArray[np.bool_] | None = None,
    ) -> None:
        T = Y.shape[0]
        if T == 0:
            return
        if keep is not None:  # only the rows kept count for the scaling, as for the fit
            Y = np.where(keep[:, :, None], Y, 0.0)
            tau = np.where(keep, tau, 0.0)
        kept = list(self.joints)
        every = len(kept) == self.n
        largest_a = (
            max(float(np.abs(Y[:, j, :]).max()) for j in kept)
            if not every
            else float(np.abs(Y).max())
        )
        largest_b = float(np.abs(tau[:, kept]).max())
        self.max_a, self.max_b = max(self.max_a, largest_a), max(self.max_b, largest_b)
        self._rescale(exponent(np.array([largest_a])), exponent(np.array([largest_b])))
        a_factor = 2.0 ** -(self.a_exp or 0)  # powers of two: exact
        b_factor = 2.0 ** -(self.b_exp or 0)
        p = self.p
        # Rows in blocks of SUB_BLOCK samples, every joint's before the next block: each block of
        # Y is read from memory once, and each QR works on a matrix that fits in cache.
        for lo in range(0, T, SUB_BLOCK):
            hi = min(T, lo + SUB_BLOCK)
            for j in kept:
                rows = slice(lo, hi) if keep is None else lo + np.flatnonzero(keep[lo:hi, j])
                count = hi - lo if keep is None else rows.size  # type: ignore[union-attr]
                old = self.factors[j]
                r0 = old.shape[0]
                block = np.empty((r0 + count, p + 1), order="F")  # LAPACK's order: no copy
                block[:r0] = old
                np.multiply(Y[rows, j, :], a_factor, out=block[r0:, :p])
                np.multiply(tau[rows, j], b_factor, out=block[r0:, p])
                self.factors[j] = upper_triangle(block)
                self.counts[j] += count
        self.samples += T

    def _rescale(self, a_new: int | None, b_new: int | None) -> None:
        """Raises the scaling exponents to a chunk's, rescaling the factors so far (exactly)."""
        self.a_exp = self._raised(self.a_exp, a_new, slice(0, self.p))
        self.b_exp = self._raised(self.b_exp, b_new, self.p)

    def _raised(self, old: int | None, new: int | None, columns: slice | int) -> int | None:
        """max(old, new), the factors' ``columns`` moved from units 2^old to 2^new if it grows.

        None means no non-zero value yet (those columns of the factors are all zero, so there is
        nothing to rescale). The tests are on None, never on truthiness: 0 is the exponent of
        values in [0.5, 1) (issue 22: ``old or new`` skipped the rescaling for it).
        """
        if new is None or (old is not None and new <= old):
            return old
        if old is not None:
            for R in self.factors.values():
                R[:, columns] = np.ldexp(R[:, columns], old - new)
        return new

    @classmethod
    def merged(cls, parts: list[GroupedTriangularFactors]) -> GroupedTriangularFactors:
        """The factors of all the rows of ``parts`` (same n, p and joints): each part's R_j
        brought to the common power-of-two units (exact), stacked and factored once more, since
        the R of stacked blocks is the R of their stacked R's."""
        first = parts[0]
        whole = cls(first.n, first.p, first.joints)
        whole.a_exp = max((f.a_exp for f in parts if f.a_exp is not None), default=None)
        whole.b_exp = max((f.b_exp for f in parts if f.b_exp is not None), default=None)
        whole.samples = sum(f.samples for f in parts)
        whole.counts = {j: sum(f.counts[j] for f in parts) for j in first.joints}
        whole.max_a = max(f.max_a for f in parts)
        whole.max_b = max(f.max_b for f in parts)
        p = first.p
        for j in first.joints:
            blocks = []
            for f in parts:
                R = f.factors[j].copy()
                if f.a_exp is not None and whole.a_exp is not None:
                    R[:, :p] = np.ldexp(R[:, :p], f.a_exp - whole.a_exp)
                if f.b_exp is not None and whole.b_exp is not None:
                    R[:, p] = np.ldexp(R[:, p], f.b_exp - whole.b_exp)
                blocks.append(R)
            whole.factors[j] = upper_triangle(np.vstack(blocks))
        return whole

    def combined(self, weights: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """The R of the whole stacked [A | b], joint j's rows multiplied by weights[k] (k-th
        kept joint); (p + 1) x (p + 1), or fewer rows when there are fewer stacked rows."""
        blocks = [
            R if weights is None else R * weights[k] for k, R in enumerate(self.factors.values())
        ]
        return upper_triangle(np.vstack(blocks))

    def residual_squares(self, theta: NDArray[np.float64]) -> NDArray[np.float64]:
        """||b_j - A_j theta||^2 per kept joint (scaled units)."""
        x = np.append(theta, -1.0)
        return np.array([float(np.sum((R @ x) ** 2)) for R in self.factors.values()])


#: Samples per Householder QR update (about 0.5 MB per joint's block for p = 62).
SUB_BLOCK = 1024


def upper_triangle(block: NDArray[np.float64]) -> NDArray[np.float64]:
    """R of block = Q R (Householder, LAPACK geqrf; Q is not formed), min(rows, cols) rows."""
    if block.shape[0] == 0:
        return block
    factored, _, _, info = scipy.linalg.lapack.dgeqrf(np.asfortranarray(block), overwrite_a=True)
    if info != 0:  # only for invalid arguments, which the callers never pass
        raise RuntimeError(f"LAPACK dgeqrf failed (info {info})")
    return np.triu(factored[: min(block.shape)])


def solve_triangular_system(
    factor: NDArray[np.float64], p: int, tolerance: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], int, NDArray[np.float64], float]:
    """theta, (A^T A)^+, rank, null-space basis (scaled coordinates) and cond(A) from the R of
    [A | b] (``factor``, at least p rows).

    R is the R of A and z = Q^T b its last column; with D the column norms of A (those of R) and
    the small SVD R D^-1 = U S V^T, over the r singular values above tolerance * s_max:
    theta = D^-1 V_r S_r^-1 U_r^T z, (A^T A)^+ = D^-1 V_r S_r^-2 V_r^T D^-1.
    """
    R, z = factor[:p, :p], factor[:p, p]
    # Column norms on columns divided by their largest entry: no overflow or underflow.
    peak = np.abs(R).max(axis=0)
    peak[peak == 0] = 1.0
    scale = peak * np.linalg.norm(R / peak, axis=0)
    scale[scale == 0] = 1.0  # an all-zero column keeps a zero singular value
    U, s, Vt = scipy.linalg.svd(R / scale, lapack_driver="gesvd")
    rank = int(np.count_nonzero(s > tolerance * s[0])) if s[0] > 0 else 0
    V = Vt[:rank].T / s[:rank]  # V_r S_r^-1
    theta = (V @ (U[:, :rank].T @ z)) / scale
    unit_cov = (V @ V.T) / np.outer(scale, scale)
    unscaled = scipy.linalg.svdvals(R)  # the singular values of A
    cond = float(unscaled[0] / unscaled[-1]) if unscaled[-1] > 0 else np.inf
    return theta, unit_cov, rank, Vt[rank:].T, cond
