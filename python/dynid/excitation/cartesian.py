"""Cartesian keep-out constraints of an exciting trajectory: a floor plane and a workspace box
for the link origins and the tool point, and a minimum distance between non-adjacent links
modelled as capsules (issue 21, item 1; docs/excitation.md, "Cartesian keep-out").

The points are the origins of the DH frames 1..n and the tool point (``robot.fkine``); the links
are the segments between consecutive points, the base's origin first: segment i (i = 1..n+1)
joins point i-1 and point i (segment n+1: frame n to the tool), a capsule of radius r_i about it.
Two capsules are kept apart when they are not adjacent: |i - j| >= 2 and the segments between
them are together longer than r_i + r_j + margin (zero-length segments, common in DH chains
with intersecting axes, make links meet at every configuration: such pairs are left out), and
their distance changes with the configuration and exceeds that bound somewhere (pairs no
motion moves apart, such as a wrist's segments about one point, are left out too: tried on
PAIR_PROBES random configurations).

SLSQP sees every constraint on its grid with ``margin`` kept free; the positions' derivatives in
q come from central differences of the C++ batch frames (one call for all samples), the
distance's from the closest points (the envelope theorem). Between grid points
(:func:`keep_out_holds`) a constraint function f changes at most at its speed, so
min f >= (f(t_k) + f(t_k+1)) / 2 - L h / 2 with L = CARTESIAN_SAFETY x the largest point speed
on the grid (a segment's points move no faster than its faster end).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _core
from .trajectory import FourierTrajectory, _basis, _finite_array

if TYPE_CHECKING:
    from ..model.robot import Robot

#: Free distance [m] on the optimiser's grid by default: room for the motion between its points.
DEFAULT_KEEP_OUT_MARGIN = 0.05

#: The speed bounding a constraint between grid points is this times the largest on the grid.
CARTESIAN_SAFETY = 2.0

#: Configurations on which capsule_pairs tries whether a pair's distance can change at all.
PAIR_PROBES = 32

# Central-difference step in q for the points' derivatives (error ~h^2, rounding ~1e-16/h).
_Q_STEP = 1e-6


@dataclass(frozen=True)
class KeepOut:
    """What to keep out of: ``floor`` (z >= floor, world z), ``box`` (xmin, xmax, ymin, ymax,
    zmin, zmax), ``radii`` (capsule radii of the n + 1 segments, or one for all; None: no
    capsules) and the ``margin`` kept free on the optimiser's grid."""

    floor: float | None = None
    box: tuple[float, ...] | None = None
    radii: ArrayLike | None = None
    margin: float = DEFAULT_KEEP_OUT_MARGIN

    def __post_init__(self) -> None:
        if self.floor is not None:
            floor = _finite_array(self.floor, "floor")
            if floor.ndim != 0:
                raise ValueError(f"floor: expected a height [m], got {self.floor!r}")
            object.__setattr__(self, "floor", float(floor))
        if self.box is not None:
            box = _finite_array(self.box, "box")
            if box.shape != (6,) or np.any(box[0::2] >= box[1::2]):
                raise ValueError(
                    f"box: expected xmin, xmax, ymin, ymax, zmin, zmax with each min < max, "
                    f"got {self.box!r}"
                )
            object.__setattr__(self, "box", tuple(float(v) for v in box))
        if self.radii is not None:
            radii = _finite_array(self.radii, "radii")
            if radii.ndim > 1 or np.any(radii < 0):
                raise ValueError(
                    f"radii: expected radii >= 0 (one, or one per segment), got {self.radii!r}"
                )
            object.__setattr__(self, "radii", radii)
        margin = _finite_array(self.margin, "margin")
        if margin.ndim != 0 or margin < 0:
            raise ValueError(f"margin: expected a distance >= 0 [m], got {self.margin!r}")
        object.__setattr__(self, "margin", float(margin))

    @property
    def active(self) -> bool:
        return self.floor is not None or self.box is not None or self.radii is not None


def points(robot: Robot, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """(T, n + 2, 3): the base origin, the origins of DH frames 1..n and the tool point."""
    frames = _core._link_frames(robot, q)[..., :3, 3]
    tool = robot.fkine(q)[..., :3, 3]
    base = np.broadcast_to(np.asarray(robot.base)[:3, 3], tool.shape)
    return np.concatenate([base[:, None], frames, tool[:, None]], axis=1)


def capsule_pairs(robot: Robot, keep_out: KeepOut, q: NDArray) -> tuple[NDArray, NDArray]:
    """The radii (n + 1,) and the pairs (i, j) of segments to keep apart (see the module), 0-based;
    the segment lengths are taken at the configuration ``q`` (constant for revolute joints)."""
    segments = robot.n + 1
    if keep_out.radii is None:
        return np.zeros(segments), np.zeros((0, 2), dtype=int)
    radii = (
        np.broadcast_to(np.asarray(keep_out.radii, dtype=float), (segments,)).copy()
        if (np.size(keep_out.radii) in (1, segments))
        else None
    )
    if radii is None:
        raise ValueError(
            f"radii: expected one radius or {segments} (the n links and the tool segment), got "
            f"{np.size(keep_out.radii)}"
        )
    p = points(robot, np.atleast_2d(q))[0]
    length = np.linalg.norm(np.diff(p, axis=0), axis=1)
    candidates = np.array(
        [
            (i, j)
            for i in range(segments)
            for j in range(i + 2, segments)
            if length[i + 1 : j].sum() > radii[i] + radii[j] + keep_out.margin
        ],
        dtype=int,
    ).reshape(-1, 2)
    if not candidates.size:
        return radii, candidates
    # Pairs whose distance no motion changes (the joints between them keep it: a wrist's
    # segments about one point) are left out: nothing to optimise, and one below its bound
    # would make every trajectory infeasible. Tried on q and PAIR_PROBES random configurations.
    rng = np.random.default_rng(0)
    qlim = np.asarray(robot.qlim)
    probes = np.vstack(
        [np.atleast_2d(q), rng.uniform(qlim[:, 0], qlim[:, 1], (PAIR_PROBES, robot.n))]
    )
    distance = _segment_distance(points(robot, probes), candidates)[0]
    moving = distance.max(axis=0) - distance.min(axis=0) > 1e-9
    # and pairs never farther apart than the bound: links that touch by construction
    apart = (
        distance.max(axis=0) > radii[candidates[:, 0]] + radii[candidates[:, 1]] + keep_out.margin
    )
    return radii, candidates[moving & apart]


class KeepOutConstraint:
    """SLSQP's inequalities of ``keep_out`` at the times ``t``, each >= 0, and their Jacobian."""

    def __init__(
        self, robot: Robot, keep_out: KeepOut, t: NDArray, wf: float, harmonics: int, q_ref: NDArray
    ) -> None:
        self.robot, self.keep_out, self.n, self.harmonics = robot, keep_out, robot.n, harmonics
        self.Bq = _basis(t, wf, harmonics)[0]
        self.radii, self.pairs = capsule_pairs(robot, keep_out, q_ref)
        self._x: NDArray[np.float64] | None = None

    @property
    def empty(self) -> bool:
        """No inequality at all: capsules only, and no pair of them that the motion can bring
        closer (a short arm whose links are all adjacent or meet by construction)."""
        return self.keep_out.floor is None and self.keep_out.box is None and not self.pairs.size

    def _update(self, x: NDArray[np.float64]) -> None:
        if self._x is not None and np.array_equal(x, self._x):
            return
        n, H = self.n, self.harmonics
        c = np.hstack([x[: n * H].reshape(n, H), x[n * H : 2 * n * H].reshape(n, H)])
        q = self.Bq @ c.T + x[2 * n * H :]
        value, dq = constraint_values(self.robot, self.keep_out, self.radii, self.pairs, q, True)
        assert dq is not None  # asked for (derivatives=True)
        T, rows = value.shape
        Bq = self.Bq
        # dq_i(t)/da_il = Bq[t, l], dq_i(t)/db_il = Bq[t, H + l], dq_i(t)/dq0_i = 1
        ja = np.einsum("tri,tl->tril", dq, Bq[:, :H]).reshape(T * rows, n * H)
        jb = np.einsum("tri,tl->tril", dq, Bq[:, H:]).reshape(T * rows, n * H)
        self._value = value.ravel() - self.keep_out.margin
        self._jac = np.hstack([ja, jb, dq.reshape(T * rows, n)])
        self._x = x.copy()

    def value(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        self._update(x)
        return self._value

    def jacobian(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        self._update(x)
        return self._jac

    def as_dict(self) -> dict[str, Any]:
        return {"type": "ineq", "fun": self.value, "jac": self.jacobian}


def constraint_values(
    robot: Robot,
    keep_out: KeepOut,
    radii: NDArray,
    pairs: NDArray,
    q: NDArray[np.float64],
    derivatives: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
    """(T, rows) distances inside the keep-out (>= 0: allowed; floor, box faces, capsule gaps)
    and, with ``derivatives``, their derivatives in q (T, rows, n)."""
    P = points(robot, q)  # (T, n + 2, 3)
    value = _values(P, keep_out, radii, pairs)
    if not derivatives:
        return value, None
    T, n, h = q.shape[0], robot.n, _Q_STEP
    Q = np.repeat(q[None, None], 2, axis=0).repeat(n, axis=1)  # (2, n, T, n)
    eye = np.eye(n)[:, None, :]
    Q[0] += h * eye
    Q[1] -= h * eye
    moved = points(robot, Q.reshape(-1, n)).reshape(2, n, T, n + 2, 3)
    dP = (moved[0] - moved[1]) / (2 * h)  # (joint i, T, point, 3)
    rows = _rows(P, dP, keep_out, radii, pairs)
    return value, rows


def keep_out_holds(
    robot: Robot, keep_out: KeepOut, trajectory: FourierTrajectory, samples: int, q_ref: NDArray
) -> bool:
    """Whether every keep-out constraint (without the margin) holds over the whole period, on
    ``samples`` points with the speed bound between them (see the module)."""
    radii, pairs = capsule_pairs(robot, keep_out, q_ref)
    _, q, _, _ = trajectory.sample(samples)
    P = points(robot, q)
    value = _values(P, keep_out, radii, pairs)
    h = trajectory.period / samples
    speed = np.linalg.norm(np.roll(P, -1, axis=0) - P, axis=2).max() / h  # mean over a step
    L = CARTESIAN_SAFETY * 2.0 * speed  # a gap closes at most at both ends' speeds
    lower = 0.5 * (value + np.roll(value, -1, axis=0)) - L * h / 2
    return bool(np.all(lower >= 0.0) and np.all(value >= 0.0))


def constraint_labels(n: int, keep_out: KeepOut, pairs: NDArray) -> list[str]:
    """A name for each column of :func:`constraint_values`, for messages."""
    names = [f"frame {k} origin" for k in range(1, n + 1)] + ["tool point"]
    labels = []
    if keep_out.floor is not None:
        labels += [f"floor: {name}" for name in names]
    if keep_out.box is not None:
        for face in ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax"):
            labels += [f"box {face}: {name}" for name in names]
    labels += [f"capsules of segments {i + 1} and {j + 1}" for i, j in pairs]
    return labels


def _values(P: NDArray, keep_out: KeepOut, radii: NDArray, pairs: NDArray) -> NDArray:
    moving = P[:, 1:]  # the frame origins and the tool point; the base origin is the mount
    parts = []
    if keep_out.floor is not None:
        parts.append(moving[..., 2] - keep_out.floor)
    if keep_out.box is not None:
        for axis in range(3):
            low, high = keep_out.box[2 * axis], keep_out.box[2 * axis + 1]
            parts += [moving[..., axis] - low, high - moving[..., axis]]
    if pairs.size:
        distance, _, _, _ = _segment_distance(P, pairs)
        parts.append(distance - radii[pairs[:, 0]] - radii[pairs[:, 1]])
    return np.concatenate(parts, axis=1) if parts else np.zeros((P.shape[0], 0))


def _rows(P: NDArray, dP: NDArray, keep_out: KeepOut, radii: NDArray, pairs: NDArray) -> NDArray:
    """d(_values)/dq, (T, rows, n), from dP (joint, T, point, 3)."""
    dmoving = np.moveaxis(dP[:, :, 1:], 0, -1)  # (T, point, 3, joint)
    parts = []
    if keep_out.floor is not None:
        parts.append(dmoving[:, :, 2])
    if keep_out.box is not None:
        for axis in range(3):
            parts += [dmoving[:, :, axis], -dmoving[:, :, axis]]
    if pairs.size:
        _, s, u, unit = _segment_distance(P, pairs)
        dPt = np.moveaxis(dP, 0, -1)  # (T, point, 3, joint)
        i, j = pairs[:, 0], pairs[:, 1]
        # closest points A_i + s (B_i - A_i) on segment i (points i, i+1), likewise u on j
        d_on_i = (1 - s)[..., None, None] * dPt[:, i] + s[..., None, None] * dPt[:, i + 1]
        d_on_j = (1 - u)[..., None, None] * dPt[:, j] + u[..., None, None] * dPt[:, j + 1]
        parts.append(np.einsum("tpk,tpkn->tpn", unit, d_on_i - d_on_j))
    return np.concatenate(parts, axis=1) if parts else np.zeros((P.shape[0], 0, dP.shape[0]))


def _segment_distance(P: NDArray, pairs: NDArray) -> tuple[NDArray, ...]:
    """Distance between segments (P[i], P[i+1]) and (P[j], P[j+1]) for each pair, with the
    parameters s, u of the closest points and the unit vector from j's to i's (Ericson,
    Real-Time Collision Detection, 5.1.9), vectorised: (T, pairs) each, the vector (T, pairs, 3)."""
    i, j = pairs[:, 0], pairs[:, 1]
    A, B, C, D = P[:, i], P[:, i + 1], P[:, j], P[:, j + 1]
    d1, d2, r = B - A, D - C, A - C
    a, e = np.einsum("tpk,tpk->tp", d1, d1), np.einsum("tpk,tpk->tp", d2, d2)
    f, b, c = (
        np.einsum("tpk,tpk->tp", d2, r),
        np.einsum("tpk,tpk->tp", d1, d2),
        np.einsum("tpk,tpk->tp", d1, r),
    )
    tiny = 1e-300
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(
            denom > 1e-12 * np.maximum(a * e, tiny), np.clip((b * f - c * e) / denom, 0, 1), 0.0
        )
        s = np.where(a > tiny, s, 0.0)
        # segment j a point (e = 0): u = 0 and s from the point's projection onto segment i
        s = np.where(e > tiny, s, np.clip(-c / np.where(a > tiny, a, 1.0), 0, 1) * (a > tiny))
        u = np.where(e > tiny, (b * s + f) / np.where(e > tiny, e, 1.0), 0.0)
        s = np.where(
            u < 0, np.where(a > tiny, np.clip(-c / np.where(a > tiny, a, 1.0), 0, 1), 0.0), s
        )
        s = np.where(
            u > 1, np.where(a > tiny, np.clip((b - c) / np.where(a > tiny, a, 1.0), 0, 1), 0.0), s
        )
        u = np.clip(u, 0, 1)
    gap = (A + s[..., None] * d1) - (C + u[..., None] * d2)
    distance = np.linalg.norm(gap, axis=2)
    unit = gap / np.where(distance > 0, distance, 1.0)[..., None]
    return distance, s, u, unit
