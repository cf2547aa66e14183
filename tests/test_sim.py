"""The virtual controller (dynid.sim): what the LWR's interface reports, for any robot.

Paper Sect. II and V: GetCurrentGravityVector / GetCurrentMassMatrix return the controller's
numeric g(q), M(q) of the link equation (7) (no rotor inertia, no friction); the torque sensors
measure tau_J = M qdd + c + g plus the link-side friction, along a motion tracked in closed loop.
The references: the robot's own dynamics with its drive terms removed here, the NumPy reference
model (tests/reference_model.py), the motor torque minus the rotors' and the friction's share
(the plant's state equation), the closed-form friction, the closed form of paper eq. (33) and
finite differences.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
import reference_model as ref
from dynid.cli.demo import controller_model
from dynid.logs.signal import differentiate, lowpass
from dynid.sim import VirtualController, paper_validation_trajectory, plant_friction
from dynid.sim.virtual_controller import COULOMB_BAND, stable_substeps

# --- static readings -----------------------------------------------------------------------------


def test_noise_free_readings_are_the_link_dynamics_without_drive_terms():
    # The LWR model has Ia != 0: the controller's M must not contain it. Equal (1e-14 relative)
    # to the rigid copy's gravity / mass_matrix, and to the reference model (1e-10 relative).
    robot = dynid.models.kuka_lwr4()
    assert np.all(robot.Ia > 0)
    controller = VirtualController(robot, seed=1)
    q = controller.random_configurations(20)
    data = controller.read_static(q)
    np.testing.assert_array_equal(data.q, q)
    assert data.g.shape == (20, 7) and data.M.shape == (20, 7, 7)
    body = robot.rigid_body()
    np.testing.assert_allclose(data.g, body.gravity(q), rtol=0, atol=1e-14 * np.abs(data.g).max())
    np.testing.assert_allclose(
        data.M, body.mass_matrix(q), rtol=0, atol=1e-14 * np.abs(data.M).max()
    )
    arm = ref.arm_of(robot)
    for k in range(3):
        np.testing.assert_allclose(
            data.M[k], ref.mass_matrix(arm, q[k]), rtol=0, atol=1e-10 * np.abs(data.M).max()
        )
        np.testing.assert_allclose(
            data.g[k], ref.gravity(arm, q[k]), rtol=0, atol=1e-10 * np.abs(data.g).max()
        )
    # the controller works on its own copy: changing the robot afterwards changes nothing
    robot.params = 2 * robot.params
    np.testing.assert_array_equal(controller.read_static(q).g, data.g)


def test_one_configuration_is_one_sample():
    robot = dynid.models.kuka_lwr4()
    q = robot.random_configurations(1, seed=2)[0]
    data = VirtualController(robot).read_static(q)
    assert data.q.shape == (1, 7) and data.g.shape == (1, 7) and data.M.shape == (1, 7, 7)
    np.testing.assert_allclose(data.g[0], robot.rigid_body().gravity(q), rtol=1e-14, atol=1e-14)


def test_random_configurations_are_uniform_within_the_joint_limits():
    # Paper Sect. VI: uniform in +-170 deg (joints 1, 3, 5, 7) and +-120 deg (2, 4, 6).
    robot = dynid.models.kuka_lwr4()
    q = VirtualController(robot, seed=3).random_configurations(4000)
    limit = np.radians([170, 120, 170, 120, 170, 120, 170])
    assert q.shape == (4000, 7)
    assert np.all(np.abs(q) <= limit)
    # uniform on [-L, L]: mean 0 (std L / sqrt(3 N)), std L / sqrt(3); 5-sigma / 5 % bounds
    assert np.all(np.abs(q.mean(axis=0)) < 5 * limit / np.sqrt(3 * 4000))
    np.testing.assert_allclose(q.std(axis=0), limit / np.sqrt(3), rtol=0.05)


def test_model_noise_is_relative_and_keeps_zeros_zero():
    # controller_model(): M_76 is zero (up to rounding, 1e-18) in the true model. With relative
    # noise sigma = 1e-3 it stays below 1e-12 max|M|; the relative errors of g and of M's diagonal
    # have standard deviation sigma (5 %), of the symmetrised off-diagonal sigma / sqrt(2) (5 %).
    robot = controller_model()
    sigma = 1e-3
    clean = VirtualController(robot, seed=4)
    noisy = VirtualController(robot, model_noise=sigma, seed=4)
    q = clean.random_configurations(800)
    exact, data = clean.read_static(q), noisy.read_static(q)
    assert np.abs(exact.M[:, 6, 5]).max() <= 1e-15 * np.abs(exact.M).max()
    assert np.abs(data.M[:, 6, 5]).max() <= 1e-12 * np.abs(data.M).max()
    np.testing.assert_array_equal(data.M, np.swapaxes(data.M, 1, 2))
    np.testing.assert_array_equal(data.q, q)  # no position noise asked for

    def relative(reading, true):
        keep = np.abs(true) > 1e-6 * np.abs(true).max()
        return reading[keep] / true[keep] - 1.0

    g_rel = relative(data.g[:, 1:], exact.g[:, 1:])  # joint 1's gravity is zero
    diag = np.arange(7)
    d_rel = relative(data.M[:, diag, diag], exact.M[:, diag, diag])
    rows, cols = np.tril_indices(7, -1)
    o_rel = relative(data.M[:, rows, cols], exact.M[:, rows, cols])
    assert np.std(g_rel) == pytest.approx(sigma, rel=0.05)
    assert np.std(d_rel) == pytest.approx(sigma, rel=0.05)
    assert np.std(o_rel) == pytest.approx(sigma / np.sqrt(2), rel=0.05)
    assert abs(np.mean(g_rel)) < 5 * sigma / np.sqrt(g_rel.size)  # unbiased


def test_position_noise_is_added_to_the_reported_q_only():
    # The readings are at the true q; the reported q carries N(0, sigma^2) (std within 5 %).
    robot = dynid.models.kuka_lwr4()
    sigma = 1e-3
    controller = VirtualController(robot, position_noise=sigma, seed=5)
    q = controller.random_configurations(1000)
    data = controller.read_static(q)
    assert np.std(data.q - q) == pytest.approx(sigma, rel=0.05)
    np.testing.assert_allclose(
        data.g, robot.rigid_body().gravity(q), rtol=0, atol=1e-14 * np.abs(data.g).max()
    )


def test_same_seed_same_data_other_seed_other_data():
    robot = dynid.models.kuka_lwr4()
    noise = {"model_noise": 1e-4, "torque_noise": 0.05, "position_noise": 1e-4}

    def run(seed):
        controller = VirtualController(robot, seed=seed, **noise)
        data = controller.read_static(controller.random_configurations(30))
        track = controller.track(lambda t: paper_validation_trajectory(t), 0.5, 100.0)
        return data.q, data.g, data.M, track.q, track.tau

    first, again, other = run(7), run(7), run(8)
    for a, b, c in zip(first, again, other):
        np.testing.assert_array_equal(a, b)
        assert not np.array_equal(a, c)


# --- torque recordings ---------------------------------------------------------------------------


def test_track_records_the_closed_loop_motion_at_the_given_rate():
    # T = duration * rate + 1 samples at t_k = k / rate. The motion is simulated in closed loop
    # (PD + gravity compensation): q is the simulated one (no sensor noise asked for), not the
    # commanded eq. (33), with a tracking error of a few mrad (measured 5.5 mrad at 250 Hz).
    # tau_J with link_friction = 0 is what the sensor between gear and link sees: the motor torque
    # minus what the rotors (Ia qdd) and the friction take, from the commanded torque and the
    # plant's state equation solved in C++ (1e-12 relative), never the full robot's rnea.
    robot = dynid.models.kuka_lwr4()
    controller = VirtualController(robot, seed=9)
    record = controller.track(lambda t: paper_validation_trajectory(t, robot.n), 2.0, 250.0)
    assert record.t.shape == (501,) and record.q.shape == (501, 7) and record.tau.shape == (501, 7)
    np.testing.assert_allclose(record.t, np.arange(501) / 250.0, rtol=0, atol=1e-15)
    q_d, _, _ = paper_validation_trajectory(record.t, robot.n)
    np.testing.assert_allclose(record.q_desired, q_d, rtol=0, atol=1e-15)
    motion = record.motion
    np.testing.assert_array_equal(record.q, motion.q)
    tracking = np.abs(motion.q - q_d).max()
    assert 1e-4 < tracking < 0.02
    link_side = motion.tau - robot.Ia * motion.qdd - plant_friction(robot, motion.qd, COULOMB_BAND)
    np.testing.assert_allclose(record.tau, link_side, rtol=0, atol=1e-12 * np.abs(link_side).max())
    with_drives = robot.rnea(motion.q, motion.qd, motion.qdd)
    assert np.abs(with_drives - record.tau).max() > 0.1  # Ia, Fv, Fs would show


def test_link_friction_appears_in_tau_j():
    # tau_J(rho) - tau_J(0) = rho (Fv qd + Fs tanh(qd / band)), the closed form, per joint
    # (1e-12): the fraction of the friction on the link side of the torque sensor.
    robot = dynid.models.kuka_lwr4()
    rho = np.array([0.1, 0.2, 0.3, 0.25, 0.5, 1.0, 0.0])
    plain = VirtualController(robot).track(paper_validation_trajectory, 1.0, 500.0)
    rubbing = VirtualController(robot, link_friction=rho).track(
        paper_validation_trajectory, 1.0, 500.0
    )
    qd = plain.motion.qd
    expected = rho * (robot.Fv * qd + robot.Fs * np.tanh(qd / COULOMB_BAND))
    np.testing.assert_array_equal(rubbing.motion.q, plain.motion.q)
    np.testing.assert_allclose(rubbing.tau - plain.tau, expected, rtol=0, atol=1e-12)


def test_torque_validation_errors_are_the_link_side_friction():
    # The paper's torque validation (eq. (33), 14 s at 1 kHz, filtered at 1 Hz, differentiated)
    # with the TRUE link model as the prediction. Without link-side friction the filtered tau_J
    # and the prediction agree to 0.02 N m (measured 0.013: filter and differences only, although
    # the robot tracks with up to 6.6 mrad error); with a quarter of the friction on the link
    # side the maximum error of each joint is the friction at the peak speed pi^2 / 14 rad/s,
    # rho (Fv qd_max + Fs): measured ratios 0.98-1.05, bound 0.9-1.15.
    robot = dynid.models.kuka_lwr4()
    body = robot.rigid_body()
    fs = 1000.0

    def smooth(x):
        return lowpass(x, fs, 1.0, order=4, padtype="even", settle=True)

    def tve(record):
        q = smooth(record.q)
        qd = differentiate(q, fs=fs)
        prediction = body.rnea(q, qd, differentiate(qd, fs=fs))
        return np.abs(smooth(record.tau) - prediction).max(axis=0)

    def eq33(t):
        return paper_validation_trajectory(t, 7)

    assert tve(VirtualController(robot).track(eq33, 14.0, fs)).max() < 0.02
    error = tve(VirtualController(robot, link_friction=0.25).track(eq33, 14.0, fs))
    peak = 0.25 * (robot.Fv * np.pi**2 / 14 + robot.Fs)
    assert np.all((0.9 * peak < error) & (error < 1.15 * peak)), error / peak


def test_track_at_a_low_rate_takes_enough_substeps():
    # At 100 Hz the explicit step must resolve the friction band's slope Fs / band near qd = 0
    # (otherwise the velocity chatters around zero: tanh keeps it bounded, not right). The
    # default substeps (20, from the largest eigenvalue of M^-1 D) agree with 4x more to 1e-8
    # rad and 1e-6 N m (measured 2.7e-9, 3.4e-7); one substep is off by 0.6 N m, four by 0.1.
    robot = dynid.models.kuka_lwr4()
    q0 = paper_validation_trajectory(np.zeros(1))[0][0]
    kd = 60.0 * np.diag(robot.mass_matrix(q0))
    assert stable_substeps(robot, q0, 1e-2, COULOMB_BAND, kd) == 20
    assert stable_substeps(robot, q0, 1e-3, COULOMB_BAND, kd) == 2
    controller = VirtualController(robot)
    default = controller.track(paper_validation_trajectory, 2.0, 100.0)
    fine = controller.track(paper_validation_trajectory, 2.0, 100.0, substeps=80)
    coarse = controller.track(paper_validation_trajectory, 2.0, 100.0, substeps=1)
    assert np.abs(fine.motion.q - default.motion.q).max() < 1e-8
    assert np.abs(fine.tau - default.tau).max() < 1e-6
    assert np.abs(coarse.tau - default.tau).max() > 0.1


def test_torque_noise_has_the_given_standard_deviation():
    robot = dynid.models.kuka_lwr4()
    exact = VirtualController(robot, seed=10).track(paper_validation_trajectory, 3.0, 1000.0)
    noisy = VirtualController(robot, torque_noise=0.05, seed=10).track(
        paper_validation_trajectory, 3.0, 1000.0
    )
    error = noisy.tau - exact.tau
    assert np.std(error) == pytest.approx(0.05, rel=0.03)  # 21007 samples: std error ~0.5 %
    assert abs(np.mean(error)) < 5 * 0.05 / np.sqrt(error.size)
    np.testing.assert_array_equal(noisy.q, exact.q)


def test_paper_validation_trajectory_is_eq_33():
    # q(t) = pi/2 cos(pi t / 7), all joints, T = 14 s: closed form (1e-14), start and end at
    # q = pi/2 at rest, q(7) = -pi/2; qd, qdd against central differences (h = 1e-5, 1e-8).
    t = np.linspace(0.0, 14.0, 57)
    q, qd, qdd = paper_validation_trajectory(t, n=7)
    assert q.shape == qd.shape == qdd.shape == (57, 7)
    np.testing.assert_allclose(
        q, np.pi / 2 * np.cos(np.pi * t / 7)[:, None] * np.ones(7), rtol=0, atol=1e-14
    )
    np.testing.assert_allclose(q[[0, -1]], np.pi / 2, rtol=0, atol=1e-14)
    np.testing.assert_allclose(qd[[0, -1]], 0.0, rtol=0, atol=1e-14)
    np.testing.assert_allclose(q[28], -np.pi / 2, rtol=0, atol=1e-14)  # t = 7 s
    h = 1e-5
    q_plus, qd_plus, _ = paper_validation_trajectory(t + h, n=7)
    q_minus, qd_minus, _ = paper_validation_trajectory(t - h, n=7)
    np.testing.assert_allclose(qd, (q_plus - q_minus) / (2 * h), rtol=0, atol=1e-8)
    np.testing.assert_allclose(qdd, (qd_plus - qd_minus) / (2 * h), rtol=0, atol=1e-8)
    assert paper_validation_trajectory(t, n=3)[0].shape == (57, 3)


# --- bad arguments -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["model_noise", "torque_noise", "position_noise"])
@pytest.mark.parametrize("value", [-1e-3, np.nan, np.inf])
def test_bad_noise_levels_raise_value_error_naming_them(name, value):
    with pytest.raises(ValueError, match=rf"^{name}\b"):
        VirtualController(dynid.models.kuka_lwr4(), **{name: value})


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"link_friction": -0.1}, "link_friction"),
        ({"link_friction": 1.5}, "link_friction"),
        ({"link_friction": np.ones(6)}, "link_friction"),
        ({"link_friction": "a"}, "link_friction"),
        ({"encoder_counts": 0}, "encoder_counts"),
        ({"encoder_counts": np.nan}, "encoder_counts"),
        ({"encoder_counts": "many"}, "encoder_counts"),
        ({"encoder_counts": True}, "encoder_counts"),
        ({"encoder_counts": 1e-300}, "encoder_counts"),  # issue 22: q recorded as 0 throughout
    ],
)
def test_bad_sensor_settings_raise_value_error_naming_them(kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name}\b"):
        VirtualController(dynid.models.kuka_lwr4(), **kwargs)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda c: c.random_configurations(0), "count"),
        (lambda c: c.random_configurations(-3), "count"),
        (lambda c: c.track(paper_validation_trajectory, 0.0), "duration"),
        (lambda c: c.track(paper_validation_trajectory, -1.0), "duration"),
        (lambda c: c.track(paper_validation_trajectory, np.nan), "duration"),
        (lambda c: c.track(paper_validation_trajectory, 1.0, 0.0), "rate"),
        (lambda c: c.track(paper_validation_trajectory, 1.0, np.inf), "rate"),
        (lambda c: c.track(paper_validation_trajectory, 1.0, gains=(1.0,)), "gains"),
        (lambda c: c.track(paper_validation_trajectory, 1.0, gains=(np.ones(6), 1.0)), "kp"),
        (lambda c: c.track(paper_validation_trajectory, 1.0, gains=(1.0, -1.0)), "kd"),
        (lambda c: c.track(lambda t: t, 1.0), "trajectory"),
    ],
    ids=[
        "count-0",
        "count-neg",
        "duration-0",
        "duration-neg",
        "duration-nan",
        "rate-0",
        "rate-inf",
        "gains-tuple",
        "kp-shape",
        "kd-negative",
        "trajectory",
    ],
)
def test_bad_arguments_raise_value_error_naming_them(call, name):
    controller = VirtualController(dynid.models.kuka_lwr4())
    with pytest.raises(ValueError, match=rf"^{name}\b"):
        call(controller)
