"""Replayable runs (issue 20.4): `--config run.yaml` gives every option of the command line (the
command line overrides it), each result folder holds the run.yaml that reproduces its
result.json byte for byte; --tip-link/--base-link on every command that reads a URDF."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

import dynid
from dynid.cli import main
from dynid.cli.parsers import build_parser
from dynid.export.result_files import load_result
from dynid.logs import save_log
from dynid.model.model_files import save_model
from test_log_identification import fourier_log
from test_several_logs import _arm, _noisy

UR5_URDF = Path(dynid.__file__).parent / "data" / "ur5.urdf"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("runs")
    arm = _arm()
    save_log(_noisy(fourier_log(arm, 3, seconds=4.0), 10, (0.05, 0.01)), folder / "a.npz")
    save_log(_noisy(fourier_log(arm, 4, seconds=3.0), 11, (0.05, 0.01)), folder / "b.csv")
    save_model(dynid.models.planar_2r(), folder / "arm.json")
    return folder


def _identify(files, out, *more):
    argv = ["identify", str(files / "a.npz"), str(files / "b.csv"), "--model"]
    argv += [str(files / "arm.json"), "--friction", "--offset", "--cutoff", "20"]
    return main([*argv, "--decimate", "2", "--output", str(out), *more])


def test_run_yaml_replays_the_result_byte_for_byte(files, tmp_path, capsys):
    out, again = tmp_path / "out", tmp_path / "again"
    assert _identify(files, out) == 0
    run = yaml.safe_load((out / "run.yaml").read_text())
    # Every option of the command, with its resolved default, the logs, the version.
    (commands,) = (a for a in build_parser()._actions if a.dest == "command")
    identify = commands.choices["identify"]
    options = {a.dest for a in identify._actions} - {"help", "config"}
    assert set(run) == options | {"command", "dynid_version", "working_directory"}
    assert run["log"] == [str(files / "a.npz"), str(files / "b.csv")]
    assert run["method"] == "wls" and run["skip"] == 0 and run["cutoff"] == 20.0
    assert run["dynid_version"] == dynid.__version__ and run["command"] == "identify"
    capsys.readouterr()
    assert main(["identify", "--config", str(out / "run.yaml"), "--output", str(again)]) == 0
    assert (again / "result.json").read_bytes() == (out / "result.json").read_bytes()
    replayed = yaml.safe_load((again / "run.yaml").read_text())
    assert replayed == dict(run, output=str(again))


def test_a_physical_run_replays_but_for_the_solver_times(files, tmp_path):
    out, again = tmp_path / "out", tmp_path / "again"
    assert _identify(files, out, "--physical", "--prior", str(files / "arm.json")) == 0
    assert main(["identify", "--config", str(out / "run.yaml"), "--output", str(again)]) == 0
    first, second = (json.loads((f / "result.json").read_text()) for f in (out, again))
    for data in (first, second):
        assert data["physical"].pop("solve_time_s") is not None
        assert data["physical"].pop("setup_time_s") is not None
    assert first == second
    assert yaml.safe_load((out / "run.yaml").read_text())["prior_weight"] == 1e-5


def test_replayed_elsewhere_a_relative_path_warns(files, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(files)
    out = tmp_path / "out"
    argv = ["identify", "a.npz", "--model", "arm.json", "--output", str(out)]
    assert main(argv) == 0
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    assert main(["identify", "--config", str(out / "run.yaml"), "--output", "again"]) == 2
    err = capsys.readouterr().err
    assert f"warning: log: a.npz is not in the current directory but in {files}" in err
    assert "model: arm.json is not in the current directory" in err
    monkeypatch.chdir(files)  # from there it replays
    assert main(["identify", "--config", str(out / "run.yaml"), "--output", str(out) + "2"]) == 0


def test_another_version_warns(files, tmp_path, capsys):
    config = tmp_path / "run.yaml"
    config.write_text(
        f"dynid_version: 0.0.1\nlog: {files / 'a.npz'}\nmodel: {files / 'arm.json'}\n"
    )
    assert main(["identify", "--config", str(config), "--output", str(tmp_path / "o")]) == 0
    err = capsys.readouterr().err
    assert f"warning: {config}: written by dynid 0.0.1, this is {dynid.__version__}" in err


def test_the_command_line_overrides_the_config(files, tmp_path):
    out = tmp_path / "out"
    assert _identify(files, out, "--method", "ols") == 0
    cutoff = tmp_path / "cutoff"
    argv = ["identify", "--config", str(out / "run.yaml"), "--cutoff", "10", "--output"]
    assert main([*argv, str(cutoff)]) == 0
    result = load_result(cutoff)
    assert result.training["preparation"]["cutoff"] == 10.0 and result.method == "ols"
    assert result.training["preparation"]["decimate"] == 2  # the file's value kept
    # LOGs on the command line replace the file's list.
    one = tmp_path / "one"
    argv = ["identify", str(files / "a.npz"), "--config", str(out / "run.yaml"), "--output"]
    assert main([*argv, str(one)]) == 0
    assert load_result(one).training["source"] == str(files / "a.npz")


def test_a_hand_written_config(files, tmp_path):
    config = tmp_path / "run.yaml"
    config.write_text(
        f"log: {files / 'a.npz'}\nmodel: {files / 'arm.json'}\nfriction: true\n"
        "method: ols\ntime-unit: s\n"
    )
    out = tmp_path / "out"
    assert main(["identify", "--config", str(config), "--output", str(out)]) == 0
    direct = tmp_path / "direct"
    argv = ["identify", str(files / "a.npz"), "--model", str(files / "arm.json"), "--friction"]
    assert main([*argv, "--method", "ols", "--time-unit", "s", "--output", str(direct)]) == 0
    assert (out / "result.json").read_bytes() == (direct / "result.json").read_bytes()


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("cutof: 10\nrotr: true\n", "unknown key.*cutof, rotr"),
        ("cutoff: fast\n", "cutoff: expected a number"),
        ("rotor: 1\n", "rotor: expected true or false"),
        ("decimate: 2.5\n", "decimate: expected an integer"),
        ("skip: null\n", "skip: expected a value"),
        # the registered estimators between wls and nls (dynid.identification.estimators)
        ("method: lasso\n", "method: expected one of 'ols', 'wls', .*'nls', 'tls', got 'lasso'"),
        ("log: [1, 2]\n", "log: expected a path or a list of paths"),
        ("command: validate\n", "command: this file is for `dynid validate`"),
        ("- a\n- b\n", "expected a mapping of options"),
        ("config: other.yaml\n", "unknown key.*config"),
        ("tip-link: a\ntip_link: b\n", "tip-link, tip_link: the same option twice"),
    ],
)
def test_bad_config_is_a_usage_error_naming_the_key(tmp_path, capsys, content, message):
    config = tmp_path / "run.yaml"
    config.write_text(content)
    with pytest.raises(SystemExit) as exit_:
        main(["identify", "--config", str(config)])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "dynid identify: error: --config" in err
    assert __import__("re").search(message, err), err


def test_missing_log_and_missing_config(tmp_path, capsys):
    assert main(["identify", "--output", str(tmp_path / "o")]) == 2
    assert "LOG: give at least one measurement log" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["identify", "--config", str(tmp_path / "absent.yaml")])
    assert "no such file" in capsys.readouterr().err


def test_validate_config_replays(files, tmp_path):
    out = tmp_path / "out"
    assert _identify(files, out) == 0
    check, again = tmp_path / "check", tmp_path / "again"
    argv = ["validate", str(out), str(files / "b.csv"), "--cutoff", "20", "--output"]
    assert main([*argv, str(check)]) == 0
    run = yaml.safe_load((check / "run.yaml").read_text())
    assert run["result"] == str(out) and run["cutoff"] == 20.0
    assert main(["validate", "--config", str(check / "run.yaml"), "--output", str(again)]) == 0
    first = json.loads((check / "validation.json").read_text())
    second = json.loads((again / "validation.json").read_text())
    assert first == second


def test_ur5_urdf_needs_tip_link(tmp_path, capsys):
    """The package's own UR5 URDF has two leaves (ee_link, tool0): the error says --tip-link,
    and with --tip-link tool0 the exact log gives the base parameters of models.ur5()."""
    robot = dynid.models.ur5()  # the URDF's chain to tool0
    log = tmp_path / "ur5.npz"
    save_log(fourier_log(robot, 1, seconds=3.0), log)
    argv = ["identify", str(log), "--model", str(UR5_URDF), "--method", "ols"]
    assert main([*argv, "--output", str(tmp_path / "fail")]) == 2
    err = capsys.readouterr().err
    assert "'ee_link', 'tool0'" in err and "--tip-link" in err
    out = tmp_path / "out"
    assert main([*argv, "--tip-link", "tool0", "--output", str(out)]) == 0
    expected = dynid.base_parameters(robot).values(robot)
    result = load_result(out)
    np.testing.assert_allclose(result.theta, expected, rtol=0, atol=1e-8 * np.abs(expected).max())
    assert yaml.safe_load((out / "run.yaml").read_text())["tip_link"] == "tool0"
    # The other commands that read a URDF.
    assert main(["info", "--model", str(UR5_URDF)]) == 2
    assert "--tip-link" in capsys.readouterr().err
    assert main(["info", "--model", str(UR5_URDF), "--tip-link", "ee_link"]) == 0
    assert "ur5: 6 joints" in capsys.readouterr().out
    urdf = tmp_path / "ur5.urdf"
    assert main(["export", str(UR5_URDF), "--tip-link", "tool0", "--urdf", str(urdf)]) == 0
    np.testing.assert_allclose(dynid.Robot.from_urdf(urdf).params, robot.params, rtol=0, atol=1e-12)
    residual = ["residual", str(UR5_URDF), str(log), "--tip-link", "tool0", "--output"]
    assert main([*residual, str(tmp_path / "residual")]) == 0
    assert (tmp_path / "residual" / "residual.npz").is_file()
    # A base link moves the chain's start: the arm from shoulder_link on has 5 joints.
    assert (
        main(
            [
                "info",
                "--model",
                str(UR5_URDF),
                "--base-link",
                "shoulder_link",
                "--tip-link",
                "tool0",
            ]
        )
        == 0
    )
    assert "5 joints" in capsys.readouterr().out


def test_links_only_with_a_urdf(files, tmp_path, capsys):
    assert main(["info", "--model", "ur5", "--tip-link", "tool0"]) == 2
    assert "--tip-link: only with a URDF model" in capsys.readouterr().err
    argv = ["identify", str(files / "a.npz"), "--model", str(files / "arm.json")]
    assert main([*argv, "--base-link", "x", "--output", str(tmp_path / "o")]) == 2
    assert "--base-link: only with a URDF model" in capsys.readouterr().err
    with pytest.raises(ValueError, match="tip_link: only for a URDF model"):
        dynid.load_model("ur5", tip_link="tool0")


def test_prior_urdf_with_tip_link(tmp_path, capsys):
    robot = dynid.models.ur5()
    log = tmp_path / "ur5.npz"
    save_log(fourier_log(robot, 2, seconds=2.0), log)
    out = tmp_path / "out"
    argv = ["identify", str(log), "--model", "ur5", "--physical", "--prior", str(UR5_URDF)]
    assert main([*argv, "--output", str(tmp_path / "fail")]) == 2
    assert "--tip-link" in capsys.readouterr().err
    assert main([*argv, "--tip-link", "tool0", "--output", str(out)]) == 0
    data = json.loads((out / "result.json").read_text())
    assert data["physical"]["prior"] == str(UR5_URDF)
    assert yaml.safe_load((out / "run.yaml").read_text())["prior_weight"] == 1e-5
