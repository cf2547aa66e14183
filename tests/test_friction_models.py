"""Asymmetric friction (dynid.friction_models; identify_log(friction="asymmetric")).

Synthetic, exact logs: the torque of a robot without friction (RNEA: rigid body and rotor) plus
a friction torque computed here element by element from its definition,

    tau_f = Fv+ qd + Fs+  (qd > 0),   Fv- qd - Fs-  (qd < 0),   0  (qd = 0),

on the 3-harmonic trajectories of tests/test_log_identification.py. The identification must
return the known coefficients (noise-free: to 1e-9 of the largest base value), the symmetric
model must not fit such data, and symmetric data must give Fv+ = Fv-, Fs+ = Fs-.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result, result_from_dict, result_to_dict, save_result
from dynid.identification.blocks.registry import friction_model
from dynid.identification.friction_models import (
    asymmetric_columns,
    asymmetric_count,
    asymmetric_names,
)
from dynid.identification.log_identification import identify_log, validate_log
from dynid.identification.observer import residual_from_log, robot_from_identification
from dynid.logs import Log, save_log
from dynid.model.model_files import save_model
from test_log_identification import fourier_log

N = 7
FV_POS = np.array([0.9, 1.4, 0.5, 0.7, 0.3, 0.25, 0.1])
FV_NEG = np.array([0.4, 1.9, 0.8, 0.2, 0.45, 0.1, 0.15])
FS_POS = np.array([0.6, 1.1, 0.35, 0.5, 0.2, 0.3, 0.05])
FS_NEG = np.array([0.9, 0.7, 0.55, 0.3, 0.4, 0.1, 0.12])
OFFSET = np.linspace(-0.5, 0.5, N)


def friction_torque(qd: np.ndarray, fv_pos, fv_neg, fs_pos, fs_neg) -> np.ndarray:
    """The asymmetric friction torque by its definition, one element at a time."""
    tau = np.zeros_like(qd)
    for index, v in np.ndenumerate(qd):
        j = index[-1]
        if v > 0:
            tau[index] = fv_pos[j] * v + fs_pos[j]
        elif v < 0:
            tau[index] = fv_neg[j] * v - fs_neg[j]
    return tau


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    """kuka_lwr4() without friction: the link side and rotors of the truth."""
    robot = dynid.models.kuka_lwr4()
    robot.Fv = np.zeros(N)
    robot.Fs = np.zeros(N)
    return robot


def asymmetric_log(robot: dynid.Robot, seed: int, offset: np.ndarray | None = None) -> Log:
    log = fourier_log(robot, seed, offset=offset)
    tau = log.tau + friction_torque(log.qd, FV_POS, FV_NEG, FS_POS, FS_NEG)
    return Log(t=log.t, q=log.q, tau=tau, qd=log.qd, qdd=log.qdd, source=log.source)


def base_values(robot: dynid.Robot) -> np.ndarray:
    return dynid.base_parameters(robot, rotor=True, friction=False).values(robot)


# ----------------------------------------------------------------------------- columns


def test_columns_follow_the_definition():
    """Each column against its definition, element by element; rows of other joints are 0."""
    qd = np.array([[0.5, -0.2, 0.0], [-1.5, 0.0, 2.0]])
    Y = asymmetric_columns(qd, offset=False)
    assert Y.shape == (2, 3, 12)
    for t in range(2):
        for j in range(3):
            v = qd[t, j]
            expected = np.zeros(12)
            expected[j] = v if v > 0 else 0.0
            expected[3 + j] = v if v < 0 else 0.0
            expected[6 + j] = 1.0 if v > 0 else 0.0
            expected[9 + j] = -1.0 if v < 0 else 0.0
            np.testing.assert_array_equal(Y[t, j], expected)
    with_offset = asymmetric_columns(qd, offset=True)
    assert with_offset.shape == (2, 3, 9)
    np.testing.assert_array_equal(with_offset[:, :, :6], Y[:, :, :6])
    for t, j in np.ndindex(2, 3):
        assert with_offset[t, j, 6 + j] == int(qd[t, j] > 0) - int(qd[t, j] < 0)
    assert asymmetric_count(3, False) == 12 and asymmetric_count(3, True) == 9
    names, expressions = asymmetric_names(2, offset=False)
    assert names == ["Fv1+", "Fv2+", "Fv1-", "Fv2-", "Fs1+", "Fs2+", "Fs1-", "Fs2-"]
    assert asymmetric_names(2, offset=True)[0] == ["Fv1+", "Fv2+", "Fv1-", "Fv2-", "Fs1", "Fs2"]
    assert len(expressions) == len(names)


def test_equal_coefficients_are_the_symmetric_friction_of_the_robot(lwr):
    """Fv+ = Fv- = Fv and Fs+ = Fs- = Fs: the columns give Robot.friction (C++), to 1e-15
    relative, and the closed form of this file."""
    robot = dynid.models.kuka_lwr4()
    qd = np.random.default_rng(0).normal(size=(50, N))
    qd[3, 2] = 0.0
    x = np.concatenate([robot.Fv, robot.Fv, robot.Fs, robot.Fs])
    got = asymmetric_columns(qd, offset=False) @ x
    reference = robot.friction(qd)
    assert np.max(np.abs(got - reference)) <= 1e-15 * np.abs(reference).max()
    closed = friction_torque(qd, robot.Fv, robot.Fv, robot.Fs, robot.Fs)
    assert np.max(np.abs(got - closed)) <= 1e-15 * np.abs(closed).max()


def test_friction_argument():
    assert [friction_model(v) for v in (False, True, np.bool_(True))] == [
        "none",
        "symmetric",
        "symmetric",
    ]
    assert friction_model("asymmetric") == "asymmetric"
    for bad in ("yes", 1, None, "Asymmetric"):
        with pytest.raises(ValueError, match="friction: expected True, False or one of"):
            friction_model(bad)


def test_bad_friction_argument_of_identify_log(lwr):
    with pytest.raises(ValueError, match="friction: expected True, False or one of"):
        identify_log(fourier_log(lwr, 1, seconds=1.0), lwr, friction="viscous")


def test_asymmetric_friction_is_refused_for_coupled_drives(lwr):
    """Per-joint direction-dependent friction has no meaning when the motors are coupled
    (robot.transmission): a ValueError naming friction, which points to the symmetric model."""
    coupled = lwr.copy()
    T = np.eye(7)
    T[6, 5] = -0.15
    coupled.transmission = T
    with pytest.raises(ValueError, match=r"^friction: the asymmetric model .* coupled"):
        identify_log(fourier_log(lwr, 1, seconds=1.0), coupled, friction="asymmetric")


# ----------------------------------------------------------------------------- recovery


def test_asymmetric_friction_is_recovered_and_the_symmetric_model_cannot_fit_it(lwr):
    """Noise-free: base values and Fv+, Fv-, Fs+, Fs- to 1e-9 of the largest base value (exact
    arithmetic; OLS), training residual below 1e-9 of the torques; the prediction Y theta on
    another log equals its torque to 1e-9. The symmetric model (+ offsets, which make the
    Coulomb part asymmetric) leaves a relative residual above 5e-4 on every joint (1e-3 to 7 %;
    the gravity-loaded joints 2 and 4 have the largest torques), on training and validation:
    the viscous asymmetry has no symmetric counterpart."""
    log = asymmetric_log(lwr, 1)
    result = identify_log(log, lwr, rotor=True, friction="asymmetric", method="ols")
    assert result.friction_model == "asymmetric" and not result.friction
    assert result.names[result.count :] == asymmetric_names(N, offset=False)[0]
    expected = base_values(lwr)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(result.theta[: result.count], expected, rtol=0, atol=1e-9 * scale)
    truth = np.concatenate([FV_POS, FV_NEG, FS_POS, FS_NEG])
    np.testing.assert_allclose(result.theta[result.count :], truth, rtol=0, atol=1e-9 * scale)
    assert np.all(result.training["metrics"]["relative_rms"] < 1e-9)
    other = asymmetric_log(lwr, 4)
    predicted = result.predict(other)
    assert np.max(np.abs(predicted - other.tau)) <= 1e-9 * np.abs(other.tau).max()
    np.testing.assert_array_equal(
        result.regressor(other.q, other.qd, other.qdd) @ result.theta, predicted
    )

    symmetric = identify_log(log, lwr, rotor=True, friction=True, offset=True, method="ols")
    assert np.all(symmetric.training["metrics"]["relative_rms"] > 5e-4)
    assert np.all(validate_log(symmetric, other)["relative_rms"] > 5e-4)


def test_symmetric_friction_gives_equal_coefficients(lwr):
    """Data of the robot's own symmetric friction: Fv+ = Fv- = Fv and Fs+ = Fs- = Fs to 1e-9
    of the largest base value."""
    truth = dynid.models.kuka_lwr4()  # Fv, Fs > 0
    result = identify_log(fourier_log(truth, 2), lwr, rotor=True, friction="asymmetric")
    scale = np.abs(base_values(lwr)).max()
    fv_pos, fv_neg, fs_pos, fs_neg = result.theta[result.count :].reshape(4, N)
    for got, expected in ((fv_pos, truth.Fv), (fv_neg, truth.Fv)):
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * scale)
    for got, expected in ((fs_pos, truth.Fs), (fs_neg, truth.Fs)):
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * scale)


def test_with_offsets_the_offset_holds_the_coulomb_asymmetry(lwr):
    """friction="asymmetric", offset=True: columns Fv+, Fv-, Fs, off (Fs+, Fs- and the offset
    are the same columns on moving samples). Closed form: Fs = (Fs+ + Fs-) / 2 and
    off = offset + (Fs+ - Fs-) / 2, to 1e-9 of the largest base value."""
    log = asymmetric_log(lwr, 1, offset=OFFSET)
    result = identify_log(log, lwr, rotor=True, friction="asymmetric", offset=True, method="ols")
    assert result.names[result.count + 2 * N : result.count + 3 * N] == [
        f"Fs{j}" for j in range(1, N + 1)
    ]
    scale = np.abs(base_values(lwr)).max()
    truth = np.concatenate([FV_POS, FV_NEG, (FS_POS + FS_NEG) / 2])
    extra = result.theta[result.count :]
    np.testing.assert_allclose(extra[: 3 * N], truth, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(
        extra[3 * N :], OFFSET + (FS_POS - FS_NEG) / 2, rtol=0, atol=1e-9 * scale
    )
    np.testing.assert_array_equal(result.offsets, extra[3 * N :])
    other = asymmetric_log(lwr, 4, offset=OFFSET)
    assert np.max(np.abs(result.predict(other) - other.tau)) <= 1e-9 * np.abs(other.tau).max()


def test_asymmetric_friction_and_position_torque_are_told_apart_on_rich_motion(lwr):
    """With a one-harmonic motion per joint |qd_j| is a function of q_j (docs/real_data.md),
    so a viscous asymmetry can pass for a position torque; on the 3-harmonic logs both are
    recovered together (noise-free, OLS): Fv+, Fv-, Fs, offsets and ks, kc to 1e-9 of the
    largest base value. (Joint 2 has no position torque: there sin q2, cos q2 are gravity
    columns, test_position_torque.py.)"""
    ks, kc = np.linspace(0.3, -0.3, N), np.linspace(-0.2, 0.25, N)
    ks[1] = kc[1] = 0.0
    log = asymmetric_log(lwr, 1, offset=OFFSET)
    tau = log.tau + ks * np.sin(log.q) + kc * np.cos(log.q)
    result = identify_log(
        Log(t=log.t, q=log.q, tau=tau, qd=log.qd, qdd=log.qdd),
        lwr,
        rotor=True,
        friction="asymmetric",
        offset=True,
        position_torque=True,
        method="ols",
    )
    joints = list(result.position_joints)
    assert joints == [0, 2, 3, 4, 5, 6]
    position = np.column_stack([ks[joints], kc[joints]]).reshape(-1)
    halves = [FV_POS, FV_NEG, (FS_POS + FS_NEG) / 2, OFFSET + (FS_POS - FS_NEG) / 2]
    truth = np.concatenate([*halves, position])
    scale = np.abs(base_values(lwr)).max()
    np.testing.assert_allclose(result.theta[result.count :], truth, rtol=0, atol=1e-9 * scale)


def test_without_backward_motion_the_fit_names_the_unexcited_coefficients():
    arm = dynid.models.planar_2r()
    t = np.arange(0.0, 5.0, 0.01)
    q = np.column_stack([0.5 * t + 0.1 * np.sin(3 * t), 0.2 * np.sin(2 * t)])
    qd = np.column_stack([0.5 + 0.3 * np.cos(3 * t), 0.4 * np.cos(2 * t)])
    qdd = np.column_stack([-0.9 * np.sin(3 * t), -0.8 * np.sin(2 * t)])
    log = Log(t=t, q=q, tau=arm.rnea(q, qd, qdd), qd=qd, qdd=qdd)
    with pytest.raises(ValueError, match="least excited: Fv1-, Fs1-"):
        identify_log(log, arm, friction="asymmetric")


# ----------------------------------------------------------------------------- physical


def test_physical_fit_recovers_asymmetric_friction(lwr):
    """The physically consistent fit (no prior; the truth is feasible, its margin 1e-6 the only
    bias) recovers Fv+, Fv-, Fs+, Fs- and the offsets to 1e-4 of the largest base value; its
    robot carries no friction (the asymmetric coefficients are columns of theta), so
    rnea + extra_torque is the prediction, to 1e-9 of the torques."""
    log = asymmetric_log(lwr, 1)
    result = identify_log(log, lwr, rotor=True, friction="asymmetric", physical=True)
    assert result.physical is not None and result.physical["status"] == "optimal"
    scale = np.abs(base_values(lwr)).max()
    truth = np.concatenate([FV_POS, FV_NEG, FS_POS, FS_NEG])
    np.testing.assert_allclose(result.theta[result.count :], truth, rtol=0, atol=1e-4 * scale)
    assert np.all(result.robot.Fv == 0) and np.all(result.robot.Fs == 0)
    other = asymmetric_log(lwr, 4)
    predicted = result.predict(other)
    assert np.max(np.abs(predicted - other.tau)) <= 1e-4 * np.abs(other.tau).max()
    rebuilt = result.robot.rnea(other.q, other.qd, other.qdd) + result.extra_torque(
        other.q, other.qd
    )
    assert np.max(np.abs(rebuilt - predicted)) <= 1e-9 * np.abs(other.tau).max()


def test_physical_fit_keeps_the_friction_coefficients_non_negative(lwr):
    """Data whose "friction" of joint 2 is negative in the backward direction (Fv2- = -0.6, a
    torque that feeds energy in) and of joint 5 forwards (Fs5+ = -0.3): least squares returns
    these values (to 1e-9), the physical fit puts them on their bound 0 (to the solver's
    accuracy, 1e-4) and no coefficient below 0 (>= -1e-12: the solver's excursions are
    clipped)."""
    fv_neg, fs_pos = FV_NEG.copy(), FS_POS.copy()
    fv_neg[1], fs_pos[4] = -0.6, -0.3
    base = fourier_log(lwr, 1)
    tau = base.tau + friction_torque(base.qd, FV_POS, fv_neg, fs_pos, FS_NEG)
    log = Log(t=base.t, q=base.q, tau=tau, qd=base.qd, qdd=base.qdd)
    scale = np.abs(base_values(lwr)).max()
    ls = identify_log(log, lwr, rotor=True, friction="asymmetric", method="ols")
    assert abs(ls.theta[ls.count + N + 1] + 0.6) <= 1e-9 * scale
    assert abs(ls.theta[ls.count + 2 * N + 4] + 0.3) <= 1e-9 * scale
    fit = identify_log(log, lwr, rotor=True, friction="asymmetric", physical=True)
    coefficients = fit.theta[fit.count :]
    assert np.all(coefficients >= -1e-12)
    assert coefficients[N + 1] <= 1e-4 and coefficients[2 * N + 4] <= 1e-4


def test_physical_fit_with_offsets_leaves_the_offsets_free(lwr):
    """friction="asymmetric", offset=True, physical: Fv+, Fv-, Fs >= 0, the offsets (of either
    sign) recovered with the Coulomb asymmetry, to 1e-4 of the largest base value."""
    log = asymmetric_log(lwr, 1, offset=OFFSET)
    result = identify_log(log, lwr, rotor=True, friction="asymmetric", offset=True, physical=True)
    scale = np.abs(base_values(lwr)).max()
    np.testing.assert_allclose(
        result.offsets, OFFSET + (FS_POS - FS_NEG) / 2, rtol=0, atol=1e-4 * scale
    )
    assert np.all(result.theta[result.count : result.count + 3 * N] >= 0)
    assert np.any(result.offsets < 0)


# ----------------------------------------------------------------------------- files, uses


def test_save_and_load_keep_the_asymmetric_friction(lwr, tmp_path):
    """Round trip: same names, coefficients, predictions and summary; written as format
    version 3, a symmetric result still as version 2 (older dynid reads it) with
    friction_model "symmetric"; a file without friction_model (older dynid) loads by its
    friction flag; a friction_model that contradicts it is refused."""
    result = identify_log(
        asymmetric_log(lwr, 1, offset=OFFSET), lwr, rotor=True, friction="asymmetric", offset=True
    )
    path = save_result(result, tmp_path / "out", plots=False)
    data = json.loads(path.read_text())
    assert data["version"] == 3 and data["options"]["friction_model"] == "asymmetric"
    assert data["options"]["friction"] is False
    loaded = load_result(path)
    assert loaded.friction_model == "asymmetric" and loaded.names == result.names
    np.testing.assert_array_equal(loaded.theta, result.theta)
    other = asymmetric_log(lwr, 4, offset=OFFSET)
    np.testing.assert_array_equal(loaded.predict(other), result.predict(other))
    assert loaded.summary() == result.summary() and "asymmetric friction" in result.summary()

    symmetric = identify_log(fourier_log(lwr, 1, seconds=2.0), lwr, friction=True)
    data = result_to_dict(symmetric)
    assert data["version"] == 2 and data["options"]["friction_model"] == "symmetric"
    del data["options"]["friction_model"]
    assert result_from_dict(data).friction_model == "symmetric"
    data["options"]["friction_model"] = "asymmetric"
    with pytest.raises(ValueError, match=r"options\.friction_model: expected"):
        result_from_dict(data)


def test_momentum_observer_takes_the_asymmetric_friction_off(lwr):
    """The observer's robot (base values at the independent columns) plus ``extra_torque``
    (asymmetric friction, offsets, position torque) is the identified prediction, to 1e-9 of
    the torques; its residual on the exact model's own data equals, to 1e-9 of the torques, the
    residual of the true robot run on the torques minus the true friction, offsets and position
    torque (computed here by their definition): both are the observer's discretisation error
    only."""
    log = asymmetric_log(lwr, 1, offset=OFFSET)
    position = 0.2 * np.sin(log.q) - 0.1 * np.cos(log.q)
    position[:, 1] = 0.0  # joint 2: gravity columns (test_position_torque.py)
    log = Log(t=log.t, q=log.q, tau=log.tau + position, qd=log.qd, qdd=log.qdd)
    result = identify_log(
        log, lwr, rotor=True, friction="asymmetric", offset=True, position_torque=True
    )
    robot, offsets = robot_from_identification(result)
    np.testing.assert_allclose(offsets, OFFSET + (FS_POS - FS_NEG) / 2, rtol=0, atol=1e-9)
    predicted = result.predict(log)
    rebuilt = robot.rnea(log.q, log.qd, log.qdd) + result.extra_torque(log.q, log.qd)
    assert np.max(np.abs(rebuilt - predicted)) <= 1e-9 * np.abs(log.tau).max()
    exact = residual_from_log(result, log, 20.0)
    friction = friction_torque(log.qd, FV_POS, FV_NEG, FS_POS, FS_NEG)
    tau = log.tau - friction - OFFSET - position
    reference = residual_from_log(lwr, Log(t=log.t, q=log.q, tau=tau, qd=log.qd), 20.0)
    assert np.max(np.abs(exact.r - reference.r)) <= 1e-9 * np.abs(log.tau).max()
    assert np.max(np.abs(reference.r)) > 1e-5  # a discretisation error to agree on


def test_cli_identify_and_validate_with_asymmetric_friction(lwr, tmp_path, capsys):
    """End to end: `dynid identify --asymmetric-friction --offset` writes the coefficients
    (Fv1+ ... and the offsets) that identify_log finds, `dynid validate` predicts another log
    exactly (relative RMS < 1e-9); --friction with --asymmetric-friction, and a log without
    backward motion, are one line on stderr and exit status 2."""
    model = tmp_path / "lwr.json"
    save_model(lwr, model)
    train, check = asymmetric_log(lwr, 1, offset=OFFSET), asymmetric_log(lwr, 4, offset=OFFSET)
    save_log(train, tmp_path / "train.npz")
    save_log(check, tmp_path / "check.npz")
    out = tmp_path / "ident"
    argv = ["identify", str(tmp_path / "train.npz"), "--model", str(model), "--rotor"]
    argv += ["--asymmetric-friction", "--offset", "--method", "ols", "--output", str(out)]
    assert main(argv) == 0
    assert "Fv1+" in capsys.readouterr().out
    loaded = load_result(out)
    direct = identify_log(train, lwr, rotor=True, friction="asymmetric", offset=True, method="ols")
    assert loaded.names == direct.names
    np.testing.assert_allclose(loaded.theta, direct.theta, rtol=1e-12, atol=1e-12)
    validation = tmp_path / "validation"
    argv = ["validate", str(out), str(tmp_path / "check.npz"), "--output", str(validation)]
    assert main(argv) == 0
    report = json.loads((validation / "validation.json").read_text())
    assert max(report["metrics"]["relative_rms"]) < 1e-9

    argv = ["identify", str(tmp_path / "train.npz"), "--model", str(model), "--friction"]
    argv += ["--asymmetric-friction", "--output", str(tmp_path / "both")]
    capsys.readouterr()
    assert main(argv) == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0 and "choose one friction model" in error

    forward = Log(t=train.t, q=train.q, tau=train.tau, qd=np.abs(train.qd), qdd=train.qdd)
    save_log(forward, tmp_path / "forward.npz")
    argv = ["identify", str(tmp_path / "forward.npz"), "--model", str(model)]
    argv += ["--asymmetric-friction", "--output", str(tmp_path / "bad")]
    capsys.readouterr()
    assert main(argv) == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0 and "14 unexcited direction(s)" in error  # Fv-, Fs- x 7
    assert re.search(r"least excited: (F[vs]\d-, )+F[vs]\d- \(", error)


def test_nonnegative_extra_argument_is_checked(lwr):
    """physical_least_squares(nonnegative_extra=...): None or one boolean per extra column."""
    log = fourier_log(lwr, 1, seconds=0.5)
    Y = lwr.regressor(log.q, log.qd, log.qdd)
    Y = np.concatenate([Y, np.ones((*Y.shape[:2], 2))], axis=2)
    for bad in ([True], [1, 0], np.array([True, False, True]), "yes"):
        with pytest.raises(ValueError, match=r"^nonnegative_extra: expected None or 2 booleans"):
            dynid.physical_least_squares(lwr, Y, log.tau, extra_columns=2, nonnegative_extra=bad)
