"""Motor-side logs (issue 20, item 1): motor angles and torques mapped to the joints through the
model's gear ratios, transmission and joint offsets (dynid.logs.motor_side), logs without a time
vector (sample_time), the Staubli TX40 model file, and `dynid identify --motor-side` end to end.

References: the TX40 README's recipe written out with NumPy (R with R65 = N6, then q2 - pi/2 and
q3 + pi/2, tau = R^T tau_m), the same in closed form per joint, and a simulated arm whose
parameters are known.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result
from dynid.logs import Log, load_log
from dynid.logs.motor_side import motor_to_joint
from dynid.model.model_files import load_model, save_model
from test_log_identification import fourier_log

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
TX40_MODEL = EXAMPLES / "staubli_tx40.json"
TX40_URDF = EXAMPLES / "staubli_tx40.urdf"
#: The TX40 README: N = (32, 32, 45, -48, 45, 32), motor 6 turns with q5 + q6 (R65 = N6).
TX40_N = np.array([32.0, 32.0, 45.0, -48.0, 45.0, 32.0])


def _readme_recipe(theta: np.ndarray, tau_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The README's steps as written: q = R^-1 theta, R = diag(N) with R65 = N6; then q2 - pi/2,
    q3 + pi/2; tau = R^T tau_m."""
    R = np.diag(TX40_N)
    R[5, 4] = TX40_N[5]
    q = np.linalg.inv(R) @ theta.T
    q[1] -= np.pi / 2
    q[2] += np.pi / 2
    return q.T, (R.T @ tau_m.T).T


def _tx40_like() -> dynid.Robot:
    return load_model(TX40_MODEL)


def _random_motor_log(seed: int, n: int = 6, samples: int = 40) -> Log:
    rng = np.random.default_rng(seed)
    return Log(
        t=np.arange(samples) * 2e-4,
        q=rng.uniform(-60.0, 60.0, (samples, n)),
        tau=rng.normal(scale=0.5, size=(samples, n)),
        qd=rng.normal(scale=100.0, size=(samples, n)),
        qdd=rng.normal(scale=1e3, size=(samples, n)),
    )


def test_mapping_is_the_readmes_recipe() -> None:
    motor = _random_motor_log(1)
    joint = motor_to_joint(motor, _tx40_like())
    q, tau = _readme_recipe(motor.q, motor.tau)
    np.testing.assert_allclose(joint.q, q, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(joint.tau, tau, rtol=1e-12, atol=1e-12)
    # Velocities and accelerations: R^-1 without the offsets.
    R = np.diag(TX40_N)
    R[5, 4] = TX40_N[5]
    np.testing.assert_allclose(joint.qd, np.linalg.solve(R, motor.qd.T).T, rtol=1e-12)
    np.testing.assert_allclose(joint.qdd, np.linalg.solve(R, motor.qdd.T).T, rtol=1e-12)
    np.testing.assert_array_equal(joint.t, motor.t)
    assert "motor side mapped to the joints" in joint.notes[-1] and "coupled" in joint.notes[-1]


def test_mapping_in_closed_form_per_joint() -> None:
    """The coupled wrist by hand: q5 = theta5 / N5, q6 = theta6 / N6 - q5; tau5 = N5 tau_m5 +
    N6 tau_m6, tau6 = N6 tau_m6; joints 1-4 theta_j / N_j (minus the offsets)."""
    motor = _random_motor_log(2, samples=5)
    joint = motor_to_joint(motor, _tx40_like())
    th, tm = motor.q, motor.tau
    offsets = np.array([0.0, np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0])
    q = th / TX40_N - offsets
    q[:, 5] = th[:, 5] / TX40_N[5] - th[:, 4] / TX40_N[4]
    tau = tm * TX40_N
    tau[:, 4] = TX40_N[4] * tm[:, 4] + TX40_N[5] * tm[:, 5]
    np.testing.assert_allclose(joint.q, q, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(joint.tau, tau, rtol=1e-12, atol=1e-12)


def test_defaults_leave_a_log_unchanged() -> None:
    """Gear ratios 1, T = I, offsets 0: q and tau as they are (bit for bit)."""
    motor = _random_motor_log(3, n=7)
    joint = motor_to_joint(motor, dynid.models.kuka_lwr4())
    np.testing.assert_array_equal(joint.q, motor.q)
    np.testing.assert_array_equal(joint.tau, motor.tau)


def test_power_is_the_same_on_both_sides() -> None:
    """Virtual work: theta_dot^T tau_m = q_dot^T tau for every sample (any R, offsets)."""
    robot = dynid.models.puma560()
    robot.gear_ratios = [62.6, -107.8, 53.7, 76.0, 71.9, 76.7]
    T = np.eye(6)
    T[4, 3], T[5, 3], T[5, 4] = 0.2, -0.15, 0.3
    robot.transmission = T
    robot.joint_offsets = [0.1, -0.2, 0.3, 0.0, 0.5, -0.6]
    motor = _random_motor_log(4)
    joint = motor_to_joint(motor, robot)
    np.testing.assert_allclose(
        np.sum(joint.qd * joint.tau, axis=1), np.sum(motor.qd * motor.tau, axis=1), rtol=1e-12
    )


def test_bad_input_names_the_argument() -> None:
    robot = _tx40_like()
    with pytest.raises(ValueError, match=r"^log: has 7 motors"):
        motor_to_joint(_random_motor_log(5, n=7), robot)
    with pytest.raises(ValueError, match=r"^log: expected a dynid.Log"):
        motor_to_joint({"q": np.zeros((3, 6))}, robot)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^robot: expected a dynid.Robot"):
        motor_to_joint(_random_motor_log(5), object())  # type: ignore[arg-type]
    for bad, message in (
        ([32.0, 32.0, 0.0, -48.0, 45.0, 32.0], "gear_ratios: joint 3 has a zero gear ratio"),
        ([32.0, 32.0, np.nan, -48.0, 45.0, 32.0], "gear_ratios"),
        ([32.0, 32.0], "gear_ratios"),
    ):
        with pytest.raises(ValueError, match=message):
            robot.gear_ratios = bad
    for bad in ([0.0, np.inf, 0.0, 0.0, 0.0, 0.0], np.zeros(5)):
        with pytest.raises(ValueError, match="joint_offsets"):
            robot.joint_offsets = bad
    np.testing.assert_array_equal(robot.gear_ratios, TX40_N)  # unchanged by the failures


# --------------------------------------------------------------------------- the TX40 model file


def test_tx40_model_file_carries_the_readmes_drive() -> None:
    robot = load_model(TX40_MODEL)
    assert robot.n == 6 and robot.convention == "modified"
    np.testing.assert_array_equal(robot.gear_ratios, TX40_N)
    coupling = np.eye(6)
    coupling[5, 4] = 1.0  # T = I + e6 e5^T
    np.testing.assert_array_equal(robot.transmission, coupling)
    R = np.diag(robot.gear_ratios) @ robot.transmission
    assert R[5, 4] == TX40_N[5]  # R65 = N6
    np.testing.assert_array_equal(robot.joint_offsets, [0, np.pi / 2, -np.pi / 2, 0, 0, 0])
    # Link 6 has a zero inertia in the URDF: read as it is (docs/real_data.md).
    again = dynid.Robot.from_urdf(str(TX40_URDF), check_physical=False, convention="modified")
    np.testing.assert_allclose(again.params, robot.params, rtol=0, atol=1e-15)
    np.testing.assert_allclose(again.dh, robot.dh, rtol=0, atol=1e-15)


def test_tx40_model_file_follows_the_urdf() -> None:
    """Frames and RNEA of the model file against Pinocchio on the URDF (link 6's zero inertia
    and the drive terms aside: the rigid body only)."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(TX40_URDF))
    data = model.createData()
    robot = load_model(TX40_MODEL).rigid_body()
    rng = np.random.default_rng(6)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, (3, 6))
        expected = pin.rnea(model, data, q, qd, qdd)
        np.testing.assert_allclose(robot.rnea(q, qd, qdd), expected, rtol=0, atol=1e-10)


# --------------------------------------------------------------------------- sample time


def test_npz_without_time_vector_reads_its_sample_time(tmp_path) -> None:
    theta = np.arange(18.0).reshape(3, 6)
    np.savez(tmp_path / "m.npz", motor_position=theta, motor_torque=-theta, sample_time=2e-4)
    log = load_log(tmp_path / "m.npz", columns={"q": "motor_position", "tau": "motor_torque"})
    np.testing.assert_array_equal(log.t, [0.0, 2e-4, 4e-4])
    np.testing.assert_array_equal(log.q, theta)
    assert "no time vector" in log.notes[-1]
    np.savez(tmp_path / "d.npz", q=theta, tau=-theta, sample_time=1e-3)  # dynid key names
    np.testing.assert_array_equal(load_log(tmp_path / "d.npz").t, [0.0, 1e-3, 2e-3])


def test_csv_without_time_column_needs_sample_time(tmp_path) -> None:
    path = tmp_path / "m.csv"
    path.write_text("q1,q2,tau1,tau2\n0,1,2,3\n4,5,6,7\n8,9,10,11\n")
    with pytest.raises(ValueError, match="missing column 't'"):
        load_log(path)
    log = load_log(path, sample_time=0.01)
    np.testing.assert_array_equal(log.t, [0.0, 0.01, 0.02])
    np.testing.assert_array_equal(log.tau, [[2, 3], [6, 7], [10, 11]])
    mapped = load_log(path, columns={"q": "q*", "tau": "tau*"}, sample_time=0.01)
    np.testing.assert_array_equal(mapped.q, log.q)


def test_sample_time_errors(tmp_path) -> None:
    np.savez(tmp_path / "m.npz", motor_position=np.zeros((3, 2)), motor_torque=np.zeros((3, 2)))
    columns = {"q": "motor_position", "tau": "motor_torque"}
    with pytest.raises(ValueError, match=r"no time vector.*sample_time"):
        load_log(tmp_path / "m.npz", columns=columns)
    for bad in (0.0, -1e-3, np.nan, "fast"):
        with pytest.raises(ValueError, match=r"^sample_time: expected"):
            load_log(tmp_path / "m.npz", columns=columns, sample_time=bad)  # type: ignore[arg-type]
    np.savez(tmp_path / "t.npz", t=np.arange(3.0), q=np.zeros((3, 2)), tau=np.zeros((3, 2)))
    with pytest.raises(ValueError, match="sample_time: given, but the log has a time vector"):
        load_log(tmp_path / "t.npz", sample_time=0.1)
    np.savez(tmp_path / "k.npz", q=np.zeros((3, 2)), tau=np.zeros((3, 2)), sample_time=-1.0)
    with pytest.raises(ValueError, match="key 'sample_time': expected a positive finite number"):
        load_log(tmp_path / "k.npz")


# --------------------------------------------------------------------------- end to end


def _coupled_arm() -> dynid.Robot:
    """The PUMA 560 with drive terms per motor, a coupled wrist, gear ratios of both signs and
    joint offsets: the parameters the command line must recover."""
    robot = dynid.models.puma560()
    robot.Ia = [1.1, 1.7, 0.9, 0.2, 0.18, 0.15]
    robot.Fv = [4.0, 3.5, 2.0, 0.8, 0.6, 0.5]
    robot.Fs = [3.0, 4.0, 2.5, 0.9, 0.7, 0.4]
    T = np.eye(6)
    T[5, 4] = 1.0
    T[4, 3] = 0.25
    robot.transmission = T
    robot.gear_ratios = [62.6, 107.8, -53.7, 76.0, 71.9, 76.7]
    robot.joint_offsets = [0.0, np.pi / 2, -np.pi / 2, 0.3, 0.0, -0.4]
    return robot


def _save_motor_log(robot: dynid.Robot, seed: int, path: Path) -> None:
    """A simulated joint-side log (exact torques) written as the motors see it, without time."""
    joint = fourier_log(robot, seed, seconds=5.0)
    R = np.diag(robot.gear_ratios) @ robot.transmission
    np.savez(
        path,
        motor_position=(joint.q + robot.joint_offsets) @ R.T,
        motor_velocity=joint.qd @ R.T,
        motor_acceleration=joint.qdd @ R.T,
        motor_torque=np.linalg.solve(R.T, joint.tau.T).T,  # tau = R^T tau_m
        sample_time=0.01,
    )


def test_identify_and_validate_a_motor_side_log(tmp_path, capsys) -> None:
    robot = _coupled_arm()
    save_model(robot, tmp_path / "arm.json")
    _save_motor_log(robot, 1, tmp_path / "train.npz")
    _save_motor_log(robot, 2, tmp_path / "check.npz")
    columns = "q=motor_position,qd=motor_velocity,qdd=motor_acceleration,tau=motor_torque"
    out = tmp_path / "ident"
    argv = ["identify", str(tmp_path / "train.npz"), "--model", str(tmp_path / "arm.json")]
    argv += ["--motor-side", "--columns", columns, "--rotor", "--friction", "--method", "ols"]
    assert main([*argv, "--output", str(out)]) == 0
    printed = capsys.readouterr()
    assert "motor side mapped to the joints" in printed.out
    # Motor angles reach ~200 rad here: no "degrees or encoder counts?" warning for them.
    assert "positions up to" not in printed.err
    expected = dynid.base_parameters(robot, rotor=True, friction=True).values(robot)
    result = load_result(out)
    np.testing.assert_allclose(result.theta, expected, rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(result.robot.gear_ratios, robot.gear_ratios)
    check = tmp_path / "check"
    argv = ["validate", str(out), str(tmp_path / "check.npz"), "--motor-side"]
    assert main([*argv, "--columns", columns, "--output", str(check)]) == 0
    report = json.loads((check / "validation.json").read_text())
    assert max(report["metrics"]["relative_rms"]) < 1e-9
    # Without --motor-side the result's record applies it (as the recorded preparation): the
    # same log read as joint angles would be a poor fit that nothing flags.
    capsys.readouterr()
    assert main([*argv[:3], "--columns", columns, "--output", str(tmp_path / "v2")]) == 0
    assert "note: --motor-side (recorded in the result)" in capsys.readouterr().out
    report = json.loads((tmp_path / "v2" / "validation.json").read_text())
    assert max(report["metrics"]["relative_rms"]) < 1e-9
    # --no-motor-side reads the log as joint angles (here wrongly: a poor fit, as asked)
    argv3 = [*argv[:3], "--no-motor-side", "--columns", columns, "--output", str(tmp_path / "v3")]
    assert main(argv3) == 0
    report = json.loads((tmp_path / "v3" / "validation.json").read_text())
    assert min(report["metrics"]["relative_rms"]) > 0.01


def test_motor_side_errors_exit_2(tmp_path, capsys) -> None:
    robot = _coupled_arm()
    save_model(robot, tmp_path / "arm.json")
    _save_motor_log(robot, 1, tmp_path / "m.npz")
    base = ["identify", str(tmp_path / "m.npz"), "--model", str(tmp_path / "arm.json")]
    base += ["--output", str(tmp_path / "out")]
    assert main([*base, "--motor-side", "--current"]) == 2
    assert "--motor-side: not with --current" in capsys.readouterr().err
    assert main([*base, "--motor-side", "--columns", "q=motor_position,tau=motor_torque",
                 "--model", "kuka_lwr4"]) == 2  # fmt: skip
    assert "log: has 6 motors (columns) but the robot has 7 joints" in capsys.readouterr().err
    assert main([*base, "--columns", "q=motor_position,tau=motor_torque",
                 "--sample-time", "-1"]) == 2  # fmt: skip
    assert "sample_time: expected a positive finite number" in capsys.readouterr().err


def test_heldout_script_scores_the_readmes_samples() -> None:
    """examples/staubli_tx40_heldout.py compares sample 10 k of the held-out rows with row k of
    the decimated target: at the decimated rate as they are, at 5 kHz after decimating x10."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("tx40", EXAMPLES / "staubli_tx40_heldout.py")
    assert spec is not None and spec.loader is not None
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    dt = 2e-4
    t = np.arange(0, 15750, 10) * dt  # held-out rows 29250:45000, every 10th
    predicted = np.arange(t.size, dtype=float)[:, None] * np.ones((1, 6))
    rows, kept = script.scored_prediction(t, predicted, dt)
    np.testing.assert_array_equal(rows, np.arange(2927, 4498))  # samples 29270:44980
    np.testing.assert_array_equal(kept[:, 0], rows - 2925)
    fine = np.sin(np.arange(15750) * dt * 7.0)[:, None] * np.ones((1, 6))
    rows, kept = script.scored_prediction(np.arange(15750) * dt, fine, dt)
    np.testing.assert_array_equal(rows, np.arange(2927, 4498))
    from scipy import signal

    expected = signal.decimate(fine, 10, axis=0, zero_phase=True)[2:1573]
    np.testing.assert_allclose(kept, expected, rtol=0, atol=1e-15)
    measured = np.array([[1.0, 2.0], [-1.0, 2.0]])
    np.testing.assert_allclose(
        script.relative_rms(measured * 1.1, measured), [0.1, 0.1], rtol=1e-12
    )
