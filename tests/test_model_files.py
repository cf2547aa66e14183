"""Model files (dynid.model.model_files): round trips, the LWR4+ tables against Pinocchio."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.model.model_files import BUILTIN_MODELS, load_model, model_from_dict, save_model

DATA = Path(__file__).parent / "data"
EXAMPLES = Path(__file__).parent.parent / "examples"


def _same_robot(a: dynid.Robot, b: dynid.Robot) -> None:
    """Exactly the same table, transforms, limits, parameters and drive terms."""
    assert (a.convention, a.joint_types, a.name) == (b.convention, b.joint_types, b.name)
    for key in ("dh", "gravity_vector", "base", "tool", "qlim", "params", "Ia", "Fv", "Fs"):
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key), err_msg=key)


@pytest.mark.parametrize("name", sorted(BUILTIN_MODELS))
def test_builtin_models_round_trip_exactly(name, tmp_path):
    robot = load_model(name)
    _same_robot(robot, BUILTIN_MODELS[name]())
    path = save_model(robot, tmp_path / f"{name}.json")
    again = load_model(path)
    _same_robot(robot, again)
    q = robot.random_configurations(4, seed=1)  # and so the same dynamics, bit for bit
    np.testing.assert_array_equal(robot.rnea(q, q, q), again.rnea(q, q, q))


def test_modified_convention_with_tool_round_trips(tmp_path):
    robot = dynid.models.planar_2r(convention="modified")  # rows in a_prev/alpha_prev, a tool
    text = save_model(robot, tmp_path / "p.json").read_text()
    assert '"a_prev"' in text and '"tool"' in text
    _same_robot(robot, load_model(tmp_path / "p.json"))


@pytest.mark.parametrize("kind", ["standard", "modified"])
def test_lwr4plus_tables_of_the_data_reproduce_pinocchio(kind, tmp_path):
    """The rows of tests/data/kuka_lwr4_dh.json, copied verbatim (theta_offset; a_prev and
    alpha_prev in modified DH) with the URDF parameters re-expressed in those frames, give
    pinocchio's RNEA on the URDF (an independent implementation) to 1e-10 N m."""
    source = json.loads((DATA / "kuka_lwr4_dh.json").read_text())
    urdf = "kuka_lwr4.urdf (HEAD)"
    model = {
        "convention": kind,
        "joint_types": source["dh"][kind]["joint_types"],
        "gravity": source["check_sample"][urdf]["gravity"],
        "rows": source["dh"][kind]["rows"],
        "params": source["params"][urdf][kind],
    }
    (tmp_path / "lwr.json").write_text(json.dumps(model))
    robot = load_model(tmp_path / "lwr.json")
    sample = source["check_sample"][urdf]
    tau = robot.rnea(sample["q"], sample["qd"], sample["qdd"])
    np.testing.assert_allclose(tau, sample["tau_rnea"], rtol=0, atol=1e-10)
    np.testing.assert_allclose(robot.mass_matrix(sample["q"]), sample["M"], rtol=0, atol=1e-10)


def test_examples_load():
    paper = load_model(EXAMPLES / "kuka_lwr4_dh.json")
    builtin = dynid.models.kuka_lwr4()
    # The example file stores the built-in model's standard parameters, which the model computes
    # from its physical form (Steiner): equal up to the last bit of that arithmetic.
    np.testing.assert_allclose(paper.params, builtin.params, rtol=1e-14, atol=0)
    paper.params = builtin.params
    _same_robot(paper, builtin)
    standard = load_model(EXAMPLES / "kuka_lwr4plus_dh.json")
    modified = load_model(EXAMPLES / "kuka_lwr4plus_modified_dh.json")
    assert standard.dh[0, 2] == 0.3105 and standard.dh[6, 2] == 0.078
    np.testing.assert_array_equal(standard.dh[:, 1], paper.dh[:, 1])  # the paper's alphas
    q = standard.random_configurations(20, seed=2)
    # the two conventions describe the same arm: same flange pose (frame 7 at the flange)
    np.testing.assert_allclose(standard.fkine(q), modified.fkine(q), rtol=0, atol=1e-12)


def test_rows_as_lists_and_defaults():
    robot = model_from_dict({"convention": "standard", "rows": [[1.0, 0, 0, 0], [1.0, 0, 0, 0]]})
    assert robot.joint_types == "RR" and robot.n == 2
    np.testing.assert_array_equal(robot.gravity_vector, [0, 0, -9.81])
    np.testing.assert_array_equal(robot.params, np.zeros((2, 10)))


GOOD = {
    "convention": "standard",
    "joint_types": "RR",
    "gravity": [0, -9.81, 0],
    "rows": [{"a": 1, "alpha": 0, "d": 0, "theta": 0}, {"a": 1, "alpha": 0, "d": 0, "theta": 0}],
}


def _drop(key):
    def change(m):
        del m[key]

    return change


def _set(*path, value):
    def change(m):
        target = m
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value

    return change


MALFORMED = [
    (_drop("convention"), "convention: missing"),
    (_drop("rows"), "rows: missing"),
    (_set("rows", value=[]), "rows: expected a non-empty list"),
    (_set("rows", 1, "alpha", value="0"), "rows[1].alpha: expected a finite number"),
    (lambda m: m["rows"][0].pop("d"), "rows[0]: missing 'd'"),
    (_set("rows", 0, "a_prev", value=0), "rows[0]: unknown field 'a_prev'"),
    (_set("rows", 1, "theta_offset", value=0), "rows[1]: both 'theta' and 'theta_offset'"),
    (_set("rows", 1, value=[1, 0, 0]), "rows[1]: expected numbers of shape (4,)"),
    (_set("gravty", value=[0, 0, -9.81]), "unknown field(s) 'gravty'"),
    (_set("gravity", value=[0, -9.81]), "gravity: expected numbers of shape (3,)"),
    (_set("convention", value="craig"), "convention: expected 'standard' or 'modified'"),
    (_set("joint_types", value="RRR"), "joint_types"),
    (_set("joint_types", value=2), "joint_types: expected a string"),
    (_set("params", value=[[1.0] * 9] * 2), "params: expected numbers of shape (2, 10)"),
    (_set("base", value=np.ones((4, 4)).tolist()), "base: expected a homogeneous transform"),
    (_set("qlim", value=[[1, -1], [-1, 1]]), "qlim"),
    (_set("Fs", value=[0.1]), "Fs: expected numbers of shape (2,)"),
    (_set("name", value=3), "name: expected a string"),
]


@pytest.mark.parametrize(("change", "message"), MALFORMED)
def test_malformed_model_files_name_the_field(change, message, tmp_path):
    model = copy.deepcopy(GOOD)
    model_from_dict(model)  # the unchanged model is fine
    change(model)
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model))
    with pytest.raises(ValueError, match=re.escape(message)) as info:
        load_model(path)
    assert str(info.value).startswith(f"{path}: ")
    assert message in str(info.value)


def test_file_errors(tmp_path):
    with pytest.raises(ValueError, match=r"neither a built-in model .*kuka_lwr4"):
        load_model("kuka")
    with pytest.raises(FileNotFoundError, match="no such file"):
        load_model(tmp_path / "absent.json")
    (tmp_path / "bad.json").write_text('{"convention": "standard",\n "rows": [1, 2,]}')
    with pytest.raises(ValueError, match=r"not valid JSON: .* line 2"):
        load_model(tmp_path / "bad.json")
    (tmp_path / "list.json").write_text("[1, 2]")
    with pytest.raises(ValueError, match="expected an object"):
        load_model(tmp_path / "list.json")
    (tmp_path / "model.txt").write_text("{}")
    with pytest.raises(ValueError, match="unknown extension"):
        load_model(tmp_path / "model.txt")
    with pytest.raises(ValueError, match="unknown extension"):
        save_model(dynid.models.planar_2r(), tmp_path / "model.txt")


def test_yaml_needs_pyyaml_or_round_trips(tmp_path):
    robot = dynid.models.planar_2r()
    try:
        import yaml  # noqa: F401 -- optional, not a dependency
    except ImportError:
        (tmp_path / "m.yaml").write_text("convention: standard\n")
        for call in (
            lambda: load_model(tmp_path / "m.yaml"),
            lambda: save_model(robot, tmp_path / "n.yml"),
        ):
            with pytest.raises(ValueError, match="PyYAML, which is not installed"):
                call()
    else:
        _same_robot(robot, load_model(save_model(robot, tmp_path / "m.yaml")))
