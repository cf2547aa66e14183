"""The dry run of an experiment (dynid.sim.rehearsal.rehearse): the arm tracks a trajectory
under its controller and what its controller would log comes out.

Independent checks: the logged torque is the command that moved the plant (the frictionless
plant's inverse dynamics at the simulated states gives it back), the sensor noise has the
asked standard deviation and leaves the motion unchanged, the logged positions lie on the
encoder's grid, the default gains track the trajectory, and a least-squares fit on the
rehearsal's logged velocities recovers the arm's base parameters with calibrated standard
deviations.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.excitation import FourierTrajectory
from dynid.identification.log_identification import identify_log
from dynid.logs import Log
from dynid.model.base_parameters import base_parameters
from dynid.sim.rehearsal import rehearse


@pytest.fixture(scope="module")
def arm():
    robot = dynid.models.kuka_lwr4()
    rng = np.random.default_rng(1)
    a, b = rng.normal(scale=0.3, size=(2, 7, 4))
    return robot, FourierTrajectory(2 * np.pi * 0.1, a, b, np.zeros(7))


def test_the_logged_torque_is_the_one_that_moved_the_arm(arm) -> None:
    robot, trajectory = arm
    run = rehearse(robot, trajectory.evaluate, 2.0, friction=False)
    s = run.simulation
    plant = robot.copy()
    plant.Fv = plant.Fs = np.zeros(7)  # the plant ran without friction
    expected = plant.rnea(s.q, s.qd, s.qdd)  # qdd at t_k under the command held from t_k
    assert np.max(np.abs(s.tau - expected)) <= 1e-9 * np.max(np.abs(expected))
    np.testing.assert_array_equal(run.q, s.q)  # no encoder: the exact positions
    # The logged torque is the one that acted around t_k: the inverse dynamics with the central
    # difference of the velocity matches it to O(dt^2), the held command only to O(dt).
    qdd_central = (s.qd[2:] - s.qd[:-2]) / (2 * (s.t[1] - s.t[0]))
    central = plant.rnea(s.q[1:-1], s.qd[1:-1], qdd_central)
    logged_error = np.abs(run.tau[1:-1] - central).max()
    command_error = np.abs(s.tau[1:-1] - central).max()
    assert logged_error < 0.05 * command_error, (logged_error, command_error)
    # default gains: a 10 Hz critically damped loop per joint tracks to about a milliradian
    assert np.all(run.tracking_error < 5e-3)
    np.testing.assert_allclose(run.kp, np.diag(robot.mass_matrix(s.q[0])) * (20 * np.pi) ** 2)


def test_sensor_noise_is_on_the_log_only_and_has_its_size(arm) -> None:
    robot, trajectory = arm
    quiet = rehearse(robot, trajectory.evaluate, 3.0, seed=4)
    noisy = rehearse(robot, trajectory.evaluate, 3.0, sensor_noise=0.2, seed=4)
    np.testing.assert_array_equal(noisy.simulation.q, quiet.simulation.q)
    noise = noisy.tau - quiet.tau
    assert abs(noise.std() / 0.2 - 1) < 0.02 and abs(noise.mean()) < 0.01
    other = rehearse(robot, trajectory.evaluate, 3.0, sensor_noise=0.2, seed=5)
    assert not np.array_equal(other.tau, noisy.tau)


def test_encoder_counts_quantise_the_logged_positions(arm) -> None:
    robot, trajectory = arm
    counts = 2**14
    run = rehearse(robot, trajectory.evaluate, 1.0, encoder_counts=counts)
    steps = run.q / (2 * np.pi / counts)
    assert np.max(np.abs(steps - np.rint(steps))) < 1e-6
    assert np.max(np.abs(run.q - run.simulation.q)) <= 2 * np.pi / counts


def test_identification_on_a_rehearsal_recovers_the_arm(arm) -> None:
    """Sensor noise 0.05 N m, the states the plant went through: every base parameter within
    its standard deviation's reach (RMS z-score in [0.7, 1.3]); rows near velocity reversals
    left out (the plant's Coulomb friction is smoothed over 1e-3 rad/s, the model's is
    sign(qd))."""
    robot, trajectory = arm
    run = rehearse(robot, trajectory.evaluate, 30.0, sensor_noise=0.05, seed=3)
    s = run.simulation
    log = Log(t=run.t, q=s.q, qd=s.qd, tau=run.tau)  # qdd: central differences of qd
    result = identify_log(log, robot, rotor=True, friction=True, preparation={"min_velocity": 0.02})
    base = base_parameters(robot, "torque", rotor=True, friction=True)
    truth = base.beta @ robot.parameter_vector(True, True)
    z = (result.theta - truth) / result.std
    assert 0.7 <= np.sqrt(np.mean(z**2)) <= 1.3
    assert np.abs(z).max() < 4.0


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"controller": "lqr"}, "controller: expected one of pd, pd_gravity, computed_torque"),
        ({"sensor_noise": -1.0}, "sensor_noise: expected a finite number >= 0"),
        ({"rate": 0.0}, "rate: expected a finite number > 0"),
        ({"kp": [1.0, 2.0]}, r"kp: expected a scalar or shape \(7,\)"),
        ({"encoder_counts": 0.5}, "encoder_counts"),
    ],
)
def test_bad_options_are_named(arm, options, message) -> None:
    robot, trajectory = arm
    with pytest.raises(ValueError, match=message):
        rehearse(robot, trajectory.evaluate, 0.1, **options)
