"""The lecture's groupings of the planar 2R's dynamic coefficients (notes pp. 22-23), as a named
alternative to dynid's base parameters.

For the planar 2R of the notes (:func:`dynid.models.planar_2r`: standard DH rows [l1, 0, 0, 0],
[l2, 0, 0, 0], the centre of mass of link i on the link's axis at d_i from joint i, gravity g0
along -y of the base, or none), found by inspection (p. 22, five coefficients):

    a1 = Ic1 + m1 d1^2 + Ic2 + m2 d2^2 + m2 l1^2,  a2 = m2 l1 d2,  a3 = Ic2 + m2 d2^2,
    a4 = g0 (m1 d1 + m2 l1),  a5 = g0 m2 d2,

    u1 = qdd1 a1 + (c2 (2 qdd1 + qdd2) - s2 (qd2^2 + 2 qd1 qd2)) a2 + qdd2 a3 + c1 a4 + c12 a5
    u2 = (c2 qdd1 + s2 qd1^2) a2 + (qdd1 + qdd2) a3 + c12 a5

and, with l1 and g0 known, merged into four (p. 23: a2 and a5 both hold m2 d2):

    a1 = Ic1 + m1 d1^2 + Ic2 + m2 d2^2 + m2 l1^2,  a2 = m2 d2,  a3 = Ic2 + m2 d2^2,
    a4 = m1 d1 + m2 l1,

    u1 = qdd1 a1 + (l1 c2 (2 qdd1 + qdd2) - l1 s2 (qd2^2 + 2 qd1 qd2) + g0 c12) a2 + qdd2 a3
         + g0 c1 a4
    u2 = (l1 c2 qdd1 + l1 s2 qd1^2 + g0 c12) a2 + (qdd1 + qdd2) a3.

Ic_i is the link's inertia about its centre of mass (z axis). In dynid's standard parameters
(frame i at the distal end of link i: mx_i = m_i (d_i - l_i), Izz_i = Ic_i + m_i (d_i - l_i)^2)
m_i d_i = mx_i + m_i l_i and Ic_i + m_i d_i^2 = Izz_i + 2 l_i mx_i + m_i l_i^2, so each
coefficient is a fixed combination of the standard parameters: ``Grouping.beta`` (k, 10 n) with
a = beta @ pi, as ``BaseParameters.beta`` for dynid's own base. The notes' model has no
perpendicular offset of the centres of mass (my_i = 0): dynid's base has six parameters
(my1 and my2 besides), the notes' four span the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from .robot import Robot

#: The groupings by name: the heuristic one of p. 22 and the minimal one of p. 23.
GROUPINGS = ("notes_2r_heuristic", "notes_2r")


@dataclass(frozen=True)
class Grouping:
    """A grouping of a 2R's standard parameters pi into the coefficients a = beta @ pi, with the
    regression matrix Y(q, qd, qdd) of u = Y a (notes pp. 22-23)."""

    name: str
    names: tuple[str, ...]
    expressions: tuple[str, ...]
    beta: NDArray[np.float64]  #: (k, 20): a = beta @ robot.parameter_vector()
    l1: float
    g0: float

    def coefficients(self, robot: Robot) -> NDArray[np.float64]:
        """a = beta @ pi of ``robot``'s standard parameters."""
        values: NDArray[np.float64] = self.beta @ robot.parameter_vector()
        return values

    def regressor(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """Y (T, 2, k) for T samples (T, 2) of q, qd, qdd: u = Y a (module docstring)."""
        q, qd, qdd = (_samples(v, name) for v, name in ((q, "q"), (qd, "qd"), (qdd, "qdd")))
        if not (q.shape == qd.shape == qdd.shape):
            raise ValueError(f"qd, qdd: expected the shape of q {q.shape}")
        c1, c2, s2 = np.cos(q[:, 0]), np.cos(q[:, 1]), np.sin(q[:, 1])
        c12 = np.cos(q[:, 0] + q[:, 1])
        a1, a2 = qdd[:, 0], qdd[:, 1]
        v1, v2 = qd[:, 0], qd[:, 1]
        coupling_1 = c2 * (2 * a1 + a2) - s2 * (v2**2 + 2 * v1 * v2)
        coupling_2 = c2 * a1 + s2 * v1**2
        zero = np.zeros_like(a1)
        l1, g0 = self.l1, self.g0
        if self.name == "notes_2r_heuristic":
            rows = [
                [a1, coupling_1, a2, c1, c12],
                [zero, coupling_2, a1 + a2, zero, c12],
            ]
        else:
            rows = [
                [a1, l1 * coupling_1 + g0 * c12, a2, g0 * c1],
                [zero, l1 * coupling_2 + g0 * c12, a1 + a2, zero],
            ]
        return np.stack([np.stack(row, axis=-1) for row in rows], axis=1)


def notes_2r_grouping(robot: Robot, name: str = "notes_2r") -> Grouping:
    """The notes' grouping ``name`` ("notes_2r": p. 23, four coefficients; "notes_2r_heuristic":
    p. 22, five) for ``robot``, a planar 2R of the notes' form (module docstring). ValueError
    naming what differs: not two revolute joints with DH rows [l, 0, 0, 0], a centre of mass
    off the link axes (my_i or mz_i != 0), gravity with an x component (g0 is its -y one; a z
    component does no work in the x-y plane)."""
    checks.robot(robot)
    if name not in GROUPINGS:
        raise ValueError(f"name: expected one of {', '.join(GROUPINGS)}, got {name!r}")
    dh = robot.dh
    if robot.n != 2 or robot.joint_types != "RR" or robot.convention != "standard":
        raise ValueError("robot: expected a planar 2R in standard DH (dynid.models.planar_2r)")
    if np.any(dh[:, 1:] != 0):
        raise ValueError(f"robot: expected DH rows [l_i, 0, 0, 0] (a planar 2R), got {dh.tolist()}")
    offsets = robot.params[:, 2:4]
    if np.any(offsets != 0):
        raise ValueError(
            "robot: the notes' grouping needs each centre of mass on its link's axis "
            f"(my_i = mz_i = 0), got my, mz = {offsets.tolist()}"
        )
    gravity = robot.gravity_vector
    if gravity[0] != 0:  # along z it does no work on a motion in the x-y plane
        raise ValueError(
            f"robot: expected gravity along -y of the base (the notes' g0), got {gravity.tolist()}"
        )
    l1, l2 = float(dh[0, 0]), float(dh[1, 0])
    g0 = -float(gravity[1])
    # Columns of the standard parameters (10 per link, standard order m mx my mz Ixx ... Izz).
    m = (0, 10)
    mx = (1, 11)
    izz = (9, 19)
    lengths = (l1, l2)

    def row(terms: dict[int, float]) -> NDArray[np.float64]:
        out = np.zeros(20)
        for column, value in terms.items():
            out[column] += value
        return out

    def md(i: int) -> dict[int, float]:  # m_i d_i = mx_i + m_i l_i
        return {mx[i]: 1.0, m[i]: lengths[i]}

    def inertia(i: int) -> dict[int, float]:  # Ic_i + m_i d_i^2 = Izz_i + 2 l_i mx_i + m_i l_i^2
        return {izz[i]: 1.0, mx[i]: 2 * lengths[i], m[i]: lengths[i] ** 2}

    a1 = row(inertia(0)) + row(inertia(1)) + row({m[1]: l1**2})
    a3 = row(inertia(1))
    names: tuple[str, ...]
    expressions: tuple[str, ...]
    if name == "notes_2r":
        beta = np.stack([a1, row(md(1)), a3, row(md(0)) + row({m[1]: l1})])
        names = ("a1", "a2", "a3", "a4")
        expressions = (
            "Ic1 + m1 d1^2 + Ic2 + m2 d2^2 + m2 l1^2",
            "m2 d2",
            "Ic2 + m2 d2^2",
            "m1 d1 + m2 l1",
        )
    else:
        beta = np.stack(
            [
                a1,
                l1 * row(md(1)),
                a3,
                g0 * (row(md(0)) + row({m[1]: l1})),
                g0 * row(md(1)),
            ]
        )
        names = ("a1", "a2", "a3", "a4", "a5")
        expressions = (
            "Ic1 + m1 d1^2 + Ic2 + m2 d2^2 + m2 l1^2",
            "m2 l1 d2",
            "Ic2 + m2 d2^2",
            "g0 (m1 d1 + m2 l1)",
            "g0 m2 d2",
        )
    return Grouping(name, names, expressions, beta, l1, g0)


def _samples(value: ArrayLike, name: str) -> NDArray[np.float64]:
    array = real_array(value, name)
    if array.ndim == 1:
        array = array[None]
    if array.ndim != 2 or array.shape[1] != 2:
        raise ValueError(f"{name}: expected shape (T, 2) or (2,), got {array.shape}")
    return array
