"""Optimal point-to-point motion (notes p. 50; dynid.motion.optimal_motion): the 1-DoF closed
forms (minimum energy: the cubic, E = 12 I^2 D^2 / T^3; minimum time under |tau| <= tau_max:
bang-bang, T* = 2 sqrt(I D / tau_max)), the torques equal to rnea along the returned motion, the
bounds active over most of the minimum-time motion, and the minimum energy falling as T grows
(the planar 2R and the LWR-IV)."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.motion.optimal_motion import minimum_energy_motion, minimum_time_motion


@pytest.fixture(scope="module")
def one_link():
    robot = dynid.Robot(dh=np.array([[0.5, 0.0, 0.0, 0.0]]), joint_types="R", gravity=(0, 0, -9.81))
    robot.set_link(0, 2.0, (-0.25, 0.0, 0.0), np.diag([0.01, 0.05, 0.05]))
    return robot, float(robot.mass_matrix(np.zeros(1))[0, 0])  # the axis is vertical: no gravity


def test_one_dof_minimum_energy_is_the_cubic(one_link) -> None:
    robot, inertia = one_link
    for T in (0.8, 1.5):
        motion = minimum_energy_motion(robot, [0.0], [1.2], T)
        assert motion.success
        assert abs(motion.energy - 12 * inertia**2 * 1.2**2 / T**3) <= 1e-9 * motion.energy
        s = motion.t / T
        cubic = 1.2 * (3 * s**2 - 2 * s**3)
        # the optimiser's tolerance: the energy to 1e-9, the path to ~1e-8 of its 1.2 rad
        np.testing.assert_allclose(motion.q[:, 0], cubic, rtol=0, atol=1e-7)


def test_one_dof_minimum_time_approaches_bang_bang(one_link) -> None:
    robot, inertia = one_link
    motion = minimum_time_motion(robot, [0.0], [1.2], 5.0, functions=10)
    bang_bang = 2 * np.sqrt(inertia * 1.2 / 5.0)
    assert motion.success and bang_bang * 0.995 <= motion.duration <= 1.03 * bang_bang
    assert np.mean(np.abs(motion.tau) > 0.95 * 5.0) > 0.6  # at the bounds most of the time
    assert np.abs(motion.tau).max() <= 1.01 * 5.0  # the bounds are on nodes: ~0.5 % between


@pytest.mark.parametrize("name", ["planar_2r", "kuka_lwr4"])
def test_trade_off_and_torques(name) -> None:
    robot = getattr(dynid.models, name)()
    if name == "planar_2r":
        q0, q1, bound = (
            np.array([-np.pi / 2, 0.0]),
            np.array([0.0, np.pi / 2]),
            np.array([40.0, 15.0]),
        )
    else:
        q0, q1 = np.zeros(7), np.array([0.8, 0.6, -0.5, -1.0, 0.7, 0.9, -0.6])
        bound = np.array([176.0, 176.0, 100.0, 100.0, 100.0, 38.0, 38.0])
    fastest = minimum_time_motion(robot, q0, q1, bound)
    assert fastest.success
    np.testing.assert_allclose(
        fastest.tau, robot.rnea(fastest.q, fastest.qd, fastest.qdd), rtol=0, atol=1e-9
    )
    np.testing.assert_allclose(fastest.q[0], q0, atol=1e-12)
    np.testing.assert_allclose(fastest.q[-1], q1, atol=1e-12)
    assert np.abs(fastest.qd[[0, -1]]).max() <= 1e-9  # at rest at both ends (polynomial rounding)
    assert np.any(np.abs(fastest.tau).max(axis=0) >= 0.99 * bound)  # a bound is active
    energies = [
        minimum_energy_motion(robot, q0, q1, k * fastest.duration).energy for k in (1.25, 1.5, 2.0)
    ]
    assert energies[0] > energies[1] > energies[2]  # slower motions cost less


def test_bad_input_is_named(one_link) -> None:
    robot, _ = one_link
    with pytest.raises(ValueError, match="duration"):
        minimum_energy_motion(robot, [0.0], [1.0], -1.0)
    with pytest.raises(ValueError, match="tau_max"):
        minimum_time_motion(robot, [0.0], [1.0], 0.0)
    with pytest.raises(ValueError, match=r"q_end: expected shape \(1,\)"):
        minimum_energy_motion(robot, [0.0], [1.0, 2.0], 1.0)
