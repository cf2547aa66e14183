"""Velocity and effort limits and link names (issue 21, item 3: "a fresh URDF keeps the source's
names and limits and never writes zero effort or velocity limits"): read from a URDF's
``<limit>``, kept in the robot, written back into URDF and MJCF, read by Pinocchio and MuJoCo.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import dynid
from dynid.export.mjcf import mjcf_text

UR5_EFFORT = [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]  # ur5_robot.urdf's <limit effort>
UR5_VELOCITY = [3.15, 3.15, 3.15, 3.2, 3.2, 3.2]


def test_a_urdf_s_limits_and_names_are_read_and_written_back(tmp_path) -> None:
    import pinocchio

    robot = dynid.models.ur5()
    np.testing.assert_array_equal(robot.effort_limits, UR5_EFFORT)
    np.testing.assert_array_equal(robot.velocity_limits, UR5_VELOCITY)
    assert robot.link_names[0] == "shoulder_link" and robot.link_names[-1] == "wrist_3_link"
    text = robot.to_urdf("ur5")
    assert not re.search(r'(effort|velocity)="0(\.0)?"', text)
    again = dynid.Robot.from_urdf(text)
    for field in ("effort_limits", "velocity_limits", "link_names", "joint_names"):
        np.testing.assert_array_equal(getattr(again, field), getattr(robot, field))
    model = pinocchio.buildModelFromXML(text)  # an independent reader of the same text
    np.testing.assert_array_equal(model.effortLimit, UR5_EFFORT)
    np.testing.assert_array_equal(model.velocityLimit, UR5_VELOCITY)
    assert [model.frames[model.getFrameId(n)].name for n in robot.link_names] == list(
        robot.link_names
    )


def test_unknown_limits_are_written_as_no_limit_never_zero() -> None:
    import pinocchio

    robot = dynid.models.kuka_lwr4()  # a DH model: no limits known
    assert np.all(np.isinf(robot.effort_limits)) and np.all(np.isinf(robot.velocity_limits))
    text = robot.to_urdf("lwr")
    assert not re.search(r'(effort|velocity)="0(\.0)?"', text)
    model = pinocchio.buildModelFromXML(text)
    assert np.all(model.effortLimit >= 1e6) and np.all(model.velocityLimit >= 1e6)
    again = dynid.Robot.from_urdf(text)  # read back as no limit
    assert np.all(np.isinf(again.effort_limits)) and np.all(np.isinf(again.velocity_limits))


def test_zero_in_a_urdf_means_not_given_and_negative_is_refused() -> None:
    text = dynid.models.ur5().to_urdf("ur5")
    zero = text.replace('effort="150.0"', 'effort="0"', 1)
    np.testing.assert_array_equal(dynid.Robot.from_urdf(zero).effort_limits[0], np.inf)
    negative = text.replace('velocity="3.15"', 'velocity="-1"', 1)
    with pytest.raises(
        ValueError, match=r"shoulder_pan_joint.*velocity=-1.0, expected a value >= 0"
    ):
        dynid.Robot.from_urdf(negative)


def test_mjcf_motors_carry_the_effort_limits_and_bodies_the_link_names() -> None:
    mujoco = pytest.importorskip("mujoco")
    robot = dynid.models.panda()
    model = mujoco.MjModel.from_xml_string(mjcf_text(robot))
    np.testing.assert_array_equal(model.actuator_ctrlrange[:, 1], robot.effort_limits)
    np.testing.assert_array_equal(model.actuator_ctrlrange[:, 0], -robot.effort_limits)
    assert all(model.actuator_ctrllimited)
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(1, 8)]
    assert names == list(robot.link_names)
    free = mujoco.MjModel.from_xml_string(mjcf_text(dynid.models.kuka_lwr4()))
    assert not any(free.actuator_ctrllimited)  # no limit known: none invented


def test_names_that_clash_with_the_writer_s_own_are_renamed() -> None:
    robot = dynid.models.planar_2r()
    robot.link_names = ["base_link", "tool"]
    text = robot.to_urdf("clash")
    again = dynid.Robot.from_urdf(text)
    assert again.link_names == ("base_link", "tool")
    assert '<link name="base_link_dynid" />' in text and '<link name="tool_dynid" />' in text
