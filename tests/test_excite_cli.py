"""`dynid excite` (issue 21, item 1; docs/cli.md): the limits it takes from options and from a
URDF's <limit velocity effort>, the files it writes, and its user errors (one line, exit 2).
Every limit of the written trajectory is checked here on a grid 100x denser than the
optimiser's samples, the torque with robot.rnea."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli.main import main
from dynid.excitation import load_trajectory
from dynid.export.trajectory_out import FILES

DATA = Path(dynid.__file__).parent / "data"
QUICK = ["--harmonics", "2", "--samples", "40", "--maxiter", "5", "--period", "6"]


def test_excite_writes_a_trajectory_within_every_limit(tmp_path, capsys) -> None:
    out = tmp_path / "lwr"
    tau_max = "60,40,25,15,5,3,2"
    argv = ["excite", "--model", "kuka_lwr4", *QUICK, "--qd-max", "0.8", "--qdd-max", "1.5"]
    argv += ["--tau-max", tau_max, "--q-max=2.5", "--rate", "250", "--output", str(out)]
    assert main(argv) == 0
    assert "cond" in capsys.readouterr().out
    written = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert written == sorted([*FILES, "report.html"])  # the page: tests/test_excite_report.py
    plan = load_trajectory(out)
    robot = dynid.models.kuka_lwr4()
    limits = plan.limits
    assert limits["qd_max"] == [0.8] * 7 and limits["qdd_max"] == [1.5] * 7
    assert limits["tau_max"] == [60.0, 40.0, 25.0, 15.0, 5.0, 3.0, 2.0]
    assert limits["q_max"] == [2.5] * 7 and limits["q_min"] == robot.qlim[:, 0].tolist()
    t = np.linspace(0.0, plan.duration, 100 * 40 + 1)
    q, qd, qdd = plan.evaluate(t)
    span = 2.5 - robot.qlim[:, 0]
    assert np.all(q <= 2.5 - 0.02 * span) and np.all(q >= robot.qlim[:, 0] + 0.02 * span)
    assert np.abs(qd).max() <= 0.8 and np.abs(qdd).max() <= 1.5
    assert np.all(np.abs(robot.rnea(q, qd, qdd)) <= np.array(limits["tau_max"]))
    log = dynid.load_log(out / "trajectory.csv")
    assert log.t.size == (6 * 250) + 1 and log.t[-1] == pytest.approx(6.0, abs=1e-12)


def test_urdf_velocity_and_effort_limits_are_used(tmp_path) -> None:
    out = tmp_path / "ur5"
    argv = ["excite", "--model", str(DATA / "ur5.urdf"), "--tip-link", "tool0", *QUICK]
    assert main([*argv, "--output", str(out)]) == 0
    limits = json.loads((out / "trajectory.json").read_text())["limits"]
    # ur5.urdf: velocity 3.15 and effort 150 on joints 1-3, 3.2 and 28 on joints 4-6
    assert limits["qd_max"] == [3.15] * 3 + [3.2] * 3
    assert limits["tau_max"] == [150.0] * 3 + [28.0] * 3
    plan = load_trajectory(out / "trajectory.json")
    robot = dynid.load_model(DATA / "ur5.urdf", tip_link="tool0")
    t = np.linspace(0.0, plan.duration, 4001)
    assert np.all(np.abs(robot.rnea(*plan.evaluate(t))) <= np.array(limits["tau_max"]))
    assert plan.joint_names == robot.joint_names


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--qd-max", "1,2"], "--qd-max: expected one number or 7"),
        (["--tau-max", "0.01"], "tau_max: the gravity torque"),
        (["--qdd-max", "-1"], "--qdd-max: expected positive limits"),
        (["--q-min=3"], "--q-min, --q-max"),
        (["--prior", "ur5"], "--prior: expected a model with 7 joints"),
        (["--tip-link", "tool0"], "--tip-link: only with a URDF model"),
        (["--harmonics", "1"], "harmonics"),
        (["--periods", "0"], "periods"),
        (["--rate", "0"], "rate"),
    ],
)
def test_user_errors_are_one_line_and_exit_2(tmp_path, capsys, extra, message) -> None:
    out = tmp_path / "out"
    assert main(["excite", *QUICK, "--maxiter", "0", *extra, "--output", str(out)]) == 2
    error = capsys.readouterr().err.strip()
    assert error.startswith("dynid excite: error: ") and "\n" not in error
    assert message in error
    assert not out.exists()  # nothing half-written


def test_a_non_empty_output_folder_is_kept(tmp_path, capsys) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    assert main(["excite", *QUICK, "--output", str(out)]) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert (out / "mine.txt").read_text() == "keep"
