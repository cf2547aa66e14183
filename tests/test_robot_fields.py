"""The robot's fields listed once (dynid.model.robot_fields; issue 19, item 2): copies, pickles,
equality, model files, result files, ``dynid info`` and the base-parameter cache cover exactly the
table's fields.

A robot with every field away from its default goes through each of them and must come back with
the values written out below (exact comparison: 17-digit files and pickles are exact), and every
derived function must notice a change of each field alone. A field added to the table without a
value here fails ``test_every_field_has_a_value_to_try``.
"""

from __future__ import annotations

import copy
import json
import pickle
from typing import Any

import numpy as np
import pytest

import dynid
from dynid.export.result_files import result_from_dict, result_to_dict
from dynid.export.summary import model_summary
from dynid.identification.log_identification import identify_log
from dynid.model import robot_fields
from dynid.model.base_parameters import base_parameters
from dynid.model.link_frames import express_in_frames_of
from dynid.model.model_files import load_model, model_from_dict, model_to_dict, save_model


def _pose(angle: float, offset: list[float]) -> np.ndarray:
    """Rotation about z by ``angle``, then the translation ``offset``."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array(
        [[c, -s, 0, offset[0]], [s, c, 0, offset[1]], [0, 0, 1, offset[2]], [0, 0, 0, 1]]
    )


def _links() -> np.ndarray:
    """Physically consistent standard parameters of three links (Steiner from the CoM)."""
    rows = []
    for i, (m, com) in enumerate([(2.0, [0.1, -0.05, 0.2]), (1.5, [0.03, 0.1, -0.1]),
                                  (0.8, [0.05, 0.02, 0.03])]):  # fmt: skip
        c = np.array(com)
        inertia = np.diag([0.03, 0.04, 0.05]) * (i + 1) + 0.002 * (np.ones((3, 3)) - np.eye(3))
        origin = inertia + m * (c @ c * np.eye(3) - np.outer(c, c))
        rows.append([m, *(m * c), *origin[0], *origin[1, 1:], origin[2, 2]])
    return np.array(rows)


#: The constructor's fields: a modified-DH table with a prismatic joint.
STRUCTURE: dict[str, Any] = {
    "convention": "modified",
    "joint_types": "RPR",
    "dh": np.array([[0.0, 0.0, 0.3, 0.1], [0.2, -np.pi / 2, 0.4, 0.0], [0.1, np.pi / 2, 0.0, 0.2]]),
}
#: Another value of each constructor field.
OTHER_STRUCTURE: dict[str, Any] = {
    "convention": "standard",
    "joint_types": "RRR",
    "dh": STRUCTURE["dh"] + 0.01,
}
#: A value away from the default for every other field (in each element where it can be).
VALUES: dict[str, Any] = {
    "name": "every field",
    "joint_names": ("shoulder", "slider", "wrist"),
    "link_names": ("upper", "carriage", "hand"),
    "gravity": np.array([0.5, -1.0, -9.7]),
    "base": _pose(0.3, [0.1, 0.2, 0.3]),
    "tool": _pose(-0.7, [0.02, 0.05, 0.12]),
    "qlim": np.array([[-1.0, 2.0], [-0.25, 0.5], [-2.5, 0.5]]),
    "velocity_limits": np.array([2.0, 0.5, 3.0]),
    "effort_limits": np.array([80.0, 300.0, 12.0]),
    "params": _links(),
    "Ia": np.array([0.1, 0.2, 0.3]),
    "Fv": np.array([1.5, 2.5, 3.5]),
    "Fs": np.array([0.4, 0.5, 0.6]),
    "transmission": np.array([[1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [-0.2, 0.3, 1.0]]),
    "gear_ratios": np.array([100.0, -50.5, 32.0]),
    "joint_offsets": np.array([0.25, -1.5, 0.125]),
}
#: The defaults of a 3-joint RPR arm, written out (docs/conventions.md; docs/models.md).
DEFAULTS: dict[str, Any] = {
    "name": "3-dof arm",
    "joint_names": ("q1", "q2", "q3"),
    "link_names": ("link1", "link2", "link3"),
    "gravity": np.array([0.0, 0.0, -9.81]),
    "base": np.eye(4),
    "tool": np.eye(4),
    "qlim": np.array([[-np.pi, np.pi], [-1.0, 1.0], [-np.pi, np.pi]]),
    "velocity_limits": np.full(3, np.inf),
    "effort_limits": np.full(3, np.inf),
    "params": np.zeros((3, 10)),
    "Ia": np.zeros(3),
    "Fv": np.zeros(3),
    "Fs": np.zeros(3),
    "transmission": np.eye(3),
    "gear_ratios": np.ones(3),
    "joint_offsets": np.zeros(3),
}


def _robot(values: dict[str, Any] = VALUES, **structure: Any) -> dynid.Robot:
    robot = dynid.Robot(**{**STRUCTURE, **structure})
    for field in robot_fields.SETTABLE:
        if field.key in values:
            setattr(robot, field.attribute, values[field.key])
    return robot


def _without(key: str) -> dict[str, Any]:
    return {k: v for k, v in VALUES.items() if k != key}


def _expect(robot: dynid.Robot, values: dict[str, Any]) -> None:
    """``robot`` holds STRUCTURE, ``values`` and the defaults for the rest, exactly."""
    for field in robot_fields.FIELDS:
        expected = {**DEFAULTS, **values, **STRUCTURE}[field.key]
        actual = getattr(robot, field.attribute)
        if isinstance(expected, str):
            assert actual == expected, field.key
        else:
            np.testing.assert_array_equal(actual, expected, err_msg=field.key)


def test_every_field_has_a_value_to_try() -> None:
    keys = {f.key for f in robot_fields.FIELDS}
    assert set(STRUCTURE) | set(VALUES) == keys
    assert set(STRUCTURE) == set(OTHER_STRUCTURE) == {f.key for f in robot_fields.STRUCTURE}
    assert set(DEFAULTS) == set(VALUES)
    for key, value in VALUES.items():  # away from the default in each element that can differ
        default = DEFAULTS[key]
        if key in ("base", "tool", "transmission"):
            assert not np.array_equal(value, default), key
        elif isinstance(value, str):
            assert value != default
        else:
            assert np.all(np.asarray(value) != default), key
    _expect(dynid.Robot(**STRUCTURE), {})  # the defaults above are the model's
    _expect(_robot(), VALUES)  # and every value is accepted as it is


@pytest.mark.parametrize(
    "round_trip",
    [
        lambda r: pickle.loads(pickle.dumps(r)),
        copy.copy,
        copy.deepcopy,
        lambda r: r.copy(),
        lambda r: model_from_dict(json.loads(json.dumps(model_to_dict(r)))),
    ],
    ids=["pickle", "copy.copy", "copy.deepcopy", "Robot.copy", "model_to_dict"],
)
def test_round_trips_keep_every_field(round_trip) -> None:
    robot = _robot()
    again = round_trip(robot)
    assert again is not robot and type(again) is dynid.Robot
    _expect(again, VALUES)


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_model_files_keep_every_field(suffix, tmp_path) -> None:
    if suffix == ".yaml":
        pytest.importorskip("yaml")
    path = save_model(_robot(), tmp_path / f"arm{suffix}")
    _expect(load_model(path), VALUES)


def test_model_files_leave_out_only_the_defaults_flagged_so() -> None:
    written = model_to_dict(_robot(DEFAULTS))
    omitted = {f.file_key for f in robot_fields.FIELDS if f.omit_default}
    assert omitted == {
        "joint_names",
        "link_names",
        "velocity_limits",
        "effort_limits",
        "base",
        "tool",
        "transmission",
        "gear_ratios",
        "joint_offsets",
    }
    assert set(written) == {"format"} | {f.file_key for f in robot_fields.FIELDS} - omitted
    assert set(model_to_dict(_robot())) == {"format"} | {f.file_key for f in robot_fields.FIELDS}


def test_unknown_limits_are_null_in_files_and_never_zero(tmp_path) -> None:
    """A limit the model does not know is inf, null in model files (JSON has no infinity), and
    a value <= 0 or NaN is refused naming the field."""
    robot = _robot()
    robot.velocity_limits = [2.0, np.inf, 3.0]
    data = json.loads(json.dumps(model_to_dict(robot)))
    assert data["velocity_limits"] == [2.0, None, 3.0]
    np.testing.assert_array_equal(model_from_dict(data).velocity_limits, [2.0, np.inf, 3.0])
    for bad in ([2.0, 0.0, 3.0], [2.0, -1.0, 3.0], [2.0, np.nan, 3.0]):
        with pytest.raises(ValueError, match="velocity_limits: joint 2"):
            robot.velocity_limits = bad
    with pytest.raises(ValueError, match=r"effort_limits: expected shape \(3,\)"):
        robot.effort_limits = [1.0, 2.0]
    data["effort_limits"] = [1.0, "x", 2.0]
    with pytest.raises(ValueError, match=r"effort_limits\[1\]: expected a finite number"):
        model_from_dict(data)


@pytest.fixture(scope="module")
def fitted() -> Any:
    """A least-squares fit of the every-field robot on an exciting log (no noise)."""
    robot = _robot()
    t = np.arange(600) / 100.0
    w = np.array([1.0, 1.7, 2.3])
    q = 0.4 * np.sin(w * t[:, None])
    qd = 0.4 * w * np.cos(w * t[:, None])
    qdd = -0.4 * w**2 * np.sin(w * t[:, None])
    tau = robot.rnea(q, qd, qdd)
    return identify_log(dynid.Log(t, q, tau, qd, qdd), robot, rotor=True, friction=True)


def test_result_files_keep_every_field_but_the_identified(fitted) -> None:
    """A least-squares result's record keeps everything but what identification estimates (the
    values the model had were a prior); a physically consistent result's record (the whole model)
    keeps every field."""
    identified = {f.key for f in robot_fields.FIELDS if f.identified}
    assert identified == {"params", "Ia", "Fv", "Fs"}
    loaded = result_from_dict(json.loads(json.dumps(result_to_dict(fitted))))
    _expect(loaded.robot, {k: v for k, v in VALUES.items() if k not in identified})
    whole = copy.copy(fitted)
    whole.model, whole._robot = model_to_dict(_robot()), None
    _expect(result_from_dict(json.loads(json.dumps(result_to_dict(whole)))).robot, VALUES)


@pytest.mark.parametrize("field", robot_fields.FIELDS, ids=lambda f: f.key)
def test_equality_notices_each_field(field) -> None:
    robot = _robot()
    assert robot == _robot()
    assert (robot != _robot()) is False
    if field.settable:
        other = _robot(_without(field.key))
    else:
        other = _robot(**{field.key: OTHER_STRUCTURE[field.key]})
    assert robot != other and other != robot


@pytest.mark.parametrize("field", robot_fields.FIELDS, ids=lambda f: f.key)
def test_dynid_info_shows_each_field(field) -> None:
    text = model_summary(_robot())
    if field.settable:
        other = _robot(_without(field.key))
    else:
        other = _robot(**{field.key: OTHER_STRUCTURE[field.key]})
    assert model_summary(other) != text


@pytest.mark.parametrize("field", robot_fields.SETTABLE, ids=lambda f: f.key)
def test_base_parameter_cache_follows_each_field(field) -> None:
    """After a field changes, the cached structure is the one computed afresh on a copy (whose
    cache is empty): the cache key holds every field the structure depends on."""
    robot = _robot()
    kinds = [("torque", True, True), ("gravity", False, False), ("inertia", True, False)]
    for kind, rotor, friction in kinds:
        base_parameters(robot, kind, rotor=rotor, friction=friction)  # cached
    setattr(robot, field.attribute, DEFAULTS[field.key])
    for kind, rotor, friction in kinds:
        cached = base_parameters(robot, kind, rotor=rotor, friction=friction)
        fresh = base_parameters(robot.copy(), kind, rotor=rotor, friction=friction)
        np.testing.assert_array_equal(cached.independent, fresh.independent)
        np.testing.assert_array_equal(cached.beta, fresh.beta)


def test_rigid_body_and_link_frames_move_the_drive_group() -> None:
    robot = _robot()
    drive = {f.key for f in robot_fields.FIELDS if f.group == "drive"}
    assert drive == {"Ia", "Fv", "Fs", "transmission"}
    _expect(robot.rigid_body(), _only_not(drive))
    same_arm = _robot(_only_not(drive))  # the same DH table: the parameters carry over as they are
    moved = express_in_frames_of(robot, same_arm)
    np.testing.assert_allclose(moved.params, robot.params, rtol=0, atol=1e-12)
    for key in drive:
        np.testing.assert_array_equal(getattr(moved, key), VALUES[key], err_msg=key)


def _only_not(keys: set[str]) -> dict[str, Any]:
    return {k: v for k, v in VALUES.items() if k not in keys}


def test_table_is_well_formed() -> None:
    keys = [f.key for f in robot_fields.FIELDS]
    assert len(set(keys)) == len(keys)
    assert [f.key for f in robot_fields.STRUCTURE] == ["convention", "joint_types", "dh"]
    with pytest.raises(ValueError, match="field 'x'"):
        robot_fields.RobotField("x", "array", (), "nowhere", "", "title")
    with pytest.raises(ValueError, match="group"):
        robot_fields.copy_group(_robot(), _robot(), "structure")


def test_table_lists_every_property_of_the_model() -> None:
    """The binding's Model properties are the table's fields (and n): a field added to the C++
    Model but not to the table would be missed by copies, pickles and files."""
    from dynid import _core

    properties = {k for k, v in vars(_core.Model).items() if isinstance(v, property)}
    settable = {k for k in properties if getattr(_core.Model, k).fset is not None}
    assert properties == {f.attribute for f in robot_fields.FIELDS} | {"n"}
    assert settable == {f.attribute for f in robot_fields.SETTABLE}
