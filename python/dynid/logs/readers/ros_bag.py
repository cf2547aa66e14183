"""ROS bags (ROS 2 MCAP or sqlite3, ROS 1): the JointState messages of one topic, joints
matched by name to the model's (:mod:`dynid.logs.ros_bags`, through the ``rosbags`` package of
the ``dynid[ros]`` extra, imported on first use; docs/data.md, "ROS bags")."""

from __future__ import annotations

from pathlib import Path

from ..formats import DIRECTORY, LogFormat, ReadOptions
from ..log import Log
from ..ros_bags import FORMAT_NAME

#: A ROS bag by its storage file (ROS 1 .bag, ROS 2 .mcap/.db3) or a ROS 2 bag's folder.
SUFFIXES = (".bag", ".mcap", ".db3", DIRECTORY)


def _read(path: Path, options: ReadOptions) -> Log:
    if options.columns is not None or options.time_unit is not None:
        raise ValueError(
            "columns, time_unit: not for a ROS bag (joints are matched by name, time is read from "
            "the header stamps)"
        )
    from ..ros_bags import read_ros_bag

    return read_ros_bag(
        path, topic=options.topic, joint_names=options.joint_names, current=options.current
    )


FORMAT = LogFormat(FORMAT_NAME, SUFFIXES, lambda path, head: True, _read, topics=True)
