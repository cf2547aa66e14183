"""ROS bags as logs (issue 20, item 1): bags written here with rosbags' own writers (ROS 2 MCAP,
ROS 2 sqlite3, ROS 1) from a simulated UR5 with known parameters, read back by dynid.

The messages name the joints in a shuffled order that changes half-way, carry a gripper joint
the model does not have, and share the bag with a second, non-JointState topic; the recorder's
receive times are another clock than the header stamps. What is read must be the simulated
arrays exactly (CDR and ROS 1 serialization keep float64), the joints in the model's order, and
t the header stamps. One bag is identified from the command line and gives back the simulated
arm's base parameters.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result
from dynid.logs import load_log
from dynid.logs.ros_bags import is_ros_bag, read_ros_bag
from dynid.model.model_files import save_model
from test_log_identification import fourier_log

rosbags = pytest.importorskip("rosbags")  # the dynid[ros] extra (requirements/test.txt)
from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import StoragePlugin  # noqa: E402
from rosbags.rosbag2 import Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

JOINT_STATE = "sensor_msgs/msg/JointState"
STRING = "std_msgs/msg/String"
#: The header stamps start here (a Unix time, as a robot's clock gives).
EPOCH_NS = 1_700_000_000 * 10**9
#: The message order of the model's joints (a permutation) before and after the switch, with a
#: gripper joint the model lacks placed between them.
FIRST_ORDER = (3, 0, 5, 1, 4, 2)
SECOND_ORDER = (1, 5, 2, 0, 3, 4)
GRIPPER = "robotiq_finger_joint"


def _arm() -> dynid.Robot:
    robot = dynid.models.ur5()  # from its URDF: the joint names shoulder_pan_joint, ...
    robot.Fv = np.linspace(0.5, 1.0, robot.n)
    return robot


def _message_names(arm: dynid.Robot, k: int, switch: int) -> tuple[list[str], list[int]]:
    """The name list of message k and, per entry, the model joint it is (-1: the gripper)."""
    order = list(FIRST_ORDER if k < switch else SECOND_ORDER)
    index = [*order[:2], -1, *order[2:]]
    return [GRIPPER if j < 0 else arm.joint_names[j] for j in index], index


def write_bag(
    path: Path,
    log: dynid.Log,
    arm: dynid.Robot,
    *,
    kind: str,
    topics: tuple[str, ...] = ("/joint_states",),
    velocity: bool = True,
) -> list[tuple[int, int]]:
    """Write ``log`` as JointState messages on each of ``topics`` (and a String topic) into a bag
    of ``kind`` ("mcap", "sqlite3", "ros1") with rosbags' writer; the header stamps (sec,
    nanosec) it wrote."""
    ros1 = kind == "ros1"
    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    types = store.types
    serialize = store.serialize_ros1 if ros1 else store.serialize_cdr
    if ros1:
        writer = Writer1(path)
    else:
        plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
        writer = Writer2(path, version=9, storage_plugin=plugin)
    stamps = []
    rng = np.random.default_rng(7)
    with writer:
        states = [writer.add_connection(topic, JOINT_STATE, typestore=store) for topic in topics]
        text = writer.add_connection("/robot_mode", STRING, typestore=store)
        switch = log.T // 2
        for k in range(log.T):
            ns = EPOCH_NS + int(np.rint(log.t[k] * 1e9))
            stamp = types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
            stamps.append((ns // 10**9, ns % 10**9))
            header_fields = {"stamp": stamp, "frame_id": ""}
            if ros1:
                header_fields["seq"] = k
            header = types["std_msgs/msg/Header"](**header_fields)
            names, index = _message_names(arm, k, switch)

            def row(values: np.ndarray, gripper: float, index: list[int] = index) -> np.ndarray:
                return np.array([gripper if j < 0 else values[j] for j in index])

            msg = types[JOINT_STATE](
                header=header,
                name=names,
                position=row(log.q[k], 0.04),
                velocity=row(log.qd[k], 0.0) if velocity else np.zeros(0),
                effort=row(log.tau[k], -3.0),
            )
            # received 2 ms (+ up to 0.5 ms) after the stamp, on the recorder's clock
            received = ns + 2_000_000 + int(rng.integers(0, 500_000))
            for connection in states:
                writer.write(connection, received, serialize(msg, JOINT_STATE))
            if k % 50 == 0:
                writer.write(text, received, serialize(types[STRING](data="running"), STRING))
    return stamps


@pytest.fixture(scope="module")
def simulated() -> tuple[dynid.Robot, dynid.Log]:
    """The UR5's exact torques (rnea with viscous friction) on a 3-harmonic trajectory, 200 Hz."""
    arm = _arm()
    return arm, fourier_log(arm, 3, seconds=2.0, fs=200.0)


@pytest.fixture(scope="module")
def bags(simulated, tmp_path_factory) -> dict[str, tuple[Path, list[tuple[int, int]]]]:
    arm, log = simulated
    folder = tmp_path_factory.mktemp("bags")
    return {
        kind: (folder / name, write_bag(folder / name, log, arm, kind=kind))
        for kind, name in (("mcap", "mcap_bag"), ("sqlite3", "sqlite_bag"), ("ros1", "run.bag"))
    }


def _expect(read: dynid.Log, log: dynid.Log, stamps: list[tuple[int, int]]) -> None:
    """``read`` is ``log`` exactly, with t the header stamps sec + nanosec * 1e-9."""
    np.testing.assert_array_equal(read.t, [sec + nanosec * 1e-9 for sec, nanosec in stamps])
    # and not the receive times: 5 ms steps on the stamps' clock
    np.testing.assert_allclose(np.diff(read.t), np.diff(log.t), rtol=0, atol=1e-6)
    np.testing.assert_array_equal(read.q, log.q)
    np.testing.assert_array_equal(read.qd, log.qd)
    np.testing.assert_array_equal(read.tau, log.tau)
    assert read.qdd is None


@pytest.mark.parametrize("kind", ["mcap", "sqlite3", "ros1"])
def test_bag_reads_back_the_simulated_arrays(kind, simulated, bags) -> None:
    arm, log = simulated
    path, stamps = bags[kind]
    read = read_ros_bag(path, joint_names=arm.joint_names)
    _expect(read, log, stamps)
    note = read.notes[-1]
    assert "topic /joint_states" in note and f"ignored joints {GRIPPER}" in note
    assert "2 different name lists" in note and "effort as joint torque" in note
    # load_log dispatches to it, and --skip acts on the bag's log
    again = load_log(path, joint_names=arm.joint_names, skip=3)
    np.testing.assert_array_equal(again.q, log.q[3:])


@pytest.mark.parametrize("kind", ["mcap", "sqlite3"])
def test_ros2_storage_file_reads_as_its_bag(kind, simulated, bags) -> None:
    arm, log = simulated
    folder, stamps = bags[kind]
    (storage,) = folder.glob("*.mcap" if kind == "mcap" else "*.db3")
    _expect(load_log(storage, joint_names=arm.joint_names), log, stamps)


def test_current_reads_effort_as_current(simulated, bags) -> None:
    arm, log = simulated
    read = load_log(bags["mcap"][0], joint_names=arm.joint_names, current=True)
    np.testing.assert_array_equal(read.tau, log.tau)  # the numbers in effort, as they are
    assert "effort as motor current" in read.notes[-1]


def test_velocity_left_out_when_a_message_lacks_it(simulated, tmp_path) -> None:
    arm, log = simulated
    stamps = write_bag(tmp_path / "bag", log, arm, kind="mcap", velocity=False)
    read = read_ros_bag(tmp_path / "bag", joint_names=arm.joint_names)
    assert read.qd is None and "no velocity" in read.notes[-1]
    np.testing.assert_array_equal(read.q, log.q)
    assert read.t[0] == stamps[0][0] + stamps[0][1] * 1e-9


def test_identify_a_bag_from_the_command_line(tmp_path, capsys) -> None:
    """`dynid identify BAG --model MODEL` with the model's joint names: the UR5's base parameters
    (rigid body and viscous friction) come back from positions, velocities and efforts, qdd
    differentiated from qd at 500 Hz (central differences: an error of (w dt)^2 / 6 ~ 1e-5 of
    the fastest harmonic)."""
    arm = _arm()
    log = fourier_log(arm, 4, seconds=10.0, fs=500.0)
    write_bag(tmp_path / "bag", log, arm, kind="mcap")
    model = save_model(dynid.models.ur5(), tmp_path / "ur5.json")  # the names, not the values
    out = tmp_path / "result"
    argv = ["identify", str(tmp_path / "bag"), "--model", str(model), "--friction"]
    assert main([*argv, "--method", "ols", "--output", str(out)]) == 0
    assert "[5/5] wrote" in capsys.readouterr().out
    result = load_result(out)
    expected = dynid.base_parameters(arm, friction=True).values(arm)
    error = np.abs(result.theta - expected) / np.abs(expected).max()
    assert error.max() < 1e-4, error.max()
    # the result's model record keeps the names, so `dynid validate` can match the bag again
    assert result.robot.joint_names == arm.joint_names
    assert main(["validate", str(out), str(tmp_path / "bag"), "--output", str(tmp_path / "v")]) == 0


def test_topic_chooses_among_several(simulated, tmp_path, capsys) -> None:
    arm, log = simulated
    stamps = write_bag(tmp_path / "bag", log, arm, kind="mcap", topics=("/a/joints", "/b/joints"))
    with pytest.raises(ValueError, match=r"2 sensor_msgs/msg/JointState topics \(/a/joints, /b/jo"):
        read_ros_bag(tmp_path / "bag", joint_names=arm.joint_names)
    with pytest.raises(ValueError, match="--topic"):
        read_ros_bag(tmp_path / "bag", joint_names=arm.joint_names)
    _expect(read_ros_bag(tmp_path / "bag", topic="/b/joints", joint_names=arm.joint_names),
            log, stamps)  # fmt: skip
    with pytest.raises(ValueError, match="topic: '/robot_mode' holds std_msgs/msg/String"):
        read_ros_bag(tmp_path / "bag", topic="/robot_mode", joint_names=arm.joint_names)
    with pytest.raises(ValueError, match="topic: no topic '/c'"):
        read_ros_bag(tmp_path / "bag", topic="/c", joint_names=arm.joint_names)
    # the command line: --topic, and the error as one line with exit 2
    model = save_model(dynid.models.ur5(), tmp_path / "ur5.json")
    argv = ["identify", str(tmp_path / "bag"), "--model", str(model), "--output"]
    assert main([*argv, str(tmp_path / "r1")]) == 2
    assert "choose one with topic= / --topic" in capsys.readouterr().err
    assert main([*argv, str(tmp_path / "r2"), "--topic", "/a/joints"]) == 0


def test_no_joint_state_topic(tmp_path) -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    with Writer2(tmp_path / "bag", version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        text = writer.add_connection("/robot_mode", STRING, typestore=store)
        writer.write(text, 1, store.serialize_cdr(store.types[STRING](data="idle"), STRING))
    with pytest.raises(ValueError, match=r"no sensor_msgs/msg/JointState topic.*/robot_mode"):
        read_ros_bag(tmp_path / "bag", joint_names=["a"])


def test_missing_joint_is_named(simulated, bags) -> None:
    arm, _ = simulated
    names = list(arm.joint_names)
    names[2] = "wrist_4_joint"
    with pytest.raises(ValueError, match="joint 'wrist_4_joint' of the model is not in"):
        read_ros_bag(bags["ros1"][0], joint_names=names)
    with pytest.raises(ValueError, match="wrist_4_joint"):  # through load_log: the file named
        load_log(bags["mcap"][0], joint_names=names)


def test_bad_arguments(simulated, bags, tmp_path) -> None:
    arm, _ = simulated
    path = bags["mcap"][0]
    assert [is_ros_bag(p) for p in (path, "a.bag", "b.MCAP", "c.db3", "d.csv", "e.npz")] == [
        True, True, True, True, False, False
    ]  # fmt: skip
    with pytest.raises(ValueError, match="joint_names: a ROS bag's joints are matched by name"):
        load_log(path)
    with pytest.raises(ValueError, match="joint_names: expected distinct"):
        read_ros_bag(path, joint_names=["a", "a"])
    with pytest.raises(ValueError, match="joint_names: expected a sequence of strings"):
        read_ros_bag(path, joint_names="shoulder_pan_joint")
    with pytest.raises(ValueError, match="columns, time_unit: not for a ROS bag"):
        load_log(path, joint_names=arm.joint_names, time_unit="ns")
    (tmp_path / "log.csv").write_text("t,q1,tau1\n0,0,0\n0.01,0,0\n")
    with pytest.raises(ValueError, match="topic: only for ROS bags"):
        load_log(tmp_path / "log.csv", topic="/joint_states")
    with pytest.raises(ValueError, match=r"without metadata\.yaml"):
        load_log(tmp_path, joint_names=arm.joint_names)
    (tmp_path / "broken.mcap").write_bytes(b"not a bag")
    with pytest.raises(ValueError, match=r"broken\.mcap: not a readable ROS bag"):
        load_log(tmp_path / "broken.mcap", joint_names=arm.joint_names)


def test_missing_extra_names_it(simulated, bags, monkeypatch) -> None:
    """Without rosbags (its import fails) the error says what to install."""
    arm, _ = simulated
    for module in [m for m in sys.modules if m == "rosbags" or m.startswith("rosbags.")]:
        monkeypatch.setitem(sys.modules, module, None)  # None: the import raises ImportError
    with pytest.raises(ValueError, match=r'needs the rosbags package.*pip install "dynid\[ros\]"'):
        load_log(bags["mcap"][0], joint_names=arm.joint_names)
