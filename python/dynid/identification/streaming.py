"""Least squares on logs of any length: the regressor evaluated in C++ chunk by chunk and folded
into triangular factors (dynid._qr), so memory is bounded by one chunk whatever the number of
samples, with the estimates, standard deviations and errors of :func:`dynid.least_squares`.

    acc = LeastSquaresAccumulator(n=7, p=base.independent.size)
    for Y, tau in chunks:             # Y (T_k, n, p), tau (T_k, n)
        acc.add(Y, tau)
    fit = acc.solve(method="wls")

or directly from joint trajectories, with the regressor computed here:

    fit = least_squares_streaming(robot, chunks_of_q_qd_qdd_tau, columns=base.independent)
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._threads import blas_single_threaded
from ..model.robot import Robot
from ._qr import GroupedTriangularFactors
from .identify import (
    LeastSquaresResult,
    _check_options,
    _excluded,
    _samples,
    solve_factors,
)


class LeastSquaresAccumulator:
    """Folds chunks of Y theta = tau into the triangular factors of the stacked system.

    ``n`` joints, ``p`` parameters; ``exclude_joints`` (0-based) leaves those joints' rows out,
    as in :func:`dynid.least_squares`. Rows are stacked by joint, so the result does not depend
    on how the samples are split into chunks (up to rounding).
    """

    def __init__(self, n: int, p: int, *, exclude_joints: Sequence[int] = ()) -> None:
        for value, name in ((n, "n"), (p, "p")):
            if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 1:
                raise ValueError(f"{name}: expected an integer >= 1, got {value!r}")
        self.excluded = tuple(sorted(_excluded(exclude_joints, int(n))))
        joints = tuple(j for j in range(int(n)) if j not in self.excluded)
        self._factors = GroupedTriangularFactors(int(n), int(p), joints)

    @property
    def samples(self) -> int:
        """Samples added so far."""
        return self._factors.samples

    @blas_single_threaded
    def add(self, Y: ArrayLike, tau: ArrayLike, keep: ArrayLike | None = None) -> None:
        """Adds T samples: Y (T, n, p) or (n, p) for one, tau (T, n) or (n,); finite values.
        ``keep`` (T, n) booleans: only the rows of joint j where ``keep[:, j]`` is True (e.g.
        the moving ones, ``dynid.logs.signal.moving_mask_min_velocity(per_joint=True)``)."""
        Y3, tau2 = _samples(Y, tau)
        expected = (self._factors.n, self._factors.p)
        if Y3.shape[1:] != expected:
            raise ValueError(
                f"Y: expected shape (T, {expected[0]}, {expected[1]}), got {np.shape(Y)}"
            )
        mask = None
        if keep is not None:
            mask = np.asarray(keep)
            if mask.dtype != bool or mask.shape != tau2.shape:
                raise ValueError(
                    f"keep: expected booleans of shape {tau2.shape}, got {mask.dtype} {mask.shape}"
                )
        self._factors.add(Y3, tau2, mask)

    @blas_single_threaded
    def solve(
        self,
        *,
        method: str = "ols",
        names: Sequence[str] | None = None,
        on_rank_deficient: str = "raise",
        rank_tolerance: float = 1e-10,
    ) -> LeastSquaresResult:
        """The estimate of :func:`dynid.least_squares` (same options, errors and result) from
        the samples added so far; the accumulator can take more samples afterwards."""
        method, on_rank_deficient = _check_options(method, on_rank_deficient, rank_tolerance)
        return solve_factors(
            self._factors,
            method=method,
            names=names,
            on_rank_deficient=on_rank_deficient,
            rank_tolerance=rank_tolerance,
            excluded=self.excluded,
        )


@blas_single_threaded
def least_squares_streaming(
    robot: Robot,
    chunks: Iterable[tuple[Any, Any, Any, Any]],
    *,
    rotor: bool = False,
    friction: bool = False,
    columns: ArrayLike | None = None,
    method: str = "ols",
    exclude_joints: Sequence[int] = (),
    names: Sequence[str] | None = None,
    on_rank_deficient: str = "raise",
    rank_tolerance: float = 1e-10,
) -> LeastSquaresResult:
    """Least squares on chunks (q, qd, qdd, tau), each (T_k, n), of one long trajectory.

    Each chunk's regressor is ``robot.regressor(q, qd, qdd, rotor=rotor, friction=friction)``
    (one C++ batch call), restricted to ``columns`` (e.g. ``base.independent`` of
    :func:`dynid.model.base_parameters`; all columns by default), and folded into the factors; the
    other options are those of :func:`dynid.least_squares`. Memory is bounded by the largest
    chunk, so a log of millions of samples can be read and solved piece by piece.
    """
    if not isinstance(robot, Robot):
        raise ValueError(f"robot: expected a dynid.Robot, got {type(robot).__name__}")
    index = _columns(columns, robot, rotor, friction)
    accumulator: LeastSquaresAccumulator | None = None
    buffer: NDArray[np.float64] | None = None  # reused while chunks have the same length
    for k, chunk in enumerate(chunks):
        try:
            q, qd, qdd, tau = chunk
        except (TypeError, ValueError):
            raise ValueError(
                f"chunks: expected (q, qd, qdd, tau) tuples, got {type(chunk).__name__} "
                f"as chunk {k}"
            ) from None
        count = np.shape(q)[0] if np.ndim(q) == 2 else None
        width = (
            index.size
            if index is not None
            else 10 * robot.n + (robot.n if rotor else 0) + (2 * robot.n if friction else 0)
        )
        if count is not None and (buffer is None or buffer.shape != (count, robot.n, width)):
            buffer = np.empty((count, robot.n, width))
        Y = robot.regressor(
            q,
            qd,
            qdd,
            rotor=rotor,
            friction=friction,
            columns=index,
            out=buffer if count is not None else None,
        )
        if accumulator is None:
            accumulator = LeastSquaresAccumulator(
                robot.n, Y.shape[-1], exclude_joints=exclude_joints
            )
        accumulator.add(Y, tau)
    if accumulator is None:
        raise ValueError("chunks: expected at least one (q, qd, qdd, tau) chunk, got none")
    return accumulator.solve(
        method=method,
        names=names,
        on_rank_deficient=on_rank_deficient,
        rank_tolerance=rank_tolerance,
    )


def _columns(
    columns: ArrayLike | None, robot: Robot, rotor: bool, friction: bool
) -> NDArray[np.int64] | None:
    if columns is None:
        return None
    total = 10 * robot.n + (robot.n if rotor else 0) + (2 * robot.n if friction else 0)
    index = np.asarray(columns)
    if index.ndim != 1 or index.size == 0 or index.dtype.kind not in "iu":
        raise ValueError(
            f"columns: expected a non-empty 1-D array of column indices, got {columns!r}"
        )
    if index.min() < 0 or index.max() >= total:
        raise ValueError(f"columns: expected indices in [0, {total}), got {columns!r}")
    return index.astype(np.int64)
