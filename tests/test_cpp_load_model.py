"""dynid::load_model (cpp/include/dynid/model_file.hpp) against Python, through the program
tests/cpp/test_model_file.cpp built with AddressSanitizer and UndefinedBehaviorSanitizer against
the installed package (tests/cpp_programs.py):

- model files written by Python's save_model (the LWR4, the Panda in modified DH, the UR5, and an
  arm with every field away from its default) and the result folder of `dynid identify
  --physical` on a simulated log: every field the C++ Model holds equals Python's exactly (the
  files hold floats with 17 significant digits, so reading them back is exact), and rnea, M(q)
  and g(q) at random states equal Python's Robot to 1e-12 (relative to the largest entry), with
  no heap allocation in the C++ evaluation loop;
- malformed files (truncated, wrong types, missing fields, NaN, nesting 100000 deep, wrong sizes,
  a least-squares result, ...): each is a std::invalid_argument whose message starts with the
  file and names the field, and Python refuses the same file (but for the two the C++ reader
  refuses on purpose: duplicate keys and YAML);
- the field names the C++ reader knows are Python's (model_files.FIELDS and METADATA).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import dynid
import dynid.cli
from cpp_programs import CppTests
from dynid.export.result_files import load_model_or_result
from dynid.identification.log_identification import LogIdentification
from dynid.logs import save_log
from dynid.model import robot_fields
from dynid.model.model_files import FIELDS, METADATA, save_model
from test_log_identification import fourier_log

STATES = 6


def _every_field_arm() -> dynid.Robot:
    """A 4-joint arm (prismatic joint 3, modified DH) with no field at its default."""
    rng = np.random.default_rng(11)
    dh = np.column_stack(
        [
            rng.uniform(0, 0.3, 4),
            rng.choice([-1.0, 1.0], 4) * np.pi / 2,
            [0.3, 0.0, 0.2, 0.1],
            0.1 * np.arange(4),
        ]
    )
    robot = dynid.Robot.from_dh(dh, "RRPR", "modified", gravity=(0.1, -0.2, -9.7))
    robot.name = "every field"
    for i in range(4):
        inertia = np.diag(rng.uniform(0.01, 0.02, 3))
        robot.set_link(i, 1.0 + i, rng.uniform(-0.05, 0.05, 3), inertia)
    base = np.eye(4)
    base[:3, :3] = [[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]  # a quarter turn about z
    base[:3, 3] = [0.1, 0.2, 0.3]
    robot.base = base
    tool = np.eye(4)
    tool[2, 3] = 0.12
    robot.tool = tool
    robot.joint_names = ["shoulder", "elbow", "slide", "wrist"]
    robot.link_names = ["upper_arm", "forearm", "carriage", "hand"]
    robot.velocity_limits = [2.0, np.inf, 0.5, 3.0]  # inf: a null in the file
    robot.effort_limits = [150.0, 80.0, 400.0, np.inf]
    robot.qlim = np.array([[-2.0, 2.0], [-1.5, 1.0], [-0.1, 0.4], [-3.0, 3.0]])
    robot.Ia, robot.Fv, robot.Fs = rng.uniform(0.1, 0.5, (3, 4))
    transmission = np.eye(4)
    transmission[3, 2] = 0.5  # a coupled wrist
    robot.transmission = transmission
    robot.gear_ratios = np.array([100.0, -80.0, 50.0, 30.0])
    robot.joint_offsets = np.array([0.1, 0.0, -0.02, 0.3])
    return robot


MODELS = {
    "kuka_lwr4": dynid.models.kuka_lwr4,
    "panda": dynid.models.panda,
    "ur5": dynid.models.ur5,
    "every_field": _every_field_arm,
}


@pytest.fixture(scope="module")
def identified(tmp_path_factory) -> Path:
    """`dynid identify --physical` on a simulated UR5 log (exact torques of a 3-harmonic
    trajectory): the result folder."""
    folder = tmp_path_factory.mktemp("identified")
    robot = dynid.models.ur5()
    save_log(fourier_log(robot, 3, seconds=10.0), folder / "train.npz")
    argv = ["identify", str(folder / "train.npz"), "--model", "ur5", "--rotor", "--friction"]
    assert dynid.cli.main([*argv, "--physical", "--output", str(folder / "physical")]) == 0
    assert dynid.cli.main([*argv, "--output", str(folder / "least_squares")]) == 0
    return folder


def _evaluate(cpp_tests: CppTests, source: Path, robot: dynid.Robot, folder: Path, seed: int):
    """Run `model_file eval` on ``source`` at random states; check its fields and dynamics."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(robot.qlim[:, 0], robot.qlim[:, 1], (STATES, robot.n))
    qd, qdd = rng.normal(scale=1.5, size=(2, STATES, robot.n))
    states = folder / f"states_{seed}.txt"
    rows = np.hstack([q, qd, qdd])
    states.write_text(f"{STATES}\n" + "\n".join(" ".join(repr(float(x)) for x in r) for r in rows))
    output = cpp_tests.run("model_file", "eval", str(source), str(states))
    lines = output.splitlines()

    fields = {}
    for line in lines:
        if line.startswith("field "):
            _, key, *values = line.split(" ")
            fields[key] = values
    assert list(fields) == list(FIELDS), output
    for f in robot_fields.FIELDS:
        expected = getattr(robot, f.attribute)
        got = fields[f.file_key]
        if f.kind == "text":
            assert " ".join(got) == str(expected), f.key
        elif f.kind == "names":
            assert tuple(got) == tuple(expected), f.key
        else:  # exactly: the file holds every float to 17 digits and from_chars reads it back
            assert np.array_equal(np.array(got, dtype=float), np.ravel(expected)), f.key

    def numbers(label: str) -> np.ndarray:
        return np.array([line.split()[1:] for line in lines if line.split()[0] == label], float)

    for label, expected in (
        ("rnea", robot.rnea(q, qd, qdd)),
        ("M", robot.mass_matrix(q).reshape(STATES, -1)),
        ("g", robot.gravity(q)),
    ):
        got = numbers(label)
        assert got.shape == expected.shape, label
        scale = max(1.0, float(np.max(np.abs(expected))))
        assert np.max(np.abs(got - expected)) <= 1e-12 * scale, label
    assert f"allocations: 0 in {STATES} states" in output, output


@pytest.mark.parametrize("name", MODELS)
def test_model_files_written_by_python_load_in_cpp(
    cpp_tests: CppTests, tmp_path: Path, name: str
) -> None:
    robot = MODELS[name]()
    if name == "every_field":  # the file holds every field, none at its default
        fresh = robot_fields.defaults(robot)
        assert not any(robot_fields.is_default(robot, f, fresh) for f in robot_fields.SETTABLE)
    path = save_model(robot, tmp_path / f"{name}.json")
    _evaluate(cpp_tests, path, robot, tmp_path, seed=len(name))


def test_identified_model_loads_in_cpp(cpp_tests: CppTests, identified: Path, tmp_path) -> None:
    """The result folder and its result.json give Python's identified robot (load_result(..).robot),
    which is not the simulated UR5's (its parameters are identified, not copied)."""
    folder = identified / "physical"
    robot = dynid.load_result(folder).robot
    assert not np.array_equal(robot.params, dynid.models.ur5().params)
    _evaluate(cpp_tests, folder, robot, tmp_path, seed=1)
    _evaluate(cpp_tests, folder / "result.json", robot, tmp_path, seed=2)


def test_cpp_reader_knows_pythons_fields(cpp_tests: CppTests) -> None:
    output = cpp_tests.run("model_file", "fields").split()
    assert output[1::2][: len(FIELDS)] == list(FIELDS)
    assert output[0::2] == ["field"] * len(FIELDS) + ["metadata"] * len(METADATA)
    assert output[1::2][len(FIELDS) :] == list(METADATA)


def _malformed(folder: Path, identified: Path) -> list[tuple[Path, str, bool]]:
    """(file, the expected message after "FILE: " (a regular expression), whether Python refuses
    it too)."""
    model_path = save_model(dynid.models.kuka_lwr4(), folder / "lwr4.json")
    text = model_path.read_text()
    model = json.loads(text)
    result = json.loads((identified / "physical" / "result.json").read_text())
    cases: list[tuple[Path, str, bool]] = []

    def add(name: str, content: str | bytes | dict, expected: str, python: bool = True) -> None:
        path = folder / name
        if name.endswith("result.json"):
            path.parent.mkdir()
        if isinstance(content, dict):
            content = json.dumps(content)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
        cases.append((path, expected, python))

    def changed(base: dict, path: str, value) -> dict:
        data = json.loads(json.dumps(base))
        *parents, last = path.split("/")
        target = data
        for key in parents:
            target = target[int(key)] if isinstance(target, list) else target[key]
        if value is KeyError:
            del target[last]
        elif isinstance(target, list):
            target[int(last)] = value
        else:
            target[last] = value
        return data

    add("truncated.json", text[: len(text) // 2], r"[\w.\[\]]+: not valid JSON: unexpected end")
    add("truncated_early.json", text[:40], r"\w+: not valid JSON: unexpected end")
    add(
        "params_text.json",
        changed(model, "params", "zeros"),
        r"params: expected numbers of shape \(7, 10\), got 'zeros'",
    )
    add("row_text.json", changed(model, "rows/3", "x"), r"rows\[3\]: expected an object")
    add("name_number.json", changed(model, "name", 7), r"name: expected a string, got 7")
    add(
        "alpha_bool.json",
        changed(model, "rows/2/alpha", True),
        r"rows\[2\]\.alpha: expected a finite number, got true",
    )
    add("no_rows.json", changed(model, "rows", KeyError), r"rows: missing")
    add("no_convention.json", changed(model, "convention", KeyError), r"convention: missing")
    add("row_without_d.json", changed(model, "rows/2/d", KeyError), r"rows\[2\]: missing 'd'")
    add("nan.json", changed(model, "params/1/0", float("nan")), r"params: contains NaN or inf")
    add(
        "inf_row.json",
        changed(model, "rows/0/theta", float("inf")),
        r"rows\[0\]\.theta: expected a finite number",
    )
    huge = json.dumps(changed(model, "Fv/0", 12345.5)).replace("12345.5", "1e999")
    add("huge.json", huge, r"Fv: contains NaN or inf")
    deep = '{"notes": ' + "[" * 100000 + "]" * 100000 + ", " + text.strip()[1:]
    add("deep.json", deep, r"notes(\[0\])+: not valid JSON: nested more than 256 levels deep")
    add(
        "short_Ia.json",
        changed(model, "Ia", [0.1] * 6),
        r"Ia: expected numbers of shape \(7,\), got shape \(6,\)",
    )
    add(
        "qlim_3.json",
        changed(model, "qlim", [[-1, 0, 1]] * 7),
        r"qlim: expected numbers of shape \(7, 2\), got shape \(7, 3\)",
    )
    add(
        "ragged.json",
        changed(model, "params/4", [1.0] * 9),
        r"params: expected numbers of shape \(7, 10\), got a list of 7",
    )
    eight = changed(model, "joint_types", "R" * 8)
    eight["rows"].append([0.0, 0.0, 0.1, 0.0])
    add("eight_rows.json", eight, r"qlim: expected numbers of shape \(8, 2\), got shape \(7, 2\)")
    add(
        "unknown.json",
        changed(model, "gravity_vector", [0, 0, -9.81]),
        r"unknown field\(s\) 'gravity_vector'; expected name, convention",
    )
    add(
        "qlim_order.json",
        changed(model, "qlim/2", [1.0, -1.0]),
        r"qlim: every lower limit must be below its upper limit",
    )
    add("names.json", changed(model, "joint_names", ["a"] * 7), r"joint_names: 'a' names joints")
    add(
        "latin1.json",
        text.replace('"name": "', '"name": "\xe9', 1).encode("latin-1"),
        r"not valid JSON: not UTF-8 text",
    )
    add(
        "duplicate.json",
        text.replace('"name":', '"name": "x", "name":', 1),
        r"name: not valid JSON: the key 'name' appears twice",
        False,
    )
    add("model.txt", text, r"unknown extension '\.txt'")
    add(
        "model.yaml",
        "convention: standard\nrows: [[0, 0, 0.3, 0]]\n",
        r"YAML model files are read by Python only; convert it to JSON",
        False,
    )
    big = folder / "big.json"
    with big.open("wb") as stream:
        stream.truncate(17 * 2**20)
    cases.append((big, r"17825792 bytes is more than a model or result file can need", True))
    cases.append((folder / "absent.json", "", True))  # "path: no such file: ..." (checked below)

    add(
        "v4/result.json",
        changed(result, "version", 4),
        r"version: expected a format version 1\.\.3",
    )
    add(
        "v2.0/result.json",
        changed(result, "version", 2.0),
        r"version: expected a format version 1\.\.3",
    )
    add(
        "format/result.json",
        changed(result, "format", "dynid-model"),
        r"format: expected 'dynid-identification'",
    )
    add(
        "model_list/result.json",
        changed(result, "model", []),
        r"model: expected an object, got a list",
    )
    add(
        "model_params/result.json",
        changed(result, "model/params/2", [1.0] * 3),
        r"model: params: expected numbers of shape \(6, 10\)",
    )
    add(
        "inconsistent/result.json",
        changed(result, "model/params/1/0", -1.0),
        r"model: a physically consistent result whose parameters are not physically consistent",
    )
    add(
        "truncated/result.json",
        (identified / "physical" / "result.json").read_text()[:2000],
        r"[\w.\[\]]+: not valid JSON: unexpected end",
    )
    cases.append(
        (
            identified / "least_squares",
            r"a least-squares result \(no 'physical' entry\) holds base parameters .*--physical",
            True,
        )
    )
    return cases


def _python_model(path: Path) -> dynid.Robot:
    loaded = load_model_or_result(path)
    if isinstance(loaded, LogIdentification):
        if loaded.physical is None:
            raise ValueError("a least-squares result holds no model")
        return loaded.robot
    return loaded


def test_malformed_files_name_the_field(cpp_tests: CppTests, identified: Path, tmp_path) -> None:
    cases = _malformed(tmp_path, identified)
    output = cpp_tests.run("model_file", "error", *(str(path) for path, _, _ in cases))
    lines = output.splitlines()
    assert len(lines) == len(cases), output
    for (path, expected, python), line in zip(cases, lines):
        shown, outcome = line.split("\t", 1)
        assert shown == str(path)
        assert outcome.startswith("refused: "), line
        message = outcome[len("refused: ") :]
        if expected == "":
            assert message == f"path: no such file: {path}", message
        else:
            file = path / "result.json" if path.is_dir() else path
            assert message.startswith(f"{file}: "), message
            assert re.match(expected, message[len(f"{file}: ") :]), (expected, message)
        if python:  # Python refuses it too (a least-squares result is no model)
            with pytest.raises((ValueError, FileNotFoundError)):
                _python_model(path)
