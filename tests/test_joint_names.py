"""Robot.joint_names (issue 20, item 1): q1..qn by default, the URDF's joint names (compared with
Pinocchio's reading of the same file), kept by model files and result files, old files without
them still load, ``dynid info`` shows them, bad names are refused naming ``joint_names``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result
from dynid.model.model_files import load_model, model_from_dict, model_to_dict, save_model

EXAMPLES = Path(__file__).parent.parent / "examples"
OLD_RESULT = Path(__file__).parent / "data" / "results_before_blocks" / "symmetric.json"
NAMES = ("base_yaw", "shoulder", "elbow")


def _arm(**kwargs) -> dynid.Robot:
    dh = [[0.0, np.pi / 2, 0.3, 0.0], [0.4, 0.0, 0.0, 0.0], [0.3, 0.0, 0.0, 0.0]]
    return dynid.Robot.from_dh(dh, **kwargs)


def test_default_is_q1_to_qn() -> None:
    assert _arm().joint_names == ("q1", "q2", "q3")
    assert dynid.models.planar_2r().joint_names == ("q1", "q2")


def test_from_dh_and_the_property() -> None:
    robot = _arm(joint_names=list(NAMES))
    assert robot.joint_names == NAMES and isinstance(robot.joint_names, tuple)
    robot.joint_names = ("a", "b", "c")
    assert robot.joint_names == ("a", "b", "c")
    assert robot.copy().joint_names == ("a", "b", "c")
    assert robot != _arm(joint_names=list(NAMES))


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (("a", "b"), "joint_names: expected 3 names, got 2"),
        (("a", "b", "c", "d"), "joint_names: expected 3 names, got 4"),
        (("a", "", "c"), "joint_names: name 1 is empty"),
        (("a", "b", "a"), "joint_names: 'a' names joints 0 and 2"),
        ("abc", "joint_names: expected a sequence of strings"),
        (("a", 2, "c"), "joint_names: expected strings, got 2"),
        (None, "joint_names: expected a sequence of strings"),
    ],
)
def test_bad_names_are_refused(value, message) -> None:
    robot = _arm(joint_names=NAMES)
    with pytest.raises(ValueError, match=message):
        robot.joint_names = value
    assert robot.joint_names == NAMES  # unchanged
    if value is not None:
        with pytest.raises(ValueError, match=message):
            _arm(joint_names=value)


@pytest.mark.parametrize(
    ("relative", "base_link", "tip_link"),
    [
        ("ur_description/urdf/ur5_robot.urdf", None, "tool0"),
        ("panda_description/urdf/panda.urdf", None, "panda_link8"),
        ("talos_data/robots/talos_left_arm.urdf", "arm_left_1_link", "wrist_left_ft_tool_link"),
    ],
)
def test_urdf_joint_names_are_pinocchios(relative, base_link, tip_link) -> None:
    """The chain's movable joints, base to tip, by the names Pinocchio reads from the file."""
    pytest.importorskip("pinocchio")
    from pinocchio_urdf import example_robot_data, reference

    text = example_robot_data(relative).read_text(encoding="utf-8")
    robot = dynid.Robot.from_urdf(text, base_link, tip_link, check_physical=False)
    ref = reference(text, base_link, tip_link)
    assert robot.joint_names == tuple(ref.model.names[j] for j in ref.joints)
    assert len(robot.joint_names) == robot.n


def test_builtin_urdf_models_keep_their_names() -> None:
    assert dynid.models.ur5().joint_names == (
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    )


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_model_files_keep_the_names(suffix, tmp_path) -> None:
    if suffix == ".yaml":
        pytest.importorskip("yaml")
    path = save_model(_arm(joint_names=NAMES), tmp_path / f"arm{suffix}")
    assert load_model(path).joint_names == NAMES
    text = path.read_text()
    assert all(name in text for name in NAMES)
    # the defaults are left out, as base and tool are (files from before keep their content)
    assert "joint_names" not in model_to_dict(_arm())


def test_old_files_without_names_load() -> None:
    """examples/*.json and a result.json written before joint_names existed: q1..qn."""
    robot = load_model(EXAMPLES / "kuka_lwr4_dh.json")
    assert robot.joint_names == tuple(f"q{i}" for i in range(1, 8))
    assert load_result(OLD_RESULT).robot.joint_names == ("q1", "q2")


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ([1, 2, 3], "joint_names: expected a list of 3 strings"),
        ("a b c", "joint_names: expected a list of 3 strings"),
        (["a", "b"], "joint_names: expected 3 names, got 2"),
        (["a", "a", "b"], "joint_names: 'a' names joints 0 and 1"),
    ],
)
def test_bad_names_in_a_model_file(value, message) -> None:
    data = model_to_dict(_arm())
    data["joint_names"] = value
    with pytest.raises(ValueError, match=message):
        model_from_dict(json.loads(json.dumps(data)))


def test_info_shows_the_names(tmp_path, capsys) -> None:
    path = save_model(_arm(joint_names=NAMES), tmp_path / "arm.json")
    assert main(["info", "--model", str(path)]) == 0
    assert "  joint names: base_yaw shoulder elbow\n" in capsys.readouterr().out
    assert main(["info", "--model", str(save_model(_arm(), tmp_path / "plain.json"))]) == 0
    assert "joint names" not in capsys.readouterr().out  # the default q1..qn: left out
