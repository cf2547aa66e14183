"""The lecture's planar robot with a parallelogram structure (notes pp. 7-10) as a closed chain.

Links as numbered on p. 7: links 1 and 2 are pivoted at the base origin and driven there (their
absolute angles are q1 and q2, measured from the x axis); link 3 is pivoted at the tip B of link
2 and stays parallel to link 1; link 4 is pivoted at the tip A of link 1, points along -e(q2)
(p_c4 = l1 e(q1) - lc4 e(q2)) and closes the loop at C = A + l2 e(q2), the far end of link 3. So
theta_1 = theta_3 = q1 and theta_2 = theta_4 = q2 (absolute angles). The motion is in the base
x-y plane and gravity g0 acts along -y, so the potential energy comes from the y-components of
the p_ci (p. 10).

The spanning tree cuts the joint at C: branch 0 is link 1 then link 4 (relative angle
q2 + pi - q1), branch 1 is link 2 then link 3 (relative angle q1 - q2); the closure is linear
(:class:`~dynid.model.loop_closures.LinearClosure`). With the notes' closed forms (p. 9)

    B11 = Izz1 + m1 lc1^2 + Izz3 + m3 lc3^2 + m4 l1^2,
    B22 = Izz2 + m2 lc2^2 + Izz4 + m4 lc4^2 + m3 l2^2,
    B12 = (m3 l2 lc3 - m4 l1 lc4) cos(q2 - q1),
    g = g0 ((m1 lc1 + m3 lc3 + m4 l1) cos q1, (m2 lc2 + m3 l2 - m4 lc4) cos q2),

and with m3 l2 lc3 = m4 l1 lc4 the inertia matrix is diagonal and constant: no Coriolis or
centrifugal terms (the mechanically decoupled design of p. 9).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import _checks as checks
from .closed_chain import ClosedChain
from .loop_closures import LinearClosure
from .robot import Robot


def planar_parallelogram(
    masses: Sequence[float],
    inertias: Sequence[float],
    com_distances: Sequence[float],
    l1: float,
    l2: float,
    gravity: float = 9.81,
) -> ClosedChain:
    """The notes' parallelogram robot (pp. 7-10) as a :class:`dynid.ClosedChain`.

    Parameters
    ----------
    masses : 4 floats
        m1..m4 [kg], > 0, links numbered as on p. 7.
    inertias : 4 floats
        Ic_i,zz, the inertia of link i about its CoM around z [kg m^2], > 0.
    com_distances : 4 floats
        lc1..lc4 [m]: the CoM of link i on its axis at lc_i from its pivot (link 4: from A,
        along -e(q2); a CoM beyond the pivot is a negative distance).
    l1, l2 : float
        Lengths of links 1 and 2 [m], > 0 (link 3 is l1 long, link 4 reaches C at l2 from A).
    gravity : float
        g0 [m/s^2] along -y (0 for a horizontal plane).
    """
    m, inertia, lc = (
        _four(values, name)
        for values, name in (
            (masses, "masses"),
            (inertias, "inertias"),
            (com_distances, "com_distances"),
        )
    )
    if np.any(m <= 0) or np.any(inertia <= 0):
        raise ValueError("masses, inertias: expected positive values")
    l1, l2 = checks.positive(l1, "l1"), checks.positive(l2, "l2")
    try:
        g0 = float(gravity)
    except (TypeError, ValueError):
        g0 = float("nan")
    if not np.isfinite(g0) or isinstance(gravity, bool):
        raise ValueError(f"gravity: expected a finite g0 [m/s^2], got {gravity!r}")
    g = (0.0, -g0, 0.0)

    def branch(first_length: float, tool_x: float, name: str) -> Robot:
        tool = np.eye(4)
        tool[0, 3] = tool_x
        rows = [[0.0, 0.0, 0.0, 0.0], [first_length, 0.0, 0.0, 0.0]]
        return Robot.from_dh(
            rows, joint_types="RR", convention="modified", gravity=g, tool=tool, name=name
        )

    # Modified DH puts frame i at pivot i with x_i along link i, so each CoM is (lc_i, 0, 0) and
    # the parameters are the notes' (mx_i = m_i lc_i, Izz_i about the pivot). Link 4's frame sits
    # at A with x along -e(q2); C is at x = -l2 (branch 0's tool), and at x = l1 on link 3.
    links_14 = branch(l1, -l2, "links 1, 4")
    links_23 = branch(l2, l1, "links 2, 3")
    placement = {1: (links_14, 0), 4: (links_14, 1), 2: (links_23, 0), 3: (links_23, 1)}
    for number, (robot, index) in placement.items():
        izz = inertia[number - 1]
        # A slender rod along its x axis: only Izz enters planar motion, the tiny axial inertia
        # keeps the tensor positive definite (as dynid.models.planar_2r).
        tensor = np.diag([0.01 * izz, izz, izz])
        robot.set_link(index, float(m[number - 1]), (lc[number - 1], 0.0, 0.0), tensor)
    # Tree joints [theta_1, theta_4 (rel. to link 1), theta_2, theta_3 (rel. to link 2)].
    closure = LinearClosure(
        [[1.0, 0.0], [-1.0, 1.0], [0.0, 1.0], [1.0, -1.0]], offset=[0.0, np.pi, 0.0, 0.0]
    )
    return ClosedChain(
        [links_14, links_23],
        closure,
        links=[(0, 0), (1, 0), (1, 1), (0, 1)],
        name="planar parallelogram",
    )


def _four(values: Sequence[float], name: str) -> np.ndarray:
    arr = np.array(values, dtype=float)
    if arr.shape != (4,) or not np.all(np.isfinite(arr)):
        raise ValueError(
            f"{name}: expected 4 finite values (links 1-4 of the notes), got {values!r}"
        )
    return arr
