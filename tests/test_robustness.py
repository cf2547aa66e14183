"""Regression tests for the audit of issue 14 (Python side): structural base parameters, silent
NaN, arguments of the wrong type, result folders that are never mixed or half-written."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
import dynid.cli
from dynid import excitation, io, signal
from dynid.export.output_folder import MARKER, output_folder, write_text_atomic
from dynid.export.result_files import load_result, save_result
from dynid.identification.log_identification import identify_log

# --------------------------------------------------------------------------- item 6


@pytest.mark.parametrize("width", [1e-6, 1e-3, 0.05])
def test_base_parameters_ignore_joint_limits(width: float) -> None:
    """docs/base_parameters.md, "Base parameters": the counts are structural (43/12/39 on the
    LWR-IV) whatever the limits, and the cached beta reproduces Y pi at configurations far outside
    those limits (1e-10 relative)."""
    robot = dynid.models.kuka_lwr4()
    robot.qlim = np.column_stack([np.full(7, 0.3), np.full(7, 0.3 + width)])
    counts = [dynid.base_parameters(robot, kind).count for kind in ("torque", "gravity", "inertia")]
    assert counts == [43, 12, 39]
    base = dynid.base_parameters(robot, "torque")
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.uniform(-3, 3, (3, 50, 7))
    Y = robot.regressor(q, qd, qdd)
    pi = robot.parameter_vector()
    full = Y @ pi
    reduced = base.reduce(Y) @ base.values(robot)
    assert np.max(np.abs(full - reduced)) <= 1e-10 * np.max(np.abs(full))


def test_base_parameter_cache_follows_gravity() -> None:
    """The cache is keyed on what the structure depends on: gravity along a joint axis removes
    gravity base parameters, and the cached result for the old gravity is not reused."""
    robot = dynid.models.planar_2r()
    vertical = dynid.base_parameters(robot, "torque").count
    robot.gravity_vector = (0.0, 0.0, 0.0)
    assert dynid.base_parameters(robot, "torque").count < vertical


# --------------------------------------------------------------------------- item 5


def test_fourier_trajectory_overflow_is_an_error() -> None:
    huge = excitation.FourierTrajectory(
        1.0, np.full((2, 3), 1e308), np.full((2, 3), 1e308), np.zeros(2)
    )
    with pytest.raises(ValueError, match=r"^t: .*overflow"):
        huge.evaluate(np.linspace(0.0, 1.0, 5))
    ordinary = excitation.FourierTrajectory(1.0, np.ones((2, 3)), np.ones((2, 3)), np.zeros(2))
    with pytest.raises(ValueError, match=r"^t: .*overflow"):
        ordinary.evaluate([1e308])
    q, _qd, _qdd = ordinary.evaluate([0.0, 0.5])  # ordinary values still work
    assert np.all(np.isfinite(q)) and q.shape == (2, 2)


def test_differentiate_overflow_is_an_error() -> None:
    with pytest.raises(ValueError, match=r"^x: the derivative overflows"):
        signal.differentiate(np.array([0.0, 1e308, -1e308, 0.0]), fs=1e3)
    x = np.sin(np.linspace(0, 1, 101))
    assert np.all(np.isfinite(signal.differentiate(x, fs=100.0)))


# --------------------------------------------------------------------------- item 9


def _robot() -> dynid.Robot:
    return dynid.models.kuka_lwr4()


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: dynid.least_squares(np.eye(3), np.ones(3), names=5), "names"),
        (lambda: dynid.least_squares(np.eye(3), np.ones(3), names=["a", "b"]), "names"),
        (
            lambda: dynid.identify_from_controller(
                _robot(),
                np.zeros((3, 7)),
                np.zeros((3, 7)),
                np.zeros((3, 7, 7)),
                exclude_gravity_joints=None,
            ),
            "exclude_gravity_joints",
        ),
        (
            lambda: dynid.identify_from_controller(
                "robot", np.zeros((3, 7)), np.zeros((3, 7)), np.zeros((3, 7, 7))
            ),
            "structure",
        ),
        (lambda: dynid.base_parameters("robot"), "robot"),
        (lambda: dynid.VirtualController("x"), "robot"),
        (lambda: dynid.base_parameters(_robot(), "torque", rotor="no"), "rotor"),
        (lambda: setattr(_robot(), "qlim", [[10**400, 1]] * 7), "qlim"),
        (lambda: io.Log(np.arange(5.0), np.zeros((5, 2)), np.zeros((5, 2))).select([7]), "mask"),
        (lambda: _robot().with_payload(1.0, [0, 0, 9e307]), "com"),
        (lambda: _robot().random_configurations(1.7), "count"),
        (lambda: _robot().set_link(True, 1.0, np.zeros(3), np.eye(3)), "i"),
    ],
)
def test_wrong_arguments_are_value_errors_naming_them(call, name: str) -> None:
    with pytest.raises(ValueError, match=f"^{name}: "):
        call()


# --------------------------------------------------------------------------- item 11


@pytest.fixture(scope="module")
def small_result():
    rng = np.random.default_rng(0)
    robot = dynid.models.planar_2r()
    t = np.arange(400) / 100.0
    q = np.column_stack([np.sin(t), np.cos(1.3 * t)])
    qd = np.column_stack([np.cos(t), -1.3 * np.sin(1.3 * t)])
    qdd = np.column_stack([-np.sin(t), -1.69 * np.cos(1.3 * t)])
    tau = robot.rnea(q, qd, qdd) + 1e-3 * rng.normal(size=q.shape)
    return identify_log(io.Log(t, q, tau, qd, qdd), robot)


def test_result_folder_is_not_overwritten_silently(small_result, tmp_path) -> None:
    out = tmp_path / "run"
    save_result(small_result, out, plots=False)
    before = (out / "result.json").read_text()
    (out / "keep.txt").write_text("user file")
    with pytest.raises(ValueError, match=r"^output: .*not empty.*overwrite"):
        save_result(small_result, out, plots=False)
    assert (out / "result.json").read_text() == before
    save_result(small_result, out, plots=False, overwrite=True)
    # replaced as a whole: no file of the previous run is left beside the new one
    assert sorted(p.name for p in out.iterdir()) == sorted([MARKER, "result.json"])
    assert load_result(out).theta.shape == small_result.theta.shape
    with pytest.raises(ValueError, match=r"^output: expected a folder path"):
        save_result(small_result, "", plots=False)


def test_a_failing_write_leaves_the_old_folder_untouched(tmp_path) -> None:
    out = tmp_path / "run"
    with output_folder(out) as staging:
        (staging / "a.json").write_text("{}")
    # The failure must happen inside the staging block, hence more than one statement.
    with pytest.raises(RuntimeError, match="plot failed"), output_folder(out, True) as staging:  # noqa: PT012
        (staging / "a.json").write_text('{"half": ')
        raise RuntimeError("plot failed")
    assert json.loads((out / "a.json").read_text()) == {}
    assert [p.name for p in tmp_path.iterdir()] == ["run"]  # no staging folder left behind


def test_write_text_atomic(tmp_path) -> None:
    target = tmp_path / "x.txt"
    write_text_atomic(target, "one")
    write_text_atomic(target, "two")
    assert target.read_text() == "two"
    assert [p.name for p in tmp_path.iterdir()] == ["x.txt"]


def test_results_get_the_permissions_of_new_files(tmp_path) -> None:
    """What is left in place has the permissions any new folder or file gets under the umask
    (tempfile's would be private), and a rewritten file keeps the permissions it had."""
    import os
    import stat

    previous = os.umask(0o022)
    try:
        with output_folder(tmp_path / "run") as staging:
            (staging / "a.json").write_text("{}")
        write_text_atomic(tmp_path / "x.txt", "one")
    finally:
        os.umask(previous)
    assert stat.S_IMODE((tmp_path / "run").stat().st_mode) == 0o755
    assert stat.S_IMODE((tmp_path / "x.txt").stat().st_mode) == 0o644
    (tmp_path / "x.txt").chmod(0o600)  # made private by its owner: a rewrite keeps that
    write_text_atomic(tmp_path / "x.txt", "two")
    assert stat.S_IMODE((tmp_path / "x.txt").stat().st_mode) == 0o600


# --------------------------------------------------------------------------- item 13


def _chunk_gravity(args: tuple[dynid.Robot, np.ndarray]) -> np.ndarray:
    robot, q = args
    return robot.gravity(q)


def test_robot_pickles_copies_and_compares() -> None:
    import copy
    import pickle

    robot = dynid.models.kuka_lwr4()
    robot.Ia, robot.Fv = np.arange(7.0), np.full(7, 0.5)
    robot.qlim = np.tile([-2.0, 2.0], (7, 1))
    for other in (pickle.loads(pickle.dumps(robot)), copy.copy(robot), copy.deepcopy(robot)):
        assert other == robot and other is not robot and type(other) is type(robot)
        q = np.linspace(-1, 1, 7)
        assert np.array_equal(other.rnea(q, q, q), robot.rnea(q, q, q))
    changed = robot.copy()
    changed.Fs = np.ones(7)
    assert changed != robot
    assert robot != "robot"
    assert np.array_equal(
        pickle.loads(pickle.dumps(robot.gravity))(np.zeros(7)), robot.gravity(np.zeros(7))
    )


def test_results_pickle_and_compare(small_result) -> None:
    import pickle

    base = dynid.base_parameters(dynid.models.kuka_lwr4())
    fit = dynid.least_squares(np.vstack([np.eye(4), np.ones((2, 4))]), np.arange(6.0))
    for value in (base, fit, small_result):
        again = pickle.loads(pickle.dumps(value))
        assert again == value
        assert (again != value) is False
    assert fit != dynid.least_squares(np.vstack([np.eye(4), np.ones((2, 4))]), np.arange(6.0) + 1)


@pytest.mark.parametrize("method", ["fork", "spawn"])
def test_gravity_over_a_process_pool(method: str) -> None:
    """Chunks of a trajectory sent with the robot to worker processes give the same torques as
    one batch call here (exact: the same C++ code on the same numbers)."""
    import multiprocessing

    robot = dynid.models.kuka_lwr4()
    q = robot.random_configurations(400, seed=1)
    chunks = [(robot, part) for part in np.array_split(q, 4)]
    with multiprocessing.get_context(method).Pool(2) as pool:
        parts = pool.map(_chunk_gravity, chunks)
    assert np.array_equal(np.concatenate(parts), robot.gravity(q))


# --------------------------------------------------------------------------- items 8 and 10


def _write_bad_inputs(folder) -> dict[str, str]:
    files = {}
    (folder / "rows300.json").write_text(
        json.dumps({"convention": "standard", "rows": [[0, 0, 0.1, 0]] * 300})
    )
    files["rows300.json"] = "rows: 300 DH rows"
    (folder / "hugeint.json").write_text(
        '{"convention": "standard", "rows": [[1' + "0" * 400 + ", 0, 0, 0]]}"
    )
    files["hugeint.json"] = "rows[0]: expected numbers"
    (folder / "deep.json").write_text(
        '{"convention": "standard", "rows": ' + "[" * 100000 + "]" * 100000 + "}"
    )
    files["deep.json"] = "nesting too deep"
    (folder / "wrongtype.json").write_text('{"convention": 5, "rows": [[0, 0, 0, 0]]}')
    files["wrongtype.json"] = "convention: expected"
    levels = ["a: &a [" + ",".join(["1"] * 9) + "]"]
    for i in range(1, 9):
        previous = "a" if i == 1 else f"l{i - 1}"
        levels.append(f"l{i}: &l{i} [" + ",".join([f"*{previous}"] * 9) + "]")
    (folder / "bomb.yaml").write_text("\n".join(levels) + "\n")
    files["bomb.yaml"] = "expands to more than"
    return files


@pytest.mark.parametrize(
    "name", ["rows300.json", "hugeint.json", "deep.json", "wrongtype.json", "bomb.yaml"]
)
def test_cli_model_file_errors_are_one_line(name, tmp_path, capsys) -> None:
    """Exit 2 and one line naming the file and the field; no traceback, no minutes of work."""
    expected = _write_bad_inputs(tmp_path)[name]
    status = dynid.cli.main(["info", "--model", str(tmp_path / name)])
    err = capsys.readouterr().err.strip()
    assert status == 2
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert name in err and expected in err


def _npz_with_header(folder, shape: str) -> str:
    import io as pyio
    import zipfile

    buffer = pyio.BytesIO()
    np.save(buffer, np.zeros(3))
    member = buffer.getvalue().replace(b"(3,)", shape.encode())
    path = folder / "header.npz"
    with zipfile.ZipFile(path, "w") as archive:
        for key in ("t", "q", "tau"):
            archive.writestr(f"{key}.npy", member)
    return str(path)


def test_cli_log_errors_are_one_line(tmp_path, capsys) -> None:
    import zipfile

    cases = {_npz_with_header(tmp_path, "(99999999999,)"): "its header asks for shape"}
    other = tmp_path / "member.npz"
    with zipfile.ZipFile(other, "w") as archive:
        archive.writestr("t.txt", "hello")
    cases[str(other)] = "member 't.txt' is not a .npy array"
    result = tmp_path / "result.json"
    result.write_text('{"format": "dynid-identification", "version": 1, "model": []}')
    for path, expected in cases.items():
        status = dynid.cli.main(["identify", path, "--output", str(tmp_path / "out")])
        err = capsys.readouterr().err.strip()
        assert status == 2 and len(err.splitlines()) == 1 and expected in err
    status = dynid.cli.main(["validate", str(result), str(other), "--output", str(tmp_path / "v")])
    err = capsys.readouterr().err.strip()
    assert status == 2 and len(err.splitlines()) == 1 and "model" in err


# --------------------------------------------------------------------------- item 12


def _foreign_log(folder, scale: float = 1e9) -> tuple[str, str, io.Log]:
    """The LWR4+ recording written as a ROS-like CSV and NPZ: nanosecond stamps, one column per
    joint named pos_1..pos_7 and effort_1..effort_7 (written out of order on purpose)."""
    reference = io.load_log("tests/data/measurements_1.npz")
    columns = {"stamp": (reference.t - reference.t[0]) * scale}
    for j in (7, 1, 2, 3, 4, 5, 6):  # pos_7 first: the natural order must put it last
        columns[f"pos_{j}"] = reference.q[:, j - 1]
        columns[f"effort_{j}"] = reference.tau[:, j - 1]
    names = list(columns)
    csv_path, npz_path = folder / "ros.csv", folder / "ros.npz"
    np.savetxt(
        csv_path,
        np.column_stack([columns[k] for k in names]),
        delimiter=",",
        header=",".join(names),
        comments="",
        fmt="%.17g",
    )
    np.savez(npz_path, **columns)
    return str(csv_path), str(npz_path), reference


def test_foreign_log_columns_and_time_unit(tmp_path) -> None:
    csv_path, npz_path, reference = _foreign_log(tmp_path)
    mapping = {"t": "stamp", "q": "pos_*", "tau": "effort_*"}
    for path in (csv_path, npz_path):
        log = io.load_log(path, columns=mapping, time_unit="ns")
        assert np.array_equal(log.q, reference.q) and np.array_equal(log.tau, reference.tau)
        assert np.allclose(log.t, reference.t - reference.t[0], rtol=0, atol=1e-12)
        assert abs(log.fs - 200.0) < 1.0
    # Nanosecond stamps read as seconds: refused (issue 22: a warning and a meaningless fit),
    # unless the caller says the unit, then a warning.
    with pytest.raises(ValueError, match=r"sampling rate is 2e-07 Hz.*'ns'.*--time-unit"):
        io.load_log(csv_path, columns=mapping)
    with pytest.warns(UserWarning, match="sampling rate is 2e-07 Hz"):
        io.load_log(csv_path, columns=mapping, time_unit="s")
    with pytest.raises(ValueError, match="columns: nothing matches 'joint_\\*' for q"):
        io.load_log(csv_path, columns={"t": "stamp", "q": "joint_*", "tau": "effort_*"})
    with pytest.raises(ValueError, match=r"^time_unit: "):
        io.load_log(csv_path, columns=mapping, time_unit="hours")
    from dynid.logs.columns import parse_columns

    assert parse_columns("t=stamp, q=pos_*,tau=effort_*") == mapping
    with pytest.raises(ValueError, match=r"^columns: unknown signal 'x'"):
        parse_columns("x=pos_*")


def test_cli_refuses_an_implausible_time_base_and_warns_in_one_line(tmp_path, capsys) -> None:
    """Nanosecond stamps read as seconds: exit 2 with one line saying how (issue 22: a warning,
    a meaningless result and exit 0); with --time-unit s the user insists: a one-line warning."""
    csv_path, _, _ = _foreign_log(tmp_path)
    argv = ["identify", csv_path, "--columns", "t=stamp,q=pos_*,tau=effort_*", "--skip", "4500"]
    assert dynid.cli.main([*argv, "--output", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dynid identify: error: ros.csv: t: the median sampling rate") and (
        err.count("\n") == 1 and "--time-unit" in err
    ), err
    assert not (tmp_path / "out").exists()
    status = dynid.cli.main([*argv, "--time-unit", "s", "--output", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 0
    assert "dynid identify: warning: ros.csv: t: the median sampling rate" in err
    assert "Traceback" not in err and "UserWarning" not in err


def test_result_file_carries_covariance_units_and_version(small_result, tmp_path) -> None:
    path = save_result(small_result, tmp_path / "r", plots=False)
    data = json.loads(path.read_text())
    assert data["version"] == 2 and data["dynid_version"] == dynid.__version__
    assert data["units"]["torque"] == "N m"
    loaded = load_result(path)
    assert np.allclose(loaded.covariance, small_result.covariance, rtol=1e-15, atol=0)
    data["version"] = 99
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=r"version: expected a format version 1\.\.3"):
        load_result(path)


# --------------------------------------------------------------------------- item 15


def test_import_dynid_loads_no_plotting_or_optimisers() -> None:
    """``import dynid`` stays light (its time is measured in bench/, never here): matplotlib,
    SciPy's optimisers and signal processing load only when a function needs them."""
    import subprocess
    import sys

    heavy = ("matplotlib", "scipy.optimize", "scipy.signal", "scipy.ndimage")
    code = (
        "import sys, dynid; dynid.Robot; dynid.models.kuka_lwr4(); "
        f"print(','.join(m for m in {heavy!r} if m in sys.modules))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert loaded == ""


def test_load_model_reads_builtin_names_and_urdf() -> None:
    """The CLI's --model: the new built-in names and a URDF path give the models of
    dynid.models / Robot.from_urdf (exact: the same construction)."""
    from dynid.model.model_files import load_model

    assert load_model("panda") == dynid.models.panda()
    assert load_model("ur5") == dynid.models.ur5()
    urdf = "tests/data/urdf/kuka_lwr4.urdf"
    assert load_model(urdf) == dynid.Robot.from_urdf(urdf)


def test_recursive_least_squares_pickles_its_whole_state() -> None:
    """A pickled estimator continues exactly as the original (same updates, bit for bit) and
    resets to the same initial state; a malformed state is a ValueError naming the field."""
    import pickle

    rng = np.random.default_rng(7)
    rls = dynid.RecursiveLeastSquares(4, forgetting=0.98, initial_covariance=50.0)
    rls.max_variance = 80.0
    for _ in range(30):
        rls.update(rng.normal(size=(3, 4)), rng.normal(size=3))
    again = pickle.loads(pickle.dumps(rls))
    assert again.forgetting == rls.forgetting and again.max_variance == rls.max_variance
    for _ in range(5):
        Y, tau = rng.normal(size=(3, 4)), rng.normal(size=3)
        rls.update(Y, tau)
        again.update(Y, tau)
    assert np.array_equal(again.theta, rls.theta)
    assert np.array_equal(again.covariance, rls.covariance)
    rls.reset()
    again.reset()
    assert np.array_equal(again.covariance, rls.covariance)
    state = list(rls.__getstate__())
    state[5] = np.ones(3)  # D with the wrong length
    blank = dynid.RecursiveLeastSquares.__new__(dynid.RecursiveLeastSquares)
    with pytest.raises(ValueError, match=r"state\.D"):
        blank.__setstate__(tuple(state))
