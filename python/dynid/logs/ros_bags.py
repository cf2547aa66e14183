"""ROS bags in: the ``sensor_msgs/msg/JointState`` messages of a recording as a :class:`Log`.

ROS 2 bags (a directory with ``metadata.yaml``, or its ``.mcap`` / ``.db3`` storage file) and
ROS 1 ``.bag`` files are read through the ``rosbags`` package (pure Python, the optional extra
``pip install "dynid[ros]"``); dynid has no bag or MCAP reader of its own. The mapping
(docs/data.md, "ROS bags"):

- t: the messages' header stamps, ``sec + nanosec * 1e-9`` s (as ROS's ``Time.to_sec``), not the
  time the recorder received them; messages are taken in stamp order;
- joints are matched **by name** to the model's ``joint_names``: any order in the message, other
  joints (gripper fingers) ignored, a joint of the model absent from a message an error naming
  it; a name list that changes between messages is matched anew;
- ``position`` -> q, ``velocity`` -> qd when every message has it, ``effort`` -> tau (with
  ``current=True`` the effort is motor current, kept in tau as ``dynid identify --current``
  expects its currents).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .log import Log
from .messages import name_list

#: The message type read; ROS 1 bags name it ``sensor_msgs/JointState``, which rosbags reports in
#: the ROS 2 spelling.
JOINT_STATE = "sensor_msgs/msg/JointState"
#: File suffixes of a bag; a directory is a ROS 2 bag (with metadata.yaml).
BAG_SUFFIXES = (".bag", ".mcap", ".db3")
#: What to install when rosbags is missing.
EXTRA = 'pip install "dynid[ros]"'


#: The format's name in the output and result.json (dynid.logs.readers.ros_bag).
FORMAT_NAME = "ROS bag"


def is_ros_bag(path: str | Path) -> bool:
    """Whether ``path`` is read as a ROS bag: a directory or a .bag/.mcap/.db3 file."""
    path = Path(path)
    return path.is_dir() or path.suffix.lower() in BAG_SUFFIXES


def read_ros_bag(
    path: str | Path,
    *,
    topic: str | None = None,
    joint_names: Sequence[str] | None,
    current: bool = False,
) -> Log:
    """The JointState messages of ``topic`` in the bag at ``path``, joints in the order of
    ``joint_names`` (the model's, :attr:`dynid.Robot.joint_names`).

    ``topic`` defaults to the bag's one ``sensor_msgs/msg/JointState`` topic. ``current=True``
    reads the effort as motor current (still called tau in the Log). ValueError naming the
    argument or the joint: rosbags not installed (naming the extra), no or several JointState
    topics without ``topic``, a joint missing from a message, a message without positions or
    efforts, an unreadable bag.
    """
    names = _check_joint_names(joint_names)
    if topic is not None and (not isinstance(topic, str) or not topic):
        raise ValueError(f"topic: expected a topic name, got {topic!r}")
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"path: no such file or directory: {path}")
    if path.is_dir() and not (path / "metadata.yaml").is_file():
        raise ValueError(f"path: {path} is a directory without metadata.yaml, not a ROS 2 bag")
    any_reader, reader_errors, typestore = _rosbags()
    try:
        with any_reader([path], default_typestore=typestore) as reader:
            chosen = _topic(reader.topics, topic)
            connections = [c for c in reader.connections if c.topic == chosen]
            messages = [
                reader.deserialize(raw, connection.msgtype)
                for connection, _, raw in reader.messages(connections=connections)
            ]
    except reader_errors as exc:
        raise ValueError(f"not a readable ROS bag ({type(exc).__name__}: {exc})") from None
    return _joint_states(messages, names, chosen, path, current)


def _rosbags() -> tuple[Any, tuple[type[BaseException], ...], Any]:
    """(AnyReader, the errors it raises on a bad bag, the ROS 2 Humble type store) from rosbags,
    imported on first use; a ValueError naming the extra when it is not installed."""
    try:
        from rosbags.highlevel import AnyReader, AnyReaderError
        from rosbags.rosbag1 import ReaderError as Reader1Error
        from rosbags.rosbag2 import ReaderError as Reader2Error
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ValueError(
            f"reading ROS bags needs the rosbags package, which is not installed: {EXTRA}"
        ) from None
    # The type store is used only when a bag does not carry its message definitions (ROS 2
    # sqlite3 bags before Iron); JointState is the same in every ROS 2 distribution.
    errors = (AnyReaderError, Reader1Error, Reader2Error)
    return AnyReader, errors, get_typestore(Stores.ROS2_HUMBLE)


def _check_joint_names(joint_names: Any) -> list[str]:
    if joint_names is None:
        raise ValueError(
            "joint_names: a ROS bag's joints are matched by name; give the model's joint names "
            "(Robot.joint_names; the command line takes them from --model)"
        )
    if isinstance(joint_names, str) or not all(isinstance(j, str) for j in joint_names):
        raise ValueError(f"joint_names: expected a sequence of strings, got {joint_names!r:.60}")
    names = list(joint_names)
    if not names or len(set(names)) != len(names) or not all(names):
        raise ValueError(f"joint_names: expected distinct non-empty names, got {names}")
    return names


def _topic(topics: dict[str, Any], topic: str | None) -> str:
    """The topic to read: ``topic`` if it holds JointState, else the bag's one JointState topic."""
    states = sorted(name for name, info in topics.items() if info.msgtype == JOINT_STATE)
    listed = ", ".join(f"{name} ({info.msgtype})" for name, info in sorted(topics.items()))
    if topic is not None:
        if topic not in topics:
            raise ValueError(
                f"topic: no topic {topic!r} in the bag; its topics: {listed or 'none'}"
            )
        if topics[topic].msgtype != JOINT_STATE:
            raise ValueError(
                f"topic: {topic!r} holds {topics[topic].msgtype}, not {JOINT_STATE}; "
                f"its topics: {listed}"
            )
        return topic
    if len(states) != 1:
        found = (
            f"{len(states)} {JOINT_STATE} topics ({', '.join(states)})"
            if states
            else (f"no {JOINT_STATE} topic")
        )
        raise ValueError(
            f"topic: the bag has {found}; choose one with topic= / --topic; "
            f"its topics: {listed or 'none'}"
        )
    return states[0]


def _joint_states(
    messages: list[Any], names: list[str], topic: str, path: Path, current: bool
) -> Log:
    """The Log of JointState ``messages``: each message's joints picked by name (see the module
    docstring)."""
    if len(messages) < 2:
        raise ValueError(f"topic {topic}: {len(messages)} messages; a log needs at least 2")
    T, n = len(messages), len(names)
    t = np.empty(T)
    q, qd, tau = np.empty((T, n)), np.empty((T, n)), np.empty((T, n))
    velocity_everywhere = True
    orders: set[tuple[str, ...]] = set()
    ignored: set[str] = set()
    last: tuple[str, ...] | None = None
    pick: np.ndarray = np.empty(0, dtype=int)
    for k, msg in enumerate(messages):
        stamp = msg.header.stamp
        t[k] = stamp.sec + stamp.nanosec * 1e-9
        order = tuple(msg.name)
        if order != last:  # a new name list: match the model's joints in it anew
            pick = _pick(order, names, topic, k)
            last = order
            orders.add(order)
            ignored.update(set(order) - set(names))
        where = f"topic {topic}, message {k} (t = {t[k]!r})"
        q[k] = _field(msg.position, order, pick, "position", where)
        tau[k] = _field(msg.effort, order, pick, "effort", where)
        if len(msg.velocity) == len(order):
            qd[k] = np.asarray(msg.velocity, dtype=float)[pick]
        else:
            velocity_everywhere = False
    order_by_stamp = np.argsort(t, kind="stable")
    reordered = int(np.count_nonzero(order_by_stamp != np.arange(T)))
    repeated = np.nonzero(np.diff(t[order_by_stamp]) <= 0)[0]
    if repeated.size:
        i = int(order_by_stamp[repeated[0] + 1])
        raise ValueError(
            f"topic {topic}: header stamps repeat (message {i}, t = {t[i]!r}; "
            f"{repeated.size} repeats): does the publisher set header.stamp?"
        )
    effort = "motor current (tau holds currents)" if current else "joint torque"
    note = (
        f"loaded from {path.name} (ROS bag, topic {topic}, {T} sensor_msgs/JointState messages; "
        f"header stamps; joints {', '.join(names)} by name; effort as {effort}; "
        + ("velocity as qd" if velocity_everywhere else "no velocity in every message")
        + ")"
    )
    extra = []
    if ignored:
        extra.append(f"ignored joints {', '.join(sorted(ignored))}")
    if len(orders) > 1:
        extra.append(f"{len(orders)} different name lists, each matched by name")
    if reordered:
        extra.append(f"{reordered} messages reordered by header stamp")
    if extra:
        note += "; " + "; ".join(extra)
    return Log(
        t=t[order_by_stamp],
        q=q[order_by_stamp],
        tau=tau[order_by_stamp],
        qd=qd[order_by_stamp] if velocity_everywhere else None,
        source=str(path),
        format=FORMAT_NAME,
        notes=[note],
    )


def _pick(order: tuple[str, ...], names: list[str], topic: str, k: int) -> np.ndarray:
    """Indices of ``names`` in a message's name list ``order``."""
    index = {name: i for i, name in enumerate(order)}
    if len(index) != len(order):
        repeated = sorted({name for name in order if order.count(name) > 1})
        raise ValueError(f"topic {topic}, message {k}: joint names repeated: {name_list(repeated)}")
    missing = [name for name in names if name not in index]
    if missing:
        raise ValueError(
            f"joint_names: joint {missing[0]!r} of the model is not in {topic}'s message {k} "
            f"(missing: {', '.join(missing)}); the message names {name_list(list(order))}: set "
            "the model's joint_names (a model file's joint_names, Robot.joint_names, or the "
            "robot's URDF as --model)"
        )
    return np.array([index[name] for name in names], dtype=int)


def _field(values: Any, order: tuple[str, ...], pick: np.ndarray, what: str, where: str) -> Any:
    """A message's ``what`` (position, effort) for the model's joints; one value per name."""
    values = np.asarray(values, dtype=float)
    if values.shape != (len(order),):
        raise ValueError(
            f"{where}: {len(values)} {what} values for {len(order)} joint names"
            + ("; a log needs torques (effort)" if what == "effort" and not len(values) else "")
        )
    return values[pick]
