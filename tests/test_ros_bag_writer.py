"""ROS 2 bags out (dynid.logs.ros_bag_writer): a log written as JointState messages reads back
through rosbags' own reader (independent of dynid's) and through ``dynid.load_log`` with the
same values, in both storages."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.logs import load_log
from dynid.logs.ros_bag_writer import write_ros_bag
from test_log_identification import fourier_log

pytest.importorskip("rosbags")


@pytest.fixture(scope="module")
def arm_log():
    arm = dynid.models.ur5()
    return arm, fourier_log(arm, 2, seconds=1.0, fs=250.0)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_a_written_bag_reads_back(arm_log, tmp_path, storage) -> None:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    arm, log = arm_log
    path = write_ros_bag(log, tmp_path / "bag", arm.joint_names, storage=storage, start=1.7e9)
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
        (connection,) = reader.connections
        assert connection.topic == "/joint_states"
        messages = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages()]
    assert len(messages) == log.T
    assert list(messages[0].name) == list(arm.joint_names)
    np.testing.assert_array_equal([m.position for m in messages], log.q)
    np.testing.assert_array_equal([m.effort for m in messages], log.tau)
    stamps = np.array([m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in messages])
    assert np.max(np.abs(stamps - 1.7e9 - log.t)) < 1e-6
    again = load_log(path, joint_names=arm.joint_names)
    np.testing.assert_array_equal(again.q, log.q)
    np.testing.assert_array_equal(again.tau, log.tau)
    np.testing.assert_allclose(again.qd, log.qd, rtol=0, atol=0)


def test_bad_arguments_are_named(arm_log, tmp_path) -> None:
    arm, log = arm_log
    with pytest.raises(ValueError, match="joint_names: expected 6 distinct names"):
        write_ros_bag(log, tmp_path / "a", ["j"] * 6)
    with pytest.raises(ValueError, match="storage: expected one of mcap, sqlite3"):
        write_ros_bag(log, tmp_path / "b", arm.joint_names, storage="zip")
    (tmp_path / "c").mkdir()
    with pytest.raises(ValueError, match=r"path: .* exists"):
        write_ros_bag(log, tmp_path / "c", arm.joint_names)
    with pytest.raises(ValueError, match="topic: expected a topic name"):
        write_ros_bag(log, tmp_path / "d", arm.joint_names, topic="joint_states")
