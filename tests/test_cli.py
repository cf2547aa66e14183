"""`dynid identify`, `dynid validate`, `dynid info`: in process through main(), once as a
process."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result
from dynid.logs import save_log
from dynid.model.model_files import save_model
from test_log_identification import PNG, fourier_log


def _arm() -> dynid.Robot:
    robot = dynid.models.planar_2r()
    robot.Fv = np.array([0.3, 0.2])
    robot.Fs = np.array([0.4, 0.1])
    return robot


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A 2R arm's model file, a training log (NPZ) and a validation log (CSV), exact torques."""
    folder = tmp_path_factory.mktemp("cli")
    arm = _arm()
    save_model(dynid.models.planar_2r(), folder / "arm.json")  # the structure only matters
    save_log(fourier_log(arm, 1, seconds=4.0), folder / "train.npz")
    save_log(fourier_log(arm, 2, seconds=2.0), folder / "check.csv")
    np.savez(folder / "no_tau.npz", t=np.arange(3.0), q=np.zeros((3, 2)))
    (folder / "no_rows.json").write_text(json.dumps({"convention": "standard"}))
    return folder


def test_identify_validate_and_info(files, tmp_path, capsys):
    out, check = tmp_path / "ident", tmp_path / "check"
    argv = [
        "identify",
        str(files / "train.npz"),
        "--model",
        str(files / "arm.json"),
        "--friction",
        "--method",
        "ols",
        "--output",
        str(out),
    ]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "[5/5] wrote" in printed and "condition number" in printed and "Fs2" in printed
    arm = _arm()
    expected = dynid.base_parameters(arm, friction=True).values(arm)
    result = load_result(out)
    np.testing.assert_allclose(result.theta, expected, rtol=0, atol=1e-9)
    assert (out / "torques.png").read_bytes()[:8] == PNG

    assert main(["validate", str(out), str(files / "check.csv"), "--output", str(check)]) == 0
    printed = capsys.readouterr().out
    assert "rel. rms" in printed and "J2" in printed
    report = json.loads((check / "validation.json").read_text())
    assert report["samples"] == 200
    assert max(report["metrics"]["relative_rms"]) < 1e-9  # the exact model, again
    assert all((check / name).read_bytes()[:8] == PNG for name in ("torques.png", "residuals.png"))

    assert main(["info", "--model", str(files / "arm.json")]) == 0
    printed = capsys.readouterr().out
    assert "planar 2R: 2 joints (RR), standard DH" in printed
    # 6 in a vertical plane (docs/base_parameters.md, "Base parameters")
    assert "base parameters: torque 6 (rigid body)" in printed


def test_preparation_options_reach_the_result(files, tmp_path, capsys):
    argv = [
        "identify",
        str(files / "train.npz"),
        "--model",
        "planar_2r",
        "--friction",
        "--skip",
        "10",
        "--cutoff",
        "8",
        "--order",
        "2",
        "--decimate",
        "2",
        "--min-velocity",
        "0.01",
        "--outliers",
        "8",
        "--offset",
        "--output",
        str(tmp_path),
    ]
    assert main(argv) == 0
    training = json.loads((tmp_path / "result.json").read_text())["training"]
    assert training["preparation"] == {
        "cutoff": 8.0,
        "decimate": 2,
        "order": 2,
        "min_velocity": 0.01,
        "outlier_k": 8.0,
    }
    notes = " ".join(training["notes"])
    assert "skipped the first 10 samples" in notes and "order-2 Butterworth 8 Hz" in notes
    assert "|qd_j| < 0.01" in notes  # rows of the slow joint, not whole samples (issue 20)
    assert "prepared: skipped" not in capsys.readouterr().out  # step 3 lists the new notes only


ERRORS = [
    (["identify", "{d}/absent.npz"], "path: no such file"),
    (["identify", "{d}/no_tau.npz"], "missing key 'tau'"),
    (["identify", "{d}/train.npz", "--model", "{d}/no_rows.json"], "rows: missing"),
    (["identify", "{d}/train.npz", "--model", "scara"], "neither a built-in model"),
    (["identify", "{d}/train.npz", "--model", "kuka_lwr4"], "log: has 2 joints"),
    (["identify", "{d}/train.npz", "--cutoff", "500"], "cutoff: expected 0 < cutoff"),
    (["validate", "{d}/absent", "{d}/check.csv"], "result: no such file"),
    (["validate", "{d}/arm.json", "{d}/check.csv"], "format: expected 'dynid-identification'"),
    (["info", "--model", "{d}/no_rows.json"], "rows: missing"),
]


@pytest.mark.parametrize(("argv", "message"), ERRORS)
def test_errors_exit_2_with_one_line(files, capsys, argv, message):
    assert main([a.format(d=files) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"dynid {argv[0]}: error: ")
    assert message in err and "Traceback" not in err


@pytest.mark.parametrize("command", ["identify", "validate", "residual"])
def test_an_unknown_option_is_reported_with_the_commands_usage(files, capsys, command):
    """Issue 22: `dynid identify LOG --frobnicate` printed the top-level usage."""
    positionals = {"identify": ["{d}/train.npz"], "validate": ["{d}/r", "{d}/check.csv"]}
    argv = [command, *positionals.get(command, ["{d}/r", "{d}/check.csv"]), "--frobnicate"]
    with pytest.raises(SystemExit) as exit_status:
        main([a.format(d=files) for a in argv])
    assert exit_status.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"usage: dynid {command} "), err
    assert err.endswith(f"dynid {command}: error: unrecognized arguments: --frobnicate\n"), err


def test_as_a_process(files):
    """The installed entry point: a bad input is one line on stderr and exit status 2."""
    done = subprocess.run(
        [sys.executable, "-m", "dynid.cli", "identify", str(files / "no_tau.npz")],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2
    assert done.stderr.startswith("dynid identify: error: ") and done.stderr.count("\n") == 1
    assert "missing key 'tau'" in done.stderr and "Traceback" not in done.stderr


def test_identify_position_torque(files, tmp_path, capsys):
    """--position-torque: the 2R arm's exact torques plus 0.3 sin q2 - 0.2 cos q2 on joint 2.
    Joint 1's columns are gravity on this vertical-plane arm (left out, said so); the result
    holds ks2, kc2 to 1e-9 and records the joint in result.json."""
    arm = _arm()
    log = fourier_log(arm, 1, seconds=4.0)
    tau = log.tau.copy()
    tau[:, 1] += 0.3 * np.sin(log.q[:, 1]) - 0.2 * np.cos(log.q[:, 1])
    save_log(dynid.Log(t=log.t, q=log.q, tau=tau, qd=log.qd, qdd=log.qdd), tmp_path / "p.npz")
    out = tmp_path / "ident"
    assert (
        main(
            [
                "identify",
                str(tmp_path / "p.npz"),
                "--model",
                str(files / "arm.json"),
                "--friction",
                "--position-torque",
                "--method",
                "ols",
                "--output",
                str(out),
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "not on joint(s) 1" in printed and "kc2" in printed
    result = load_result(out)
    assert result.names[-2:] == ["ks2", "kc2"] and result.position_joints == (1,)
    np.testing.assert_allclose(result.theta[-2:], [0.3, -0.2], rtol=0, atol=1e-9)
    options = json.loads((out / "result.json").read_text())["options"]
    assert options["position_torque_joints"] == [2]


def test_python_m_dynid_is_the_command() -> None:
    """``python -m dynid`` runs the ``dynid`` command (environments without the script)."""
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-m", "dynid", "info", "--model", "planar_2r"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("planar 2R")
