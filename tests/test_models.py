"""The ready-made models (dynid.models) against published values.

- PUMA 560: gravity torques at the Robotics Toolbox's nominal pose qn = [0, pi/4, pi, 0, pi/4, 0]
  against the toolbox's own test values, [0, 31.6399, 6.0351, 0, 0.0283, 0] N m (Peter Corke,
  robotics-toolbox-python, tests/test_SerialLink.py, test_gravload: ``taur``, checked there to 4
  decimals), with the same "params of 8/95" model and gravity 9.81 m/s^2. Tolerance 1e-3 N m
  absolute: the published values are rounded to 1e-4.
- KUKA LWR-IV: the DH table of Table I of Gaz, Flacco, De Luca (ICRA 2014) with d1 = 0.4 m and
  d2 = 0.39 m (Sect. VII), and joint limits of +-170 deg (joints 1, 3, 5, 7) and +-120 deg
  (joints 2, 4, 6).
- planar 2R: the standard and modified DH descriptions are the same arm: the same M(q) and g(q)
  at random states, to 1e-12 (relative to the largest entry, both are O(1)).
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid

PUMA_QN = np.array([0.0, np.pi / 4, np.pi, 0.0, np.pi / 4, 0.0])
PUMA_GRAVITY_QN = np.array([0.0, 31.6399, 6.0351, 0.0, 0.0283, 0.0])  # N m, toolbox test_gravload

D1, D2 = 0.4, 0.39  # m, Gaz et al. Sect. VII
LWR_TABLE_I = np.array([  # a, alpha, d, theta offset (theta_i = q_i)
    [0.0,  np.pi / 2, 0.0, 0.0],
    [0.0, -np.pi / 2, 0.0, 0.0],
    [0.0, -np.pi / 2, D1,  0.0],
    [0.0,  np.pi / 2, 0.0, 0.0],
    [0.0,  np.pi / 2, D2,  0.0],
    [0.0, -np.pi / 2, 0.0, 0.0],
    [0.0,  0.0,       0.0, 0.0],
])  # fmt: skip


def test_puma560_gravity_at_the_nominal_pose_matches_the_robotics_toolbox():
    robot = dynid.models.puma560()
    assert np.allclose(robot.gravity_vector, [0.0, 0.0, -9.81])
    np.testing.assert_allclose(robot.gravity(PUMA_QN), PUMA_GRAVITY_QN, rtol=0, atol=1e-3)


def test_lwr4_dh_table_is_table_one_of_the_paper():
    robot = dynid.models.kuka_lwr4()
    assert robot.n == 7
    assert robot.joint_types == "R" * 7
    assert robot.convention == "standard"
    np.testing.assert_allclose(robot.dh, LWR_TABLE_I, rtol=0, atol=1e-15)


def test_lwr4_joint_limits():
    robot = dynid.models.kuka_lwr4()
    limits = np.radians([170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 170.0])
    np.testing.assert_allclose(robot.qlim[:, 0], -limits, rtol=1e-15)
    np.testing.assert_allclose(robot.qlim[:, 1], limits, rtol=1e-15)
    for j in (0, 2, 4, 6):  # joints 1, 3, 5, 7
        assert np.degrees(robot.qlim[j]) == pytest.approx([-170.0, 170.0], abs=1e-12)
    for j in (1, 3, 5):  # joints 2, 4, 6
        assert np.degrees(robot.qlim[j]) == pytest.approx([-120.0, 120.0], abs=1e-12)


@pytest.mark.parametrize(
    "gravity", [(0.0, -9.81, 0.0), (0.0, 0.0, -9.81)], ids=["vertical plane", "horizontal plane"]
)
def test_planar_2r_standard_and_modified_are_the_same_arm(gravity):
    kwargs = {
        "l1": 0.8,
        "l2": 0.6,
        "lc1": 0.35,
        "lc2": 0.25,
        "m1": 2.0,
        "m2": 1.5,
        "gravity": gravity,
    }
    standard = dynid.models.planar_2r(convention="standard", **kwargs)
    modified = dynid.models.planar_2r(convention="modified", **kwargs)
    assert (standard.convention, modified.convention) == ("standard", "modified")
    q = np.random.default_rng(7).uniform(-np.pi, np.pi, size=(20, 2))
    np.testing.assert_allclose(modified.mass_matrix(q), standard.mass_matrix(q), rtol=0, atol=1e-12)
    np.testing.assert_allclose(modified.gravity(q), standard.gravity(q), rtol=0, atol=1e-12)


def test_planar_2r_default_matches_the_closed_form_of_the_notes():
    """Independent check of the shared model: M and g of the notes (pp. 22-24) for the defaults
    l = 1, lc = 0.5, m = 1, I = m l^2 / 12 and g0 = 9.81 along -y."""
    l1 = 1.0
    d1 = d2 = 0.5
    m1 = m2 = 1.0
    i1 = i2 = 1.0 / 12.0
    g0 = 9.81
    for convention in ("standard", "modified"):
        robot = dynid.models.planar_2r(convention=convention)
        for q1, q2 in ((0.3, -1.1), (2.0, 0.7), (-0.4, 3.0)):
            c2 = np.cos(q2)
            a1 = i1 + m1 * d1**2 + i2 + m2 * d2**2 + m2 * l1**2
            a2 = m2 * l1 * d2
            a3 = i2 + m2 * d2**2
            M = np.array([[a1 + 2 * a2 * c2, a3 + a2 * c2], [a3 + a2 * c2, a3]])
            g = np.array(
                [
                    g0 * ((m1 * d1 + m2 * l1) * np.cos(q1) + m2 * d2 * np.cos(q1 + q2)),
                    g0 * m2 * d2 * np.cos(q1 + q2),
                ]
            )
            np.testing.assert_allclose(robot.mass_matrix([q1, q2]), M, rtol=0, atol=1e-12)
            np.testing.assert_allclose(robot.gravity([q1, q2]), g, rtol=0, atol=1e-12)


def test_rigid_body_copy_drops_only_the_drive_terms():
    robot = dynid.models.kuka_lwr4()
    body = robot.rigid_body()
    for name in ("Ia", "Fv", "Fs"):
        assert np.all(getattr(robot, name) > 0.0)  # the original keeps its drive terms
        np.testing.assert_array_equal(getattr(body, name), np.zeros(robot.n))
    np.testing.assert_array_equal(body.params, robot.params)
    q, qd, qdd = np.random.default_rng(3).uniform(-1.0, 1.0, (3, robot.n))
    # tau of the links alone = full tau minus the rotor and friction terms, written out here
    expected = robot.rnea(q, qd, qdd) - robot.Ia * qdd - robot.Fv * qd - robot.Fs * np.sign(qd)
    np.testing.assert_allclose(body.rnea(q, qd, qdd), expected, rtol=1e-12, atol=1e-12)
