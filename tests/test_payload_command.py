"""`dynid payload` and what it rests on: the controller formats (export/payload_out.py) against
hand computations, the long-run covariance (identification/serial_correlation.py) against closed
forms, the joint fit of the unloaded model and the payload (identification/payload_logs.py) on
simulated arms with a known payload, and the command end to end.

The simulated logs: a Fourier trajectory (0.1 Hz, 5 harmonics) sampled at 500 Hz for 20 s,
torques from the inverse dynamics of the arm (with the payload put on by Robot.with_payload,
itself checked in tests/test_payload.py) plus Gaussian sensor noise of a stated level per joint.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.payload_out import (
    franka_endeffector,
    kuka_angles,
    kuka_load_data,
    loaded_model,
    principal_axes,
    urscript,
)
from dynid.identification.payload import PayloadEstimate, _physical
from dynid.identification.payload_logs import estimate_payload_from_logs
from dynid.identification.serial_correlation import (
    bartlett_width,
    correlation_window,
    long_run_covariance,
)
from dynid.logs import Log, save_log
from dynid.model.model_files import load_model

MASS, COM = 2.0, np.array([0.01, -0.02, 0.05])
INERTIA = np.array([[4e-3, 2e-4, -1e-4], [2e-4, 5e-3, 3e-4], [-1e-4, 3e-4, 3e-3]])
#: per-joint torque noise [N m] of the UR5 logs: shoulder and elbow larger than the wrist
UR5_NOISE = np.array([0.3, 0.3, 0.2, 0.05, 0.05, 0.05])
FS = 500.0


def rz(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def ry(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rx(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def box_inertia(mass: float, sides: tuple[float, float, float]) -> np.ndarray:
    """A solid box about its centre, axes along its edges: m/12 (b^2 + c^2), ..."""
    a, b, c = sides
    return mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def estimate_in_tool_frame(mass: float, com: np.ndarray, inertia: np.ndarray) -> PayloadEstimate:
    """A PayloadEstimate holding given values (the formats only read mass, com, inertia)."""
    zero = np.zeros((3, 3))
    return PayloadEstimate(
        mass=mass,
        mass_std=0.0,
        com=com,
        com_std=np.zeros(3),
        inertia=inertia,
        inertia_std=zero,
        parameters=np.zeros(10),
        parameters_std=np.zeros(10),
        frame="tool",
        fit=None,
    )


def fourier_run(robot: dynid.Robot, seed: int, seconds: float = 20.0) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(seed)
    n = robot.n
    trajectory = dynid.FourierTrajectory(
        2 * np.pi * 0.1,
        0.25 * rng.standard_normal((n, 5)),
        0.25 * rng.standard_normal((n, 5)),
        np.zeros(n),
    )
    t = np.arange(0.0, seconds, 1.0 / FS)
    q, qd, qdd = trajectory.evaluate(t)
    return t, q, qd, qdd


def noisy_log(
    robot: dynid.Robot,
    seed: int,
    noise: np.ndarray | float,
    seconds: float = 20.0,
    derivatives: bool = False,
) -> Log:
    """A log of ``robot`` along the Fourier trajectory of ``seed``, torque noise of ``noise``
    N m (seeded by seed + 7919); positions only (qd, qdd differentiated by prepare_log) unless
    ``derivatives`` (the exact qd, qdd, for noise-free checks)."""
    t, q, qd, qdd = fourier_run(robot, seed, seconds)
    rng = np.random.default_rng(seed + 7919)
    tau = robot.rnea(q, qd, qdd) + noise * rng.standard_normal(q.shape)
    if derivatives:
        return Log(t=t, q=q, tau=tau, qd=qd, qdd=qdd, source=f"fourier{seed}")
    return Log(t=t, q=q, tau=tau, source=f"fourier{seed}")


def z_scores(estimate: PayloadEstimate) -> np.ndarray:
    """(10,) (estimate - truth) / std: mass, com x y z, inertia xx xy xz yy yz zz."""
    upper = np.triu_indices(3)
    return np.concatenate(
        [
            [(estimate.mass - MASS) / estimate.mass_std],
            (estimate.com - COM) / estimate.com_std,
            ((estimate.inertia - INERTIA) / estimate.inertia_std)[upper],
        ]
    )


# --------------------------------------------------------------------------- the formats


def test_kuka_principal_axes_of_a_rotated_box_rebuild_its_inertia():
    # A 3 kg box 0.1 x 0.2 x 0.3 m turned by A = 25, B = -15, C = 10 deg (R = Rz Ry Rx): the
    # load data give back those angles (1e-9 deg), the box's own moments in its edge order
    # (1e-12) and, rebuilt here as R diag(J) R^T, the inertia (1e-12 kg m^2).
    moments = np.diag(box_inertia(3.0, (0.1, 0.2, 0.3)))
    A, B, C = 25.0, -15.0, 10.0
    R = rz(np.radians(A)) @ ry(np.radians(B)) @ rx(np.radians(C))
    inertia = R @ np.diag(moments) @ R.T
    com = np.array([0.012, -0.034, 0.156])
    text = kuka_load_data(estimate_in_tool_frame(3.0, com, inertia))
    line = text.splitlines()[-1]
    values = dict(re.findall(r"([A-Z]+) (-?[0-9.e+-]+)", line.split("J {")[0]))
    J = [float(v) for v in re.findall(r"[XYZ] (-?[0-9.e+-]+)", line.split("J {")[1])]
    assert line.startswith("LOAD_DATA[1]={M 3.0,CM {X ")
    np.testing.assert_allclose(
        [float(values[k]) for k in ("X", "Y", "Z")], 1000 * com, rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(
        [float(values[k]) for k in ("A", "B", "C")], [A, B, C], rtol=0, atol=1e-9
    )
    np.testing.assert_allclose(J, moments, rtol=0, atol=1e-12)
    a, b, c = np.radians([float(values[k]) for k in ("A", "B", "C")])
    rebuilt = rz(a) @ ry(b) @ rx(c)
    np.testing.assert_allclose(rebuilt @ np.diag(J) @ rebuilt.T, inertia, rtol=0, atol=1e-12)


def test_principal_axes_of_a_load_along_the_flange_are_the_flange():
    # A box with its edges along the flange axes: R = E, A = B = C = 0, J = its diagonal.
    inertia = box_inertia(1.0, (0.3, 0.1, 0.2))
    moments, R = principal_axes(inertia)
    np.testing.assert_allclose(R, np.eye(3), rtol=0, atol=1e-15)
    np.testing.assert_allclose(moments, np.diag(inertia), rtol=0, atol=1e-15)
    np.testing.assert_allclose(kuka_angles(R), 0.0, rtol=0, atol=1e-12)


def test_kuka_angles_at_the_gimbal_lock_rebuild_the_rotation():
    # B = 90 deg: A and C are not separate; C = 0 and A carries their difference (1e-12).
    R = rz(0.4) @ ry(np.pi / 2) @ rx(0.1)
    A, B, C = np.radians(kuka_angles(R))
    assert C == 0.0 and pytest.approx(np.pi / 2, abs=1e-12) == B
    np.testing.assert_allclose(rz(A) @ ry(B) @ rx(C), R, rtol=0, atol=1e-12)


def test_franka_and_urscript_fields_hold_the_given_payload():
    # libfranka setLoad: load_inertia column-major (read back here with order="F"); URScript:
    # [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]. Exact (the floats are written by repr).
    estimate = estimate_in_tool_frame(MASS, COM, INERTIA)
    franka = json.loads(json.dumps(franka_endeffector(estimate)))
    assert set(franka) == {"mass", "F_x_Cload", "load_inertia"}
    assert franka["mass"] == MASS and franka["F_x_Cload"] == COM.tolist()
    np.testing.assert_array_equal(np.reshape(franka["load_inertia"], (3, 3), order="F"), INERTIA)
    line = urscript(estimate)
    match = re.fullmatch(r"set_target_payload\(([^,]+), \[([^\]]+)\], \[([^\]]+)\]\)", line)
    assert match is not None, line
    assert float(match[1]) == MASS
    assert [float(v) for v in match[2].split(",")] == COM.tolist()
    J = INERTIA
    assert [float(v) for v in match[3].split(",")] == [
        J[0, 0],
        J[1, 1],
        J[2, 2],
        J[0, 1],
        J[0, 2],
        J[1, 2],
    ]


def test_the_formats_refuse_a_frame_n_estimate_and_a_missing_inertia():
    estimate = estimate_in_tool_frame(MASS, COM, INERTIA)
    flange = PayloadEstimate(**{**estimate.__dict__, "frame": "flange"})
    with pytest.raises(ValueError, match=r"^estimate: controllers take the payload in their"):
        urscript(flange)
    empty = PayloadEstimate(**{**estimate.__dict__, "com": None, "inertia": None})
    with pytest.raises(ValueError, match=r"^estimate: no significant payload"):
        franka_endeffector(empty)


def test_loaded_model_adds_the_payload_to_the_last_link():
    # Its last link's standard parameters = the robot's + (m, m c, I_C + m S(c)) (Steiner, by
    # hand here), 1e-15; the other links unchanged.
    robot = dynid.models.ur5()
    steiner = INERTIA + MASS * (COM @ COM * np.eye(3) - np.outer(COM, COM))
    parameters = np.concatenate(
        [[MASS], MASS * COM, steiner[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]]
    )
    estimate = PayloadEstimate(
        **{**estimate_in_tool_frame(MASS, COM, INERTIA).__dict__, "parameters": parameters}
    )
    model = loaded_model(robot, estimate)
    np.testing.assert_allclose(model.params[-1], robot.params[-1] + parameters, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(model.params[:-1], robot.params[:-1])


# --------------------------------------------------------------------------- serial correlation


def test_long_run_covariance_of_white_rows_is_their_sum_of_squares():
    h = np.random.default_rng(0).standard_normal((500, 3))
    np.testing.assert_allclose(long_run_covariance([h], 1), h.T @ h, rtol=1e-14, atol=0)


def test_long_run_covariance_of_box_filtered_noise_matches_its_closed_form():
    # h = moving sums of K = 10 white draws (unit variance): autocovariance (K - |l|) at lag
    # |l| < K, so Var(sum_t h_t) = T sum_l (K - |l|) = T K^2 (to the ends). Sokal's window finds
    # tau_int = K: M = 5 K within 20 %; the Bartlett estimate within 8 % (T = 200000, sampling
    # error ~ sqrt(4 L / 3 T) = 4 %).
    K, T = 10, 200_000
    rng = np.random.default_rng(1)
    white = rng.standard_normal(T + K - 1)
    h = np.convolve(white, np.ones(K), mode="valid")[:, None]
    M = correlation_window([h])
    assert 0.8 * 5 * K <= M <= 1.2 * 5 * K
    width = bartlett_width([h])
    omega = long_run_covariance([h], width)[0, 0]
    assert omega == pytest.approx(T * K**2, rel=0.08)
    white_only = long_run_covariance([h], 1)[0, 0]
    assert white_only == pytest.approx(T * K, rel=0.05)  # the white-noise formula: K x too small


# --------------------------------------------------------------------------- the estimate


def test_noise_free_logs_give_the_payload_exactly_with_a_results_torque_model():
    # The unloaded arm identified first (rotor, friction and offsets: a result's own columns); its
    # model's coefficients and the payload fitted together on exact torques: 1e-9.
    arm = dynid.models.kuka_lwr4()
    arm.Fv, arm.Fs = np.full(7, 0.4), np.full(7, 0.3)
    unloaded = noisy_log(arm, 1, 0.0, seconds=12.0, derivatives=True)
    loaded = noisy_log(arm.with_payload(MASS, COM, INERTIA), 2, 0.0, seconds=12.0, derivatives=True)
    result = dynid.identify_log(
        unloaded, dynid.models.kuka_lwr4(), rotor=True, friction=True, offset=True
    )
    est = estimate_payload_from_logs(unloaded, loaded, result)
    assert est.mass == pytest.approx(MASS, abs=1e-9)
    np.testing.assert_allclose(est.com, COM, rtol=0, atol=1e-9)
    np.testing.assert_allclose(est.inertia, INERTIA, rtol=0, atol=1e-9)
    assert len(est.fit.names) == len(result.names) + 10


def test_ur5_filtered_logs_the_std_are_calibrated_over_40_seeds():
    # UR5, 2 kg payload, per-joint noise UR5_NOISE, 20 s logs low-passed at 10 Hz (500 Hz:
    # tau_int ~ 30 samples). Every seed: mass within 1 %, com within 2 mm. Over 40 seeds the RMS
    # of each quantity's z-score in [0.7, 1.3] (expected 1, +-0.11 one sigma). The same fits
    # with the white-noise covariance: the inertia's z RMS above 3 (the "5 std off").
    robot = dynid.models.ur5()
    loaded_arm = robot.with_payload(MASS, COM, INERTIA)
    z, white = [], []
    for seed in range(40):
        est = estimate_payload_from_logs(
            noisy_log(robot, 1000 + seed, UR5_NOISE),
            noisy_log(loaded_arm, 2000 + seed, UR5_NOISE),
            robot,
            preparation={"cutoff": 10.0},
        )
        assert abs(est.mass - MASS) < 0.01 * MASS
        assert np.all(np.abs(est.com - COM) < 2e-3)
        z.append(z_scores(est))
        p = est.fit.theta.size - 10
        white.append(
            z_scores(
                _physical(est.fit.theta[p:], est.fit.covariance[p:, p:], robot, "flange", None)
            )
        )
    rms = np.sqrt((np.array(z) ** 2).mean(axis=0))
    assert np.all((rms > 0.7) & (rms < 1.3)), rms
    assert np.all(np.sqrt((np.array(white) ** 2).mean(axis=0))[4:] > 3.0)


def test_a_short_unloaded_log_its_model_error_is_in_the_std():
    # Unfiltered, the unloaded log 4 s against a 20 s loaded log: the unloaded model's error is
    # a large part of the payload's. Over 24 seeds the joint fit's inertia z-scores (the six
    # entries pooled) have RMS in [0.8, 1.2] (observed 0.93); taking the identified unloaded
    # model as exact (its prediction as tau_unloaded, dynid.estimate_payload) gives an RMS above
    # 1.5.
    robot = dynid.models.ur5()
    loaded_arm = robot.with_payload(MASS, COM, INERTIA)
    z, exact = [], []
    for seed in range(24):
        unloaded = noisy_log(robot, 3000 + seed, UR5_NOISE, seconds=4.0)
        loaded = noisy_log(loaded_arm, 4000 + seed, UR5_NOISE)
        z.append(z_scores(estimate_payload_from_logs(unloaded, loaded, robot))[4:])
        result = dynid.identify_log(unloaded, robot)
        prepared = dynid.prepare_log(loaded)
        two_step = dynid.estimate_payload(
            robot,
            prepared.q,
            prepared.qd,
            prepared.qdd,
            prepared.tau,
            tau_unloaded=result.predict(prepared),
            method="wls",
        )
        exact.append(z_scores(two_step)[4:])
    rms = np.sqrt((np.array(z) ** 2).mean())
    assert 0.8 < rms < 1.2, rms
    assert np.sqrt((np.array(exact) ** 2).mean()) > 1.5


def test_estimate_payload_from_logs_bad_arguments():
    robot = dynid.models.planar_2r()
    log = noisy_log(robot, 0, 0.0, seconds=2.0)
    with pytest.raises(ValueError, match=r"^model: expected a dynid.Robot or a result"):
        estimate_payload_from_logs(log, log, "ur5")
    with pytest.raises(ValueError, match=r"^frame: expected one of"):
        estimate_payload_from_logs(log, log, robot, frame="base")
    with pytest.raises(ValueError, match=r"^method: expected 'ols' or 'wls'"):
        estimate_payload_from_logs(log, log, robot, method="tls")
    with pytest.raises(ValueError, match=r"^loaded: log: expected a dynid.Log"):
        estimate_payload_from_logs(log, 3, robot)
    result = dynid.identify_log(log, robot)
    with pytest.raises(ValueError, match=r"^rotor, friction, offset: a result brings"):
        estimate_payload_from_logs(log, log, result, friction=True)


# --------------------------------------------------------------------------- the command


@pytest.fixture(scope="module")
def panda_logs(tmp_path_factory):
    """Panda (tool: the flange 0.107 m along z of frame 7) without and with the payload, exact
    torques, as NPZ logs."""
    folder = tmp_path_factory.mktemp("payload")
    robot = dynid.models.panda()
    save_log(noisy_log(robot, 5, 0.0, seconds=12.0, derivatives=True), folder / "unloaded.npz")
    save_log(
        noisy_log(robot.with_payload(MASS, COM, INERTIA), 6, 0.0, seconds=12.0, derivatives=True),
        folder / "loaded.npz",
    )
    return folder


def test_the_command_writes_every_format_in_the_flange_frame(panda_logs, tmp_path, capsys):
    # Exact torques: the files hold the payload in the Panda's flange frame F, c_F = c_7 - (0,
    # 0, 0.107) and the inertia unchanged (the tool is a translation), 1e-9; model.json is the
    # loaded arm (its rnea equals the truth's, 1e-9 N m).
    out = tmp_path / "p"
    argv = ["payload", str(panda_logs / "unloaded.npz"), str(panda_logs / "loaded.npz")]
    assert main([*argv, "--model", "panda", "--output", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "payload in the tool frame" in printed and "[3/3] wrote" in printed
    flange_com = COM - np.array([0.0, 0.0, 0.107])
    record = json.loads((out / "payload.json").read_text())
    assert record["frame"] == "tool" and record["mass"] == pytest.approx(MASS, abs=1e-9)
    np.testing.assert_allclose(record["com"], flange_com, rtol=0, atol=1e-9)
    np.testing.assert_allclose(record["inertia"], INERTIA, rtol=0, atol=1e-9)
    np.testing.assert_allclose(record["tool"], dynid.models.panda().tool, rtol=0, atol=0)
    franka = json.loads((out / "franka_endeffector.json").read_text())
    np.testing.assert_allclose(franka["F_x_Cload"], flange_com, rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        np.reshape(franka["load_inertia"], (3, 3), order="F"), INERTIA, rtol=0, atol=1e-9
    )
    line = (out / "urscript.txt").read_text().strip()
    assert line.startswith("set_target_payload(")
    kuka = (out / "kuka_load_data.txt").read_text().splitlines()[-1]
    assert kuka.startswith("LOAD_DATA[1]={M ")
    model = load_model(out / "model.json")
    truth = dynid.models.panda().with_payload(MASS, COM, INERTIA)
    _, q, qd, qdd = fourier_run(truth, 9, seconds=1.0)
    np.testing.assert_allclose(model.rnea(q, qd, qdd), truth.rnea(q, qd, qdd), atol=1e-9)


def test_the_command_with_a_result_uses_its_model_and_preparation(tmp_path, capsys):
    # identify on the unloaded log with --cutoff 20, then payload --model RESULT: the recorded
    # cutoff is applied (printed), the payload within 1 % / 2 mm.
    robot = dynid.models.ur5()
    save_log(noisy_log(robot, 11, UR5_NOISE), tmp_path / "u.npz")
    save_log(noisy_log(robot.with_payload(MASS, COM, INERTIA), 12, UR5_NOISE), tmp_path / "l.npz")
    ident = tmp_path / "ident"
    assert (
        main(
            [
                "identify",
                str(tmp_path / "u.npz"),
                "--model",
                "ur5",
                "--cutoff",
                "20",
                "--output",
                str(ident),
            ]
        )
        == 0
    )
    capsys.readouterr()
    out = tmp_path / "p"
    assert (
        main(
            [
                "payload",
                str(tmp_path / "u.npz"),
                str(tmp_path / "l.npz"),
                "--model",
                str(ident),
                "--output",
                str(out),
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "--cutoff 20.0 (recorded in the result)" in printed
    record = json.loads((out / "payload.json").read_text())
    assert abs(record["mass"] - MASS) < 0.01 * MASS
    assert np.all(np.abs(np.array(record["com"]) - COM) < 2e-3)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--model", "{d}/ident", "--rotor"], r"--rotor, --friction, --offset: only with a MODEL"),
        (["--model", "panda", "--loaded-unloaded"], r"unrecognized arguments"),
        (["--model", "nosuchmodel"], r"nosuchmodel"),
    ],
    ids=["rotor_with_result", "unknown_option", "unknown_model"],
)
def test_the_commands_errors_are_one_line(panda_logs, tmp_path, capsys, extra, message):
    if "{d}/ident" in extra:
        argv = [
            "identify",
            str(panda_logs / "unloaded.npz"),
            "--model",
            "panda",
            "--output",
            str(tmp_path / "ident"),
        ]
        assert main(argv) == 0
        capsys.readouterr()
    argv = [
        "payload",
        str(panda_logs / "unloaded.npz"),
        str(panda_logs / "loaded.npz"),
        "--output",
        str(tmp_path / "out"),
        *[a.format(d=tmp_path) for a in extra],
    ]
    if "--loaded-unloaded" in extra:
        with pytest.raises(SystemExit) as info:
            main(argv)
        assert info.value.code == 2
    else:
        assert main(argv) == 2
    err = capsys.readouterr().err
    assert re.search(message, err), err
    assert not (tmp_path / "out").exists()


def test_no_payload_is_an_error_and_writes_nothing(panda_logs, tmp_path, capsys):
    # The unloaded log given as the loaded one: mass ~0, no centre of mass, exit 2, no folder.
    log = str(panda_logs / "unloaded.npz")
    out = tmp_path / "out"
    assert main(["payload", log, log, "--model", "panda", "--output", str(out)]) == 2
    assert "no significant payload" in capsys.readouterr().err
    assert not out.exists()
