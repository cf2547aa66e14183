"""Robot.to_urdf: the text read back by dynid and by Pinocchio's URDF parser (urdfdom, its own
algorithms) gives the same model, to 1e-12 relative (docs/urdf.md); bad links are refused by name;
writing to a path is atomic and never overwrites silently."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import dynid
from conftest import ARM_CASES, make_arm, random_arm
from pinocchio_urdf import relative_error

TOL = 1e-12  # relative to the largest entry of each result


def robots() -> dict[str, dynid.Robot]:
    """DH robots of both conventions, with base/tool transforms and prismatic joints."""
    cases = {case: make_arm(case).robot() for case in ARM_CASES}
    cases["kuka_lwr4"] = dynid.models.kuka_lwr4()
    rng = np.random.default_rng(7)
    for k, convention in enumerate(("standard", "modified", "standard", "modified")):
        cases[f"random_{k}_{convention}"] = random_arm(rng, 7, convention).robot()
    return cases


ROBOTS = robots()


def assert_same_dynamics(robot: dynid.Robot, other: dynid.Robot, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(6):
        q, qd, qdd = rng.uniform(-2.0, 2.0, (3, robot.n))
        assert relative_error(other.rnea(q, qd, qdd), robot.rnea(q, qd, qdd)) < TOL
        assert relative_error(other.mass_matrix(q), robot.mass_matrix(q)) < TOL
        assert relative_error(other.gravity(q), robot.gravity(q)) < TOL
        assert relative_error(other.fkine(q), robot.fkine(q)) < TOL


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("case", sorted(ROBOTS))
def test_round_trip_through_dynid(case: str, convention: str) -> None:
    robot = ROBOTS[case]
    back = dynid.Robot.from_urdf(
        robot.to_urdf(name=case), convention=convention, gravity=robot.gravity_vector
    )
    assert back.joint_types == robot.joint_types and back.name == case
    assert_same_dynamics(robot, back)  # Ia comes back from the dynid comment
    np.testing.assert_array_equal(back.Ia, robot.Ia)
    np.testing.assert_array_equal(back.Fv, robot.Fv)
    np.testing.assert_array_equal(back.Fs, robot.Fs)
    np.testing.assert_array_equal(back.qlim, robot.qlim)
    # (the DH frames themselves may differ: a DH table of given axes is not unique, e.g. the
    # sign of x along a common normal; what is unique is the model, checked above)


@pytest.mark.parametrize("case", sorted(ROBOTS))
def test_pinocchio_reads_the_same_model(case: str) -> None:
    robot = ROBOTS[case]
    model = pin.buildModelFromXML(robot.to_urdf())
    assert model.nq == model.nv == robot.n
    model.gravity.linear = robot.gravity_vector
    model.armature = robot.Ia  # no URDF field: the comment is dynid's only
    data = model.createData()
    np.testing.assert_array_equal(model.damping, robot.Fv)
    np.testing.assert_array_equal(model.friction, robot.Fs)
    np.testing.assert_array_equal(model.lowerPositionLimit, robot.qlim[:, 0])
    np.testing.assert_array_equal(model.upperPositionLimit, robot.qlim[:, 1])
    tool = model.getFrameId("tool")
    rng = np.random.default_rng(3)
    for _ in range(6):
        q, qd, qdd = rng.uniform(-2.0, 2.0, (3, robot.n))
        # Pinocchio's rnea has no friction: subtract dynid's
        tau = robot.rnea(q, qd, qdd) - robot.friction(qd)
        assert relative_error(pin.rnea(model, data, q, qd, qdd), tau) < TOL
        M = np.triu(pin.crba(model, data, q))
        assert relative_error(M + np.triu(M, 1).T, robot.mass_matrix(q)) < TOL
        assert relative_error(pin.computeGeneralizedGravity(model, data, q), robot.gravity(q)) < TOL
        pin.framesForwardKinematics(model, data, q)
        assert relative_error(data.oMf[tool].homogeneous, robot.fkine(q)) < TOL


def test_urdf_content() -> None:
    robot = dynid.models.kuka_lwr4()
    text = robot.to_urdf(name="lwr")
    assert text.startswith('<?xml version="1.0"?>\n<robot name="lwr">')
    # Ia in a comment of each joint, with the value that reads back exactly
    for i, value in enumerate(robot.Ia, start=1):
        assert f'<joint name="q{i}" type="revolute">\n    <!-- dynid: Ia="{float(value)!r}"' in text
    # The joints carry the robot's joint names (a URDF's own, read back as they were).
    named = robot.copy()
    named.joint_names = [f"lwr_a{i}" for i in range(1, 8)]
    again = dynid.Robot.from_urdf(named.to_urdf())
    assert again.joint_names == named.joint_names
    assert text.count("<link ") == robot.n + 2 and text.count("<joint ") == robot.n + 1
    assert '<axis xyz="0 0 1" />' in text
    assert "-0.0" not in re.findall(r"[-+.\de]+", text)  # no negative zeros printed


def test_inconsistent_links_are_refused_by_name() -> None:
    with pytest.raises(ValueError, match=r"link 1 is not physically consistent \(mass 0.0 is"):
        dynid.models.puma560().to_urdf()  # link 1 of the published model has no mass
    robot = dynid.models.kuka_lwr4()
    params = robot.params.copy()
    params[3, 4] = -1.0  # Ixx4 < 0: no body has that
    robot.params = params
    with pytest.raises(ValueError, match="link 4 is not physically consistent"):
        robot.to_urdf()
    with pytest.raises(ValueError, match="name"):
        dynid.models.kuka_lwr4().to_urdf(name="")


def test_path_is_written_atomically_and_never_overwritten(tmp_path: Path) -> None:
    robot = dynid.models.kuka_lwr4()
    path = tmp_path / "lwr.urdf"
    text = robot.to_urdf(name="lwr", path=path)
    assert path.read_text(encoding="utf-8") == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lwr.urdf"]  # no temporary left
    with pytest.raises(ValueError, match=r"path: .* exists; pass overwrite=True"):
        robot.to_urdf(name="other", path=path)
    assert path.read_text(encoding="utf-8") == text  # untouched
    robot.to_urdf(name="other", path=str(path), overwrite=True)
    assert '<robot name="other">' in path.read_text(encoding="utf-8")
    with pytest.raises(ValueError, match="overwrite"):
        robot.to_urdf(path=path, overwrite="yes")
    with pytest.raises(ValueError, match="is a folder"):
        robot.to_urdf(path=tmp_path)
    bad = robot.copy()
    bad.params = -robot.params
    with pytest.raises(ValueError, match="not physically consistent"):  # checked before writing
        bad.to_urdf(path=tmp_path / "bad.urdf")
    assert not (tmp_path / "bad.urdf").exists()


@pytest.mark.parametrize("bad", ["arm\x01", "a\x00b", "x\x1b[31m", "\ufffe"])
def test_a_name_xml_cannot_hold_is_refused(bad: str, tmp_path: Path) -> None:
    """Issue 22: `to_urdf(name=...)` / `dynid export --name` with a control character wrote a
    file that is not XML (exit 0). Refused by name, and no file written."""
    robot = dynid.models.planar_2r()
    with pytest.raises(ValueError, match=r"^name: expected characters that XML 1\.0 allows"):
        robot.to_urdf(name=bad, path=tmp_path / "arm.urdf")
    assert not (tmp_path / "arm.urdf").exists()


@pytest.mark.parametrize("name", ['arm & <co> "7"', "bras à 7 axes", "tab\there", "κ-arm"])
def test_names_xml_can_hold_round_trip(name: str) -> None:
    """Any name made of XML characters is written escaped and read back exactly."""
    import xml.etree.ElementTree as ET

    text = dynid.models.planar_2r().to_urdf(name=name)
    assert ET.fromstring(text).get("name") == name
