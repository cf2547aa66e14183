"""Cartesian (operational-space) dynamics of the tool point (Khatib 1987; notes, "Uses of the
dynamic model").

With the geometric Jacobian J (rows [v; omega] of the tool point, world axes) and
xdd = J qdd + Jdot qd, the joint dynamics M qdd + c + g = tau = J^T F seen at the tool read

    Lam xdd + mu + p = F,   Lam = (J M^-1 J^T)^-1,
    mu = Lam (J M^-1 c - Jdot qd),   p = Lam J M^-1 g,

for any n (for a square non-singular J: Lam = J^-T M J^-1, mu = J^-T c - Lam Jdot qd,
p = J^-T g). Joint friction is not part of mu or p: compensate it in tau. F is the force and
the moment about the tool point, world axes.

``rows`` selects task rows of J (and of xdd, F): ``"position"`` (0, 1, 2), ``"orientation"``
(3, 4, 5) or a sequence of distinct row indices; a robot with fewer than 6 joints has a
singular 6 x 6 J M^-1 J^T and needs it (e.g. a planar arm: rows=(0, 1)).

Singularity: J M^-1 J^T (k x k) is scaled to unit diagonal, D^-1/2 X D^-1/2 with D = diag(X),
so that metres and radians compare; when the ratio of its smallest to its largest eigenvalue
(its reciprocal condition number) is below ``SINGULAR_RCOND`` = 1e-12, or a diagonal entry is
below 1e-12 times the largest, the configuration is singular for those rows and a ValueError
naming ``q`` is raised (near a singularity Lam grows as 1/distance^2: 1e-12 is reached about
1e-6 rad from it).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import real_array

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

    from .robot import Robot

Array: TypeAlias = NDArray[np.float64]

#: Reciprocal condition number of the unit-diagonal J M^-1 J^T below which q is singular.
SINGULAR_RCOND = 1e-12

ROW_SETS = {"position": (0, 1, 2), "orientation": (3, 4, 5)}


def task_rows(rows: str | Sequence[int] | None) -> list[int]:
    """The selected rows of [v; omega] as a list of indices (all six for None)."""
    if rows is None:
        return list(range(6))
    if isinstance(rows, str):
        if rows not in ROW_SETS:
            raise ValueError(
                f"rows: expected 'position', 'orientation' or row indices in 0..5, got {rows!r}"
            )
        return list(ROW_SETS[rows])
    values = real_array(rows, "rows", ndim=1)
    if (
        values.size == 0
        or np.any(values != np.round(values))
        or np.any((values < 0) | (values > 5))
        or len(set(values.tolist())) != values.size
    ):
        raise ValueError(f"rows: expected distinct row indices in 0..5, got {rows!r}")
    return [int(v) for v in values]


def _task_mobility(robot: Robot, q: Array, rows: list[int]) -> tuple[Array, Array, Array]:
    """J (rows), M and Y = M^-1 J^T for q (n,) or (T, n)."""
    J = robot.jacobian(q)[..., rows, :]
    M = robot.mass_matrix(q)
    # asarray: NumPy's stubs type linalg results as floating[Any]; float64 in, float64 out
    Y = np.asarray(np.linalg.solve(M, np.swapaxes(J, -1, -2)), dtype=np.float64)
    return J, M, Y


def _inverse_checked(X: Array, rows: list[int]) -> Array:
    """(J M^-1 J^T)^-1 per sample, ValueError naming q where it is singular (module doc)."""
    X = 0.5 * (X + np.swapaxes(X, -1, -2))
    diagonal = np.diagonal(X, axis1=-2, axis2=-1)
    largest = diagonal.max(axis=-1, keepdims=True)
    degenerate = np.any(diagonal <= 1e-12 * largest, axis=-1) | (largest[..., 0] <= 0.0)
    scale = 1.0 / np.sqrt(np.where(diagonal > 0.0, diagonal, 1.0))
    scaled = X * scale[..., :, None] * scale[..., None, :]
    eigenvalues = np.linalg.eigvalsh(scaled)
    rcond = eigenvalues[..., 0] / eigenvalues[..., -1]
    singular = degenerate | (rcond < SINGULAR_RCOND)
    if np.any(singular):
        where = "" if X.ndim == 2 else f" at sample {int(np.flatnonzero(singular)[0])}"
        value = float(np.atleast_1d(rcond)[np.flatnonzero(np.atleast_1d(singular))[0]])
        raise ValueError(
            f"q: singular configuration{where} for the task rows {rows}: J M^-1 J^T has a "
            f"scaled reciprocal condition number {max(value, 0.0):.3g} < {SINGULAR_RCOND:g} "
            "(select fewer rows with rows=..., e.g. rows='position', or move away from the "
            "singularity)"
        )
    return np.asarray(np.linalg.inv(X), dtype=np.float64)  # typed floating[Any] by NumPy


def cartesian_inertia(robot: Robot, q: ArrayLike, rows: str | Sequence[int] | None = None) -> Array:
    """Lam = (J M^-1 J^T)^-1: (k, k) for q (n,), (T, k, k) for (T, n); k = 6 or len(rows)."""
    q_array = real_array(q, "q")
    selected = task_rows(rows)
    J, _, Y = _task_mobility(robot, q_array, selected)
    return _inverse_checked(J @ Y, selected)


def cartesian_dynamics(
    robot: Robot, q: ArrayLike, qd: ArrayLike, rows: str | Sequence[int] | None = None
) -> tuple[Array, Array, Array]:
    """(Lam, mu, p) with Lam xdd + mu + p = F (module doc): (k, k), (k,), (k,) per sample."""
    q_array = real_array(q, "q")
    selected = task_rows(rows)
    c = robot.coriolis(q_array, qd)  # checks qd against q
    g = robot.gravity(q_array)
    J, _, Y = _task_mobility(robot, q_array, selected)
    Lam = _inverse_checked(J @ Y, selected)
    Jdot_qd = (
        robot.jacobian_dot(q_array, qd)[..., selected, :] @ np.asarray(qd, dtype=float)[..., None]
    )[..., 0]
    Yt = np.swapaxes(Y, -1, -2)  # J M^-1 (M symmetric)
    mu = (Lam @ ((Yt @ c[..., None])[..., 0] - Jdot_qd)[..., None])[..., 0]
    p = (Lam @ (Yt @ g[..., None]))[..., 0]
    return Lam, mu, p


def cartesian_coriolis_matrix(
    robot: Robot, q: ArrayLike, qd: ArrayLike, rows: str | Sequence[int] | None = None
) -> Array:
    """S_p = J^-T (S - M J^-1 Jdot) J^-1: the factorization mu = S_p xd of the Cartesian
    Coriolis/centrifugal force, xd = J qd, for a square Jacobian (as many task rows as joints;
    notes p. 49), (k, k) per sample. S is the joint-space factorization of
    ``robot.coriolis_matrix`` (Christoffel symbols), with which Mdot - 2 S is skew-symmetric;
    then so is Lamdot - 2 S_p (Lam = J^-T M J^-1): Lamdot - 2 S_p = J^-T (Mdot - 2 S) J^-1.
    ValueError naming ``rows`` when J is not square, ``q`` at a singularity."""
    q_array = real_array(q, "q")
    selected = task_rows(rows)
    if len(selected) != robot.n:
        raise ValueError(
            f"rows: the Cartesian factorization S_p needs a square Jacobian: {robot.n} task rows "
            f"for {robot.n} joints, got {len(selected)} ({selected})"
        )
    J, M, Y = _task_mobility(robot, q_array, selected)
    _inverse_checked(J @ Y, selected)  # the singularity check of cartesian_inertia
    S = robot.coriolis_matrix(q_array, qd)  # checks qd against q
    Jdot = robot.jacobian_dot(q_array, qd)[..., selected, :]
    J_inv = np.asarray(np.linalg.inv(J), dtype=np.float64)
    J_inv_t = np.swapaxes(J_inv, -1, -2)
    return np.asarray(J_inv_t @ (S - M @ J_inv @ Jdot) @ J_inv, dtype=np.float64)
