"""The laws' one home in the C++ core (issue 19, item 3; cpp/bindings/laws.cpp): the drive
friction with the simulators' smoothing and split by term, the elastic joints' motor equation and
the world frames of all links, each against an independent computation written here (the law's
closed form, finite differences, the DH product of tests/reference_model.py)."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from conftest import random_arm
from coupled_robots import coupled_puma
from dynid import _core
from reference_model import kinematics

BAND = 0.05


def reference_friction(robot: dynid.Robot, qd: np.ndarray, band: float) -> np.ndarray:
    """T^T (Fv w + Fs s(w)), w = T qd, s = tanh(. / band) or sign: the law written out here."""
    T = np.asarray(robot.transmission)
    w = qd @ T.T
    s = np.tanh(w / band) if band > 0 else np.sign(w)
    return (np.asarray(robot.Fv) * w + np.asarray(robot.Fs) * s) @ T


def drive_robot(coupled: bool) -> dynid.Robot:
    robot = coupled_puma() if coupled else dynid.models.puma560()
    rng = np.random.default_rng(3)
    robot.Fv = rng.uniform(0.5, 3.0, 6)
    robot.Fs = rng.uniform(0.2, 2.0, 6)
    return robot


@pytest.mark.parametrize("coupled", [False, True])
@pytest.mark.parametrize("band", [0.0, BAND])
def test_friction_is_the_law(coupled: bool, band: float) -> None:
    """_friction against the closed form on 50 samples with exact zeros among them, 1e-12 N m."""
    robot = drive_robot(coupled)
    qd = np.random.default_rng(4).uniform(-0.2, 0.2, (50, 6))
    qd[::7, 2] = 0.0
    expected = reference_friction(robot, qd, band)
    np.testing.assert_allclose(_core._friction(robot, qd, band), expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(_core._friction(robot, qd[3], band), expected[3], rtol=0, atol=1e-12)


@pytest.mark.parametrize("coupled", [False, True])
def test_zero_band_is_the_robots_friction(coupled: bool) -> None:
    """Band 0 is the sign law of docs/conventions.md, "Drive terms and the torque model",
    Robot.friction, bit for bit."""
    robot = drive_robot(coupled)
    qd = np.random.default_rng(5).normal(size=(20, 6))
    qd[0] = 0.0
    np.testing.assert_array_equal(_core._friction(robot, qd, 0.0), robot.friction(qd))


@pytest.mark.parametrize("coupled", [False, True])
def test_smoothed_friction_slope_at_rest(coupled: bool) -> None:
    """d friction / d qd at qd = 0 is T^T diag(Fv + Fs / band) T (tanh'(0) = 1), by central
    differences with h = 1e-6 band (truncation ~ (h / band)^2 Fs / band: 1e-9 relative)."""
    robot = drive_robot(coupled)
    T = np.asarray(robot.transmission)
    expected = T.T @ np.diag(np.asarray(robot.Fv) + np.asarray(robot.Fs) / BAND) @ T
    h = 1e-6 * BAND
    steps = h * np.eye(6)
    slope = (_core._friction(robot, steps, BAND) - _core._friction(robot, -steps, BAND)) / (2 * h)
    np.testing.assert_allclose(slope.T, expected, rtol=0, atol=1e-7 * np.abs(expected).max())


@pytest.mark.parametrize("coupled", [False, True])
@pytest.mark.parametrize("band", [0.0, BAND])
def test_friction_terms_are_the_viscous_and_coulomb_parts(coupled: bool, band: float) -> None:
    """viscous = T^T diag(Fv) T qd, coulomb = T^T (Fs s(T qd)) (closed forms, 1e-12), and their
    sum is _friction (1e-12)."""
    robot = drive_robot(coupled)
    T = np.asarray(robot.transmission)
    qd = np.random.default_rng(6).uniform(-0.3, 0.3, (40, 6))
    qd[5] = 0.0
    terms = _core._friction_terms(robot, qd, band)
    assert terms.shape == (40, 2, 6)
    viscous = qd @ (T.T @ np.diag(robot.Fv) @ T).T
    w = qd @ T.T
    coulomb = (np.asarray(robot.Fs) * (np.tanh(w / band) if band else np.sign(w))) @ T
    np.testing.assert_allclose(terms[:, 0], viscous, rtol=0, atol=1e-12)
    np.testing.assert_allclose(terms[:, 1], coulomb, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        terms.sum(axis=1), _core._friction(robot, qd, band), rtol=0, atol=1e-12
    )
    assert _core._friction_terms(robot, qd[0], band).shape == (2, 6)


def test_friction_bad_arguments_name_them() -> None:
    robot = drive_robot(False)
    for band in (-1.0, np.inf, np.nan):
        with pytest.raises(ValueError, match=r"^coulomb_band"):
            _core._friction(robot, np.zeros(6), band)
        with pytest.raises(ValueError, match=r"^coulomb_band"):
            _core._friction_terms(robot, np.zeros(6), band)
    with pytest.raises(ValueError, match=r"^qd: expected shape \(6,\)"):
        _core._friction(robot, np.zeros(5), 0.0)
    with pytest.raises(ValueError, match=r"^qd"):
        _core._friction(robot, [np.nan] * 6, 0.0)


# ---- the elastic joints' motor equation (paper eq. (2)) ----------------------------------------
def motor_drives(n: int = 3):
    rng = np.random.default_rng(7)
    return (
        rng.uniform(100.0, 1000.0, n),  # K
        rng.uniform(0.1, 2.0, n),  # B
        rng.uniform(0.0, 3.0, n),  # Fv_m
        rng.uniform(0.0, 2.0, n),  # Fs_m
    )


@pytest.mark.parametrize("band", [0.0, BAND])
def test_motor_equation_is_the_closed_form(band: float) -> None:
    """tau_F = Fv_m w + Fs_m s(w); thetadd = (tau - tau_J - tau_F) / B; tau = B thetadd + tau_J +
    tau_F, each against the formula written here at 1e-12, on samples with exact zeros."""
    _, B, Fv, Fs = drives = motor_drives()
    rng = np.random.default_rng(8)
    thetad, thetadd, tau, tau_J = (
        rng.uniform(-0.2, 0.2, (4, 30, 3)) * np.array([1.0, 10.0, 50.0, 50.0])[:, None, None]
    )
    thetad[::4, 1] = 0.0
    s = np.tanh(thetad / band) if band else np.sign(thetad)
    tau_F = Fv * thetad + Fs * s
    np.testing.assert_allclose(
        _core._motor_friction(*drives, thetad, band), tau_F, rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(
        _core._motor_acceleration(*drives, thetad, tau, tau_J, band),
        (tau - tau_J - tau_F) / B,
        rtol=0,
        atol=1e-12,
    )
    np.testing.assert_allclose(
        _core._motor_torque(*drives, thetad, thetadd, tau_J, band),
        B * thetadd + tau_J + tau_F,
        rtol=0,
        atol=1e-12,
    )
    one = _core._motor_torque(*drives, thetad[0], thetadd[0], tau_J[0], band)
    assert one.shape == (3,)


def test_motor_torque_and_acceleration_invert_each_other() -> None:
    """The motor acceleration of the motor torque for thetadd is thetadd (1e-12)."""
    drives = motor_drives()
    rng = np.random.default_rng(9)
    thetad, thetadd, tau_J = rng.normal(size=(3, 25, 3))
    tau = _core._motor_torque(*drives, thetad, thetadd, tau_J, BAND)
    back = _core._motor_acceleration(*drives, thetad, tau, tau_J, BAND)
    np.testing.assert_allclose(back, thetadd, rtol=0, atol=1e-12)


def test_elastic_robot_uses_the_motor_equation() -> None:
    """ElasticRobot.motor_friction and forward_dynamics' thetadd are the core's motor equation
    with the exact sign (band 0): the formula here at 1e-12."""
    K, B, Fv, Fs = motor_drives(2)
    elastic = dynid.ElasticRobot(dynid.models.planar_2r(), K, B, Fv, Fs)
    rng = np.random.default_rng(10)
    q, qd, theta, thetad, tau = rng.normal(size=(5, 12, 2))
    thetad[3] = 0.0
    tau_F = Fv * thetad + Fs * np.sign(thetad)
    np.testing.assert_allclose(elastic.motor_friction(thetad), tau_F, rtol=0, atol=1e-12)
    _, thetadd = elastic.forward_dynamics(q, qd, theta, thetad, tau)
    expected = (tau - K * (theta - q) - tau_F) / B
    np.testing.assert_allclose(thetadd, expected, rtol=0, atol=1e-12)


def test_motor_equation_bad_arguments_name_them() -> None:
    K, B, Fv, Fs = motor_drives()
    z = np.zeros(3)
    with pytest.raises(ValueError, match=r"^motor_inertia: expected finite values > 0"):
        _core._motor_friction(K, [1.0, 0.0, 1.0], Fv, Fs, z, 0.0)
    with pytest.raises(ValueError, match=r"^motor_coulomb: expected finite values >= 0"):
        _core._motor_friction(K, B, Fv, [-1.0, 0.0, 0.0], z, 0.0)
    with pytest.raises(ValueError, match=r"^motor_viscous"):
        _core._motor_friction(K, B, [1.0, 2.0], Fs, z, 0.0)
    with pytest.raises(ValueError, match=r"^stiffness"):
        _core._motor_friction([[1.0]], B, Fv, Fs, z, 0.0)
    with pytest.raises(ValueError, match=r"^coulomb_band"):
        _core._motor_torque(K, B, Fv, Fs, z, z, z, -1.0)
    with pytest.raises(ValueError, match=r"^tau_J: expected shape \(4, 3\) like thetad"):
        _core._motor_acceleration(K, B, Fv, Fs, np.zeros((4, 3)), np.zeros((4, 3)), z, 0.0)


# ---- link frames --------------------------------------------------------------------------------
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_link_frames_are_the_dh_products(convention: str) -> None:
    """Frame i = base A_1 ... A_i (tests/reference_model.py's DH matrices, both conventions,
    revolute and prismatic joints, a random base; the tool excluded), 1e-12."""
    rng = np.random.default_rng(11)
    arm = random_arm(rng, 6, convention, joint_types="RPRRPR")
    robot = arm.robot()
    q = rng.uniform(-2.0, 2.0, (8, 6))
    frames = _core._link_frames(robot, q)
    assert frames.shape == (8, 6, 4, 4)
    for t in range(len(q)):
        expected = np.array(kinematics(arm, q[t]).frames)
        np.testing.assert_allclose(frames[t], expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(_core._link_frames(robot, q[0]), frames[0], rtol=0, atol=0)


def test_link_frames_bad_arguments_name_them() -> None:
    robot = dynid.models.puma560()
    with pytest.raises(ValueError, match=r"^q: expected shape \(6,\)"):
        _core._link_frames(robot, np.zeros(4))
    with pytest.raises(ValueError, match=r"^q"):
        _core._link_frames(robot, np.full(6, np.inf))


# ---- the asymmetric friction model ---------------------------------------------------------------
@pytest.mark.parametrize("offset", [False, True])
def test_asymmetric_friction_columns_give_the_law(offset: bool) -> None:
    """Columns times coefficients is Fv+ max(qd, 0) + Fv- min(qd, 0) + Fs+ [qd > 0] - Fs- [qd < 0]
    per joint (with offset: Fs sign(qd) for the Coulomb pair), written here, 1e-12."""
    rng = np.random.default_rng(12)
    qd = rng.uniform(-1.0, 1.0, (30, 4))
    qd[::5, 0] = 0.0
    Fv_pos, Fv_neg, Fs_pos, Fs_neg = rng.uniform(0.1, 2.0, (4, 4))
    Y = _core._asymmetric_friction_columns(qd, offset)
    viscous = Fv_pos * np.maximum(qd, 0) + Fv_neg * np.minimum(qd, 0)
    if offset:
        coefficients = np.concatenate([Fv_pos, Fv_neg, Fs_pos])
        expected = viscous + Fs_pos * np.sign(qd)
    else:
        coefficients = np.concatenate([Fv_pos, Fv_neg, Fs_pos, Fs_neg])
        expected = viscous + Fs_pos * (qd > 0) - Fs_neg * (qd < 0)
    assert Y.shape == (30, 4, (3 if offset else 4) * 4)
    np.testing.assert_allclose(Y @ coefficients, expected, rtol=0, atol=1e-12)
    assert np.count_nonzero(Y[:, 0, :]) <= 3 * 30  # row j has entries in joint j's columns only
    for j in range(4):
        others = [c for c in range(Y.shape[2]) if c % 4 != j]
        assert not Y[:, j, others].any()


def test_asymmetric_friction_columns_bad_arguments_name_them() -> None:
    with pytest.raises(ValueError, match=r"^qd: expected shape \(T, n\)"):
        _core._asymmetric_friction_columns(np.zeros(3), False)
    with pytest.raises(ValueError, match=r"^offset"):
        _core._asymmetric_friction_columns(np.zeros((2, 3)), "yes")
