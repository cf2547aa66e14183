"""The notes' k2, k3, k5, k7 (p. 4; dynid.model.growth_bounds): zero for revolute joints only,
the closed forms of a polar R-P arm (B11 = I + m2 (d + c)^2: k3 = m2, k2 = 2 m2 |c|; S linear in d;
g1 = m2 g0 cos q1), and the quadratic growth of S that an R-R-P arm has (the notes' linear form
does not hold for it)."""

from __future__ import annotations

import numpy as np

import dynid
from dynid.model.growth_bounds import growth_bounds

M2, C, G0 = 2.5, 0.15, 9.81


def _polar() -> dynid.Robot:
    robot = dynid.Robot(
        dh=np.array([[0.0, -np.pi / 2, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]]),
        joint_types="RP",
        gravity=(0.0, -G0, 0.0),
    )
    robot.qlim = [[-np.pi, np.pi], [0.2, 1.0]]
    robot.set_link(0, 1.0, (0, 0, 0), np.diag([0.02, 0.02, 0.02]))
    robot.set_link(1, M2, (0.0, 0.0, C), np.diag([0.01, 0.01, 0.004]))
    return robot


def test_revolute_arms_do_not_grow() -> None:
    b = growth_bounds(dynid.models.kuka_lwr4(), samples=300)
    scale = b.k1 + b.k4 + b.k6
    for value in (b.k2, b.k3, b.k5, b.k5_quadratic, b.k7):
        assert value <= 1e-12 * scale


def test_polar_rp_arm_closed_forms() -> None:
    b = growth_bounds(_polar(), samples=4000)
    assert abs(b.k3 - M2) <= 1e-9 * M2
    assert abs(b.k2 - 2 * M2 * C) <= 1e-9 * M2
    assert b.k5_quadratic <= 1e-12 * b.k5  # S linear in d: the notes' form holds
    # S1(v) = m2 [[v2, v1], [-v1, 0]] for a unit velocity v: its largest spectral norm over v,
    # by a dense sweep (the estimate samples v: within 1 %)
    angles = np.linspace(0, np.pi, 20001)
    sweep = max(
        np.linalg.norm(M2 * np.array([[np.sin(a), np.cos(a)], [-np.cos(a), 0.0]]), 2)
        for a in angles
    )
    assert 0.99 * sweep <= b.k5 <= sweep * (1 + 1e-9)
    # g = [m2 g0 (d + c) cos q1, m2 g0 sin q1]: g1 = [m2 g0 cos q1, 0], largest at q1 = 0
    assert 0.999 * M2 * G0 <= b.k7 <= M2 * G0 * (1 + 1e-9)


def test_an_rrp_arm_has_coriolis_terms_quadratic_in_the_displacement() -> None:
    robot = dynid.Robot(
        dh=np.array(
            [[0.0, -np.pi / 2, 0.3, 0.0], [0.0, np.pi / 2, 0.1, 0.0], [0.0, 0.0, 0.0, 0.0]]
        ),
        joint_types="RRP",
    )
    robot.qlim = [[-np.pi, np.pi], [-np.pi, np.pi], [0.2, 1.0]]
    for i, mass in enumerate((3.0, 2.0, 1.5)):
        robot.set_link(i, mass, (0.0, 0.0, 0.05), np.diag([0.02, 0.02, 0.01]))
    b = growth_bounds(robot, samples=3000)
    assert b.k5_quadratic > 0.1 * 1.5  # ~ m3 |sin q2 cos q2|: the notes' k4 + k5 ||q|| fails
    # the d^2 term of S at one state, directly: S(d) at d = 0, 1, 2 has a second difference
    q = np.array([0.4, 0.7, 0.0])
    v = np.array([0.0, 1.0, 0.0])
    S = [robot.coriolis_matrix(q + np.array([0.0, 0.0, d]), v) for d in (0.0, 1.0, 2.0)]
    assert np.abs(S[2] - 2 * S[1] + S[0]).max() > 0.1
