"""Identification on files in the robots' own formats (issue 20, item 1): a simulated arm with
known parameters writes a UR RTDE, libfranka or headerless CSV file (tests/log_writers.py);
``dynid identify`` (the library call, and once the command line) reads it and must recover the
base parameters beta @ pi of the simulated arm (rigid body, rotor inertia, viscous and Coulomb
friction) to the tolerance the file's number formatting allows."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli.main import main
from dynid.identification.log_identification import identify_log
from dynid.logs import load_log
from log_writers import Motion, simulate, write_libfranka, write_rtde


def true_base(robot: dynid.Robot) -> np.ndarray:
    return dynid.base_parameters(robot, rotor=True, friction=True).values(robot)


def relative_error(theta: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(theta - expected)) / np.max(np.abs(expected)))


def test_rtde_recording_recovers_the_ur5(tmp_path: Path):
    robot = dynid.models.ur5()
    m = simulate(robot, seed=11, seconds=10.0, fs=500.0)
    path = tmp_path / "robot_data.csv"
    write_rtde(path, m, current=m.tau)
    result = identify_log(load_log(path), robot, rotor=True, friction=True, method="ols")
    # Written with repr (exact); qdd is differentiated from actual_qd (central differences at
    # 500 Hz of harmonics up to 0.6 Hz: relative error ~(w dt)^2 / 6 ~ 1e-5, more at the ends);
    # measured 1.1e-5 of the largest parameter.
    assert relative_error(result.theta, true_base(robot)) < 1e-4
    assert result.training["format"] == "UR RTDE CSV"


def test_libfranka_recording_recovers_the_panda(tmp_path: Path):
    robot = dynid.models.panda()
    m = simulate(robot, seed=12, seconds=10.0, fs=1000.0)
    path = tmp_path / "panda.csv"
    write_libfranka(path, m)
    result = identify_log(load_log(path), robot, rotor=True, friction=True, method="ols")
    # 6 significant digits in q, dq, tau_J (relative rounding 5e-6) and qdd from dq: measured
    # 7.5e-6 of the largest parameter.
    assert relative_error(result.theta, true_base(robot)) < 1e-4
    assert result.training["format"] == "libfranka logToCSV"


def test_headerless_csv_recovers_the_lwr_from_the_command_line(tmp_path: Path, capsys):
    robot = dynid.models.kuka_lwr4()
    m = simulate(robot, seed=13, seconds=5.0, fs=200.0)
    path = tmp_path / "plain.csv"
    np.savetxt(path, np.column_stack([m.t, m.q, m.qd, m.qdd, m.tau]), fmt="%.17g", delimiter=" ")
    out = tmp_path / "out"
    status = main(
        ["identify", str(path), "--model", "kuka_lwr4", "--rotor", "--friction", "--method",
         "ols", "--columns", "t=0,q=1:8,qd=8:15,qdd=15:22,tau=22:29", "--output", str(out)]
    )  # fmt: skip
    assert status in (0, None)
    printed = capsys.readouterr().out
    assert f"log {path} (CSV)" in printed
    saved = json.loads((out / "result.json").read_text())
    assert saved["training"]["format"] == "CSV"
    theta = np.array([row["value"] for row in saved["coefficients"]])
    # Every signal exact in the file (17 digits): the least squares' own rounding only.
    assert relative_error(theta, true_base(robot)) < 1e-9
    # validate names the format of its log too (validation.json's log_format)
    argv = ["validate", str(out), str(path), "--columns", "t=0,q=1:8,qd=8:15,qdd=15:22,tau=22:29"]
    assert main([*argv, "--output", str(tmp_path / "v")]) == 0
    report = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert report["log_format"] == "CSV"


def test_drop_nonfinite_from_the_command_line(tmp_path: Path, capsys):
    robot = dynid.models.kuka_lwr4()
    m = simulate(robot, seed=14, seconds=5.0, fs=200.0)
    m.tau[100, 3] = np.nan
    path = tmp_path / "robot_data.csv"
    write_rtde(path, Motion(m.t, m.q, m.qd, m.qdd, m.tau), current=m.tau)
    out = tmp_path / "out"
    args = ["identify", str(path), "--model", "kuka_lwr4", "--output", str(out)]
    assert main(args) == 2
    assert "--drop-nonfinite" in capsys.readouterr().err
    assert main([*args, "--drop-nonfinite"]) in (0, None)
    printed = capsys.readouterr().out
    assert "(UR RTDE CSV; dropped 1 of 1000 rows with non-finite values" in printed


@pytest.mark.parametrize("flag", [[], ["--current"]])
def test_log_options_pass_current_and_drop_nonfinite(flag):
    from dynid.cli.commands import log_options
    from dynid.cli.parsers import build_parser

    args = build_parser().parse_args(["validate", "res", "log.csv", "--drop-nonfinite", *flag])
    options = log_options(args)
    assert options["drop_nonfinite"] is True and options["current"] is bool(flag)
