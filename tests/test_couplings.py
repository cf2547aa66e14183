"""The structure of B(q) and g(q) (notes pp. 2-3; dynid.model.couplings.dynamic_structure) on
the notes' examples, each built here from its DH table: the Cartesian robot (B constant and
diagonal), the "skew" Cartesian robot (constant, b12 != 0), the PR and 2R robots (b11(q2),
b12(q2), b22 constant; constant B when the centre of mass of link 2 is on joint 2's axis), the 3R
articulated robot (b11(q2, q3), b22(q3), b23(q3), b33 constant, b12 = b13 = 0) and the absence
of gravity (planar motion in a horizontal plane: g = 0, a linear model when B is constant)."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.model.couplings import dynamic_structure


def _arm(dh, types, gravity=(0.0, 0.0, -9.81), links=None):
    robot = dynid.Robot(dh=np.array(dh, dtype=float), joint_types=types, gravity=gravity)
    for i, (mass, com, inertia) in enumerate(links):
        robot.set_link(i, mass, com, np.diag(inertia))
    return robot


def test_cartesian_robot_constant_diagonal() -> None:
    # two prismatic joints along orthogonal axes (z0, then x after alpha = pi/2)
    robot = _arm(
        [[0, -np.pi / 2, 0, 0], [0, 0, 0, 0]],
        "PP",
        links=[(2.0, (0, 0, 0), (0.1, 0.1, 0.1)), (1.0, (0, 0, 0), (0.1, 0.1, 0.1))],
    )
    s = dynamic_structure(robot)
    assert s.inertia_constant and s.entry(0, 1) == "0" and s.entry(0, 0) == "const"
    assert s.gravity == ((), ()) and not s.no_gravity  # m g on the vertical axis: constant


def test_skew_cartesian_robot_constant_coupled() -> None:
    robot = _arm(
        [[0, -np.pi / 3, 0, 0], [0, 0, 0, 0]],
        "PP",
        links=[(2.0, (0, 0, 0), (0.1, 0.1, 0.1)), (1.0, (0, 0, 0), (0.1, 0.1, 0.1))],
    )
    s = dynamic_structure(robot)
    assert s.inertia_constant and s.entry(0, 1) == "const"  # b12 != 0: the axes are not orthogonal


def test_2r_robot_and_its_balanced_case() -> None:
    s = dynamic_structure(dynid.models.planar_2r())
    assert [s.entry(0, 0), s.entry(0, 1), s.entry(1, 1)] == ["b(q2)", "b(q2)", "const"]
    assert s.gravity == ((0, 1), (0, 1))
    on_axis = dynamic_structure(dynid.models.planar_2r(lc2=0.0))  # CoM of link 2 on joint 2
    assert on_axis.inertia_constant and not on_axis.linear
    assert on_axis.gravity == ((0,), ()) and on_axis.gravity_zero[1]


def test_pr_robot() -> None:
    # a prismatic joint along x0, then a revolute joint about z: the notes' PR robot
    robot = _arm(
        [[0, np.pi / 2, 0, 0], [0.6, -np.pi / 2, 0, 0]],
        "PR",
        gravity=(0, -9.81, 0),
        links=[(3.0, (0, 0, 0), (0.1, 0.1, 0.1)), (1.5, (-0.3, 0, 0), (0.02, 0.05, 0.05))],
    )
    s = dynamic_structure(robot)
    assert [s.entry(0, 0), s.entry(0, 1), s.entry(1, 1)] == ["const", "b(q2)", "const"]


def test_3r_articulated_robot() -> None:
    # anthropomorphic: vertical joint 1, then two parallel horizontal joints; CoMs on the link
    # axes, principal inertias along the DH axes (the notes' simplifying assumptions)
    robot = _arm(
        [[0, np.pi / 2, 0.4, 0], [0.5, 0, 0, 0], [0.4, 0, 0, 0]],
        "RRR",
        links=[
            (4.0, (0, -0.2, 0), (0.05, 0.02, 0.05)),
            (3.0, (-0.25, 0, 0), (0.01, 0.08, 0.08)),
            (2.0, (-0.2, 0, 0), (0.01, 0.04, 0.04)),
        ],
    )
    s = dynamic_structure(robot)
    assert [s.entry(0, 0), s.entry(0, 1), s.entry(0, 2)] == ["b(q2, q3)", "0", "0"]
    assert [s.entry(1, 1), s.entry(1, 2), s.entry(2, 2)] == ["b(q3)", "b(q3)", "const"]
    assert s.gravity[0] == () and s.gravity_zero[0] and s.gravity[1] == (1, 2)


def test_no_gravity_and_a_linear_model() -> None:
    horizontal = dynid.models.planar_2r(gravity=(0.0, 0.0, -9.81))  # axes along gravity
    s = dynamic_structure(horizontal)
    assert s.no_gravity and not s.inertia_constant and not s.linear
    linear = dynamic_structure(dynid.models.planar_2r(lc2=0.0, gravity=(0.0, 0.0, -9.81)))
    assert linear.linear and "linear (g = 0, B constant)" in linear.table()


def test_a_general_arm_and_bad_input() -> None:
    s = dynamic_structure(dynid.models.kuka_lwr4())
    # B_ij depends only on the joints after min(i, j): the kinetic energy of the chain beyond
    # a joint does not change when that joint and the ones before it turn (never on q_1)
    for i in range(7):
        for j in range(7):
            assert all(k > min(i, j) for k in s.inertia[i][j])
    assert s.inertia[0][0] == (1, 2, 3, 4, 5, 6)
    with pytest.raises(ValueError, match="tolerance"):
        dynamic_structure(dynid.models.planar_2r(), tolerance=2.0)
    with pytest.raises(ValueError, match="samples"):
        dynamic_structure(dynid.models.planar_2r(), samples=0)
