"""ROS 2 bags out: a :class:`Log` as ``sensor_msgs/msg/JointState`` messages, written by the
``rosbags`` package (the optional extra ``pip install "dynid[ros]"``), so that a simulated
experiment (``dynid simulate --format bag``) is read back by ``dynid identify`` and by ROS 2's
own tools (``ros2 bag info``) like a recording of the arm.

The mapping is the reader's (:mod:`dynid.logs.ros_bags`), turned around: one message per
sample, its header stamp ``start + t`` (sec, nanosec), the joints named by the model's
``joint_names``, ``position`` = q, ``velocity`` = qd when the log has it (empty otherwise),
``effort`` = tau. The bag's receive times are the stamps.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .log import Log
from .ros_bags import EXTRA, JOINT_STATE

#: Storage formats of a ROS 2 bag: MCAP (the default since ROS 2 Iron) or SQLite 3.
STORAGES = ("mcap", "sqlite3")


def write_ros_bag(
    log: Log,
    path: str | Path,
    joint_names: Sequence[str],
    *,
    topic: str = "/joint_states",
    storage: str = "mcap",
    start: float = 0.0,
) -> Path:
    """Write ``log`` into a new ROS 2 bag directory ``path`` (it must not exist: rosbags creates
    it); ``start`` [s] is added to the log's times for the stamps (e.g. a Unix time). ValueError
    naming the argument: rosbags not installed (naming the extra), joint names not matching the
    log, an unknown storage, an existing path, a negative stamp."""
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    names = [str(name) for name in joint_names]
    if len(names) != log.n or len(set(names)) != log.n:
        raise ValueError(f"joint_names: expected {log.n} distinct names, got {names!r}")
    if storage not in STORAGES:
        raise ValueError(f"storage: expected one of {', '.join(STORAGES)}, got {storage!r}")
    if not isinstance(topic, str) or not topic.startswith("/"):
        raise ValueError(f"topic: expected a topic name starting with '/', got {topic!r}")
    path = Path(path)
    if path.exists():
        raise ValueError(f"path: {path} exists (a bag is written into a new directory)")
    stamps = np.rint((np.asarray(log.t) + float(start)) * 1e9).astype(np.int64)
    if stamps[0] < 0:
        raise ValueError(f"start: the first stamp would be negative ({stamps[0] * 1e-9:g} s)")
    try:
        from rosbags.rosbag2 import StoragePlugin, Writer
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ValueError(
            f"writing ROS bags needs the rosbags package, which is not installed: {EXTRA}"
        ) from None
    store = get_typestore(Stores.ROS2_HUMBLE)
    types = store.types
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    velocity = log.qd
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        connection = writer.add_connection(topic, JOINT_STATE, typestore=store)
        for k, ns in enumerate(stamps.tolist()):
            stamp = types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
            message = types[JOINT_STATE](
                header=types["std_msgs/msg/Header"](stamp=stamp, frame_id=""),
                name=names,
                position=np.ascontiguousarray(log.q[k]),
                velocity=np.zeros(0) if velocity is None else np.ascontiguousarray(velocity[k]),
                effort=np.ascontiguousarray(log.tau[k]),
            )
            writer.write(connection, ns, store.serialize_cdr(message, JOINT_STATE))
    return path
