"""The log readers, one file per format, each registered here with one line (the registry:
:mod:`dynid.logs.formats`). Formats recognised by their header come first; the generic ones
(any CSV, NPZ, MATLAB) are tried after every specific one.

Importing this package registers the formats; ``dynid.logs.formats`` does it on first use.
"""

from __future__ import annotations

from ..formats import register
from . import fri, generic_csv, libfranka, matlab, npz, ur_rtde

register(ur_rtde.FORMAT)
register(libfranka.FORMAT)
register(fri.FORMAT)
# ROS bags: logs/ros_bags.py's read_ros_bag(path, *, topic, joint_names, current) (another
# session's work) is registered here at its merge, e.g. as
#     register(LogFormat("ROS bag", (".bag", ".db3", ".mcap", DIRECTORY), lambda p, head: True,
#         lambda p, o: ros_bags.read_ros_bag(p, topic=o.topic, joint_names=o.joint_names,
#                                            current=o.current)))
# (its own suffixes, so its place in the order does not matter; DIRECTORY from ..formats: a
# ROS 2 bag is a folder).
register(generic_csv.FORMAT, generic=True)
register(npz.FORMAT, generic=True)
register(matlab.FORMAT, generic=True)
