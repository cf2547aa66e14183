"""DH frames along the joint axes of a serial chain: any axes, skew, intersecting or parallel.

Input: joint i's axis as a line (a point p_i and a unit direction u_i, base coordinates, all
joints at q = 0) and the tip's pose. Output: a DH table whose frames put z along +u_i, so that
the joint variable is the URDF joint position (same zero, same sign), and the base pose of frame 0.

The frames follow the textbook construction (Spong for standard, Craig for modified DH): the
x axis of the frame between two consecutive axes lies along their common normal.

- Skew axes: the unique common normal, from the closest points of the two lines.
- Intersecting axes: x = +-(u_i x u_{i+1}) through the intersection point.
- Parallel axes (|u_i x u_{i+1}| < PARALLEL = 5e-6): the common normal through the previous
  frame's origin (standard) or through the point where the previous x axis meets axis i
  (modified), so that d_i = 0; coincident axes keep the previous x (theta = 0).
- Frame 0 (both conventions): z along u_1, origin at the foot of the base origin on axis 1, x
  along the base x axis projected on the plane normal to u_1 (its y axis if x is nearly along
  u_1): the base transform is the identity when axis 1 is the base z axis, as on most arms.
- Last frame: z along u_n, origin at the foot of the tip origin on axis n, x along the tip's x
  projected (tip y if x is nearly along u_n): the tool transform is a pure translation, often
  zero, when the tip's z is the last axis.

Where the sign of x is free (non-parallel axes, the normal between parallel ones) it is taken
so that x makes an acute angle with the previous x: theta offsets stay small.

Each frame is rebuilt from its DH row (the previous frame times the row's transform) before the
next row is computed, so the table and the frames agree to rounding whatever the input.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]

#: Two axes whose directions differ by less than this angle [rad] count as parallel. A DH table
#: has no good form for nearly parallel axes: their common normal lies at ~distance / angle, and
#: link parameters about such a far origin lose ~eps (distance / angle)^2 of precision, while
#: treating the axes as parallel misplaces them by ~angle. Both are ~eps^(1/3) ~ 5e-6 relative
#: at this threshold; see :func:`nearly_parallel`, which the reader warns about.
PARALLEL = 5e-6
#: Consecutive axes closer than this to parallel (but not within rounding of it) are reported.
NEARLY_PARALLEL = (1e-10, 1e-3)


def dh_standard(a: float, alpha: float, d: float, theta: float) -> Array:
    """A = Rz(theta) Tz(d) Tx(a) Rx(alpha) (docs/conventions.md, "DH tables")."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def dh_modified(a: float, alpha: float, d: float, theta: float) -> Array:
    """A = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i) (docs/conventions.md, "DH tables")."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array(
        [
            [ct, -st, 0.0, a],
            [st * ca, ct * ca, -sa, -d * sa],
            [st * sa, ct * sa, ca, d * ca],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def dh_frames(points: Array, axes: Array, tip: Array, convention: str) -> tuple[Array, Array]:
    """The DH table (n, 4) and the base pose of frame 0 (4, 4) for joint axes through ``points``
    along unit ``axes`` (n, 3) and a tip pose ``tip`` (4, 4), all in base coordinates at q = 0."""
    frame = np.eye(4)
    frame[:3, 2] = axes[0]
    frame[:3, 0] = _perpendicular(np.eye(3), axes[0])
    frame[:3, 1] = np.cross(axes[0], frame[:3, 0])
    frame[:3, 3] = _foot(np.zeros(3), points[0], axes[0])
    base = frame.copy()
    step = _standard_rows if convention == "standard" else _modified_rows
    return np.array(list(step(base, points, axes, tip))) + 0.0, base  # + 0.0: no -0.0 printed


def nearly_parallel(axes: Array) -> list[tuple[int, float]]:
    """(i, angle) for consecutive axes i, i+1 (0-based) within NEARLY_PARALLEL of parallel or
    anti-parallel: the DH table then holds errors of up to ~5e-6 relative (see PARALLEL)."""
    out = []
    for i in range(len(axes) - 1):
        angle = float(np.arcsin(min(1.0, float(np.linalg.norm(np.cross(axes[i], axes[i + 1]))))))
        if NEARLY_PARALLEL[0] < angle < NEARLY_PARALLEL[1]:
            out.append((i, angle))
    return out


def _standard_rows(
    frame: Array, points: Array, axes: Array, tip: Array
) -> Iterator[tuple[float, float, float, float]]:
    # Frame i-1 has z on axis i; frame i has z on axis i+1, x on the common normal
    # (Spong, Hutchinson, Vidyasagar, "Robot Modeling and Control", ch. 3).
    n = len(axes)
    for i in range(n):
        origin, x_prev, z_prev = frame[:3, 3], frame[:3, 0], frame[:3, 2]
        if i + 1 < n:
            foot, new_origin, x = _common_normal(
                origin, z_prev, points[i + 1], axes[i + 1], origin, x_prev
            )
            z = axes[i + 1]
        else:
            foot = new_origin = _foot(tip[:3, 3], origin, z_prev)
            x, z = _perpendicular(tip[:3, :3], z_prev), z_prev
        theta = _angle(x_prev, x, z_prev)
        d = float((foot - origin) @ z_prev)
        a = float((new_origin - foot) @ x)
        alpha = _angle(z_prev, z, x)
        yield a, alpha, d, theta
        frame = frame @ dh_standard(a, alpha, d, theta)


def _modified_rows(
    frame: Array, points: Array, axes: Array, tip: Array
) -> Iterator[tuple[float, float, float, float]]:
    # Frame i has z on axis i, origin on it at the common normal to axis
    # i+1 (Craig, "Introduction to Robotics", ch. 3).
    n = len(axes)
    a, alpha = 0.0, 0.0  # frame 0 has z on axis 1 already
    for i in range(n):
        # Rx(alpha_{i-1}) Tx(a_{i-1}): an intermediate frame with z on axis i, x = x_{i-1}
        middle = frame @ dh_modified(a, alpha, 0.0, 0.0)
        point, x_prev, z = middle[:3, 3], middle[:3, 0], middle[:3, 2]
        if i + 1 < n:
            origin, next_point, x = _common_normal(
                point, z, points[i + 1], axes[i + 1], point, x_prev
            )
        else:
            origin = _foot(tip[:3, 3], point, z)
            x = _perpendicular(tip[:3, :3], z)
        theta = _angle(x_prev, x, z)
        d = float((origin - point) @ z)
        yield a, alpha, d, theta
        frame = frame @ dh_modified(a, alpha, d, theta)
        if i + 1 < n:
            a = float((next_point - frame[:3, 3]) @ frame[:3, 0])
            alpha = _angle(frame[:3, 2], axes[i + 1], frame[:3, 0])


def _common_normal(
    p: Array, u: Array, q: Array, v: Array, reference: Array, x_prev: Array
) -> tuple[Array, Array, Array]:
    """Feet of the common normal on line (p, u) and line (q, v), and its unit direction x.
    ``reference`` (a point on the first line) places the normal between parallel lines."""
    c = np.cross(u, v)
    s = float(np.linalg.norm(c))
    if s >= PARALLEL:
        # closest points p + t u, q + r v: (w + r v - t u) orthogonal to u and v, w = q - p
        w = q - p
        b = float(u @ v)
        t = (w @ u - b * (w @ v)) / s**2
        r = (b * (w @ u) - w @ v) / s**2
        foot, other, x = p + t * u, q + r * v, c / s
    else:
        foot = reference
        other = _foot(reference, q, v)
        gap = other - foot
        gap -= (gap @ u) * u  # orthogonal to u to rounding, as the frames need
        length = float(np.linalg.norm(gap))
        x = gap / length if length > 1e-12 else x_prev
    if x @ x_prev < 0.0:
        x = -x
    return foot, other, x


def _foot(point: Array, p: Array, u: Array) -> Array:
    """The foot of ``point`` on the line through p along unit u."""
    return p + ((point - p) @ u) * u


def _perpendicular(rotation: Array, z: Array) -> Array:
    """The first column of ``rotation`` made normal to z, or its second when the first is along
    z (both cannot be)."""
    column = rotation[:, 0] if abs(rotation[:, 0] @ z) < 0.9 else rotation[:, 1]
    x = column - (column @ z) * z
    return x / np.linalg.norm(x)


def _angle(a: Array, b: Array, about: Array) -> float:
    """The angle from a to b about the unit vector ``about`` (both normal to it)."""
    return float(np.arctan2(np.cross(a, b) @ about, a @ b))
