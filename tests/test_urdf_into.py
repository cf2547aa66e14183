"""`dynid export --urdf OUT --into USER.urdf` (dynid.export.urdf_into): the user's own URDF with
the identified inertials and drive terms, everything else kept.

Independent checks: Pinocchio reading the written file computes the identified robot's rigid-body
torques (its armature set to Ia), dynid reading it back the whole model, to 1e-12 relative; and
the file, with the inertials and the dynamics' damping/friction taken out, is the user's file
with the same taken out (canonical XML: every other element, attribute, text and comment kept).
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import dynid
import dynid.cli
from dynid.export.urdf_into import urdf_into_text
from dynid.model.urdf import dh_model_from_urdf

DATA = "tests/data/urdf/"


def identified(robot: dynid.Robot, seed: int = 0) -> dynid.Robot:
    """``robot`` with other (consistent) parameters and drive terms: a stand-in for an
    identified model of the same arm."""
    rng = np.random.default_rng(seed)
    out = robot.copy()
    out.params = robot.params * rng.uniform(0.8, 1.2, (robot.n, 1))  # scaled bodies stay bodies
    out.Fv = rng.uniform(0.1, 1.0, robot.n)
    out.Fs = rng.uniform(0.1, 1.0, robot.n)
    out.Ia = rng.uniform(0.01, 0.2, robot.n)
    return out


def without_identified_fields(text: str) -> str:
    """The URDF's canonical XML with every <inertial>, the dynamics' damping and friction and the
    dynid rotor comments removed."""
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    root = ET.fromstring(text, parser=parser)
    for parent in root.iter():
        for child in list(parent):
            if child.tag == "inertial" or (
                child.tag is ET.Comment and "dynid: Ia=" in (child.text or "")
            ):
                parent.remove(child)
        for dynamics in parent.findall("dynamics"):
            dynamics.attrib.pop("damping", None)
            dynamics.attrib.pop("friction", None)
            if not dynamics.attrib and not len(dynamics):  # added where the user had none
                parent.remove(dynamics)
    return ET.canonicalize(ET.tostring(root, encoding="unicode"), strip_text=True)


def assert_same_robot(text: str, robot: dynid.Robot, tip_link: str | None = None) -> None:
    import pinocchio

    again = dynid.Robot.from_urdf(text, tip_link=tip_link)
    q, qd, qdd = np.random.default_rng(5).uniform(-1.5, 1.5, (3, 20, robot.n))
    expected = robot.rnea(q, qd, qdd)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(again.rnea(q, qd, qdd), expected, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(again.Ia, robot.Ia)
    # Pinocchio: the rigid body of the chain (reduced to it) plus armature = rnea without friction
    full = pinocchio.buildModelFromXML(text)
    chain = set(dh_model_from_urdf(text, tip_link=tip_link, check_physical=False).joint_names)
    locked = [j for j in range(1, full.njoints) if full.names[j] not in chain]
    model = pinocchio.buildReducedModel(full, locked, pinocchio.neutral(full)) if locked else full
    assert model.nq == robot.n
    model.armature[:] = robot.Ia
    data = model.createData()
    rigid = robot.copy()
    rigid.Fv = rigid.Fs = np.zeros(robot.n)
    for k in range(5):
        tau = pinocchio.rnea(model, data, q[k], qd[k], qdd[k])
        reference = rigid.rnea(q[k], qd[k], qdd[k])
        assert np.abs(tau - reference).max() <= 1e-12 * np.abs(reference).max()


@pytest.mark.parametrize(
    ("file", "tip"),
    [("kuka_lwr4.urdf", None), ("xarm7.urdf", None), ("ur3.urdf", "tool0")],
)
def test_identified_model_into_real_urdfs(file, tip):
    text = Path(DATA, file).read_text()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # nearly parallel axes of some arms (docs/urdf.md)
        robot = identified(dynid.Robot.from_urdf(text, tip_link=tip))
        written = urdf_into_text(robot, text, tip_link=tip)
        assert_same_robot(written, robot, tip)
    assert without_identified_fields(written) == without_identified_fields(text)


def test_links_fixed_to_a_chain_link_keep_their_inertials():
    """The Panda's hand is fixed to link 8 (not a chain joint's child) and its fingers are
    prismatic joints off the chain: both keep their inertials, the chain links get the rest."""
    text = Path(DATA, "panda.urdf").read_text()
    tip = "panda_hand_tcp"
    robot = identified(dynid.Robot.from_urdf(text, tip_link=tip))
    written = urdf_into_text(robot, text, tip_link=tip)
    assert_same_robot(written, robot, tip)

    def inertial(source: str, link: str) -> str:
        element = ET.fromstring(source).find(f"link[@name='{link}']/inertial")
        assert element is not None
        return ET.canonicalize(ET.tostring(element, encoding="unicode"), strip_text=True)

    for link in ("panda_hand", "panda_leftfinger", "panda_rightfinger"):
        assert inertial(written, link) == inertial(text, link)


USER_URDF = """<?xml version="1.0"?>
<!-- the user's header comment, before the root -->
<robot name="two_link" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <!-- a comment the user wrote -->
  <link name="base_link"/>
  <link name="upper">
    <visual><geometry><mesh filename="package://arm/meshes/upper.stl"/></geometry></visual>
    <inertial>
      <mass value="2.0"/>
      <!-- CAD estimate -->
      <origin xyz="0.2 0 0" rpy="0 0 0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.05"/>
    </inertial>
  </link>
  <link name="lower">
    <inertial>
      <mass value="1.0"/>
      <origin xyz="0.15 0 0"/>
      <inertia ixx="0.005" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/>
    </inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base_link"/><child link="upper"/>
    <origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="80" velocity="2.5"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="lower"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="2.5" effort="40" velocity="3"/>
    <dynamics damping="0.1" friction="0.2"/>
  </joint>
  <ros2_control name="arm" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="shoulder"><command_interface name="effort"/></joint>
  </ros2_control>
  <gazebo reference="upper"><material>Gazebo/Orange</material></gazebo>
</robot>
<!-- trailing comment -->
"""


def test_user_tags_comments_and_namespaces_are_kept():
    robot = identified(dynid.Robot.from_urdf(USER_URDF), seed=3)
    written = urdf_into_text(robot, USER_URDF)
    assert_same_robot(written, robot)
    assert without_identified_fields(written) == without_identified_fields(USER_URDF)
    for kept in (
        "<!-- the user's header comment, before the root -->",
        "<!-- CAD estimate -->",
        "<!-- trailing comment -->",
        'xmlns:xacro="http://www.ros.org/wiki/xacro"',
        "<plugin>mock_components/GenericSystem</plugin>",
        'effort="80" velocity="2.5"',
    ):
        assert kept in written
    assert written.startswith('<?xml version="1.0"?>\n<!-- the user')


def test_refusals_and_cli(tmp_path, capsys):
    user = tmp_path / "user.urdf"
    user.write_text(USER_URDF)
    other = dynid.models.planar_2r()  # a different arm: its frames are on other bodies
    with pytest.raises(ValueError, match="into: the robot is not the arm of this URDF's chain"):
        urdf_into_text(other, USER_URDF)
    coupled = dynid.Robot.from_urdf(USER_URDF)
    coupled.transmission = np.array([[1.0, 0.0], [1.0, 1.0]])
    with pytest.raises(ValueError, match="transmission: a robot with coupled drives"):
        urdf_into_text(coupled, USER_URDF)
    model = tmp_path / "model.json"
    dynid.save_model(identified(dynid.Robot.from_urdf(USER_URDF), seed=4), model)
    out = tmp_path / "out.urdf"
    argv = ["export", str(model), "--urdf", str(out), "--into", str(user)]
    assert dynid.cli.main(argv) == 0
    assert_same_robot(out.read_text(), dynid.load_model(model))
    assert user.read_text() == USER_URDF  # the user's file is not touched
    assert dynid.cli.main(argv) == 2  # exists, no --overwrite
    assert "exists" in capsys.readouterr().err
    assert dynid.cli.main(["export", str(model), "--into", str(user)]) == 2
    assert "into: the user's URDF to update needs --urdf OUT" in capsys.readouterr().err
