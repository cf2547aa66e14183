"""The files of `dynid excite` (issue 21, item 1; docs/excitation.md, "Files"): trajectory.json
reloads exactly, the CSV and the ROS YAML parse back (dynid.load_log, numpy, PyYAML) and hold the
series summed term by term here and the torque of robot.rnea, and trajectory.hpp compiled with
g++ equals the Python evaluation at 1,000 times to 1e-12 without allocating."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest
import yaml

import dynid
from cpp_programs import find_compiler
from dynid.excitation import ExperimentTrajectory, FourierTrajectory, load_trajectory, rest_to_rest
from dynid.excitation.joint_limits import urdf_velocity_effort
from dynid.export.trajectory_out import FILES, save_trajectory_folder

SEED = 2611


def series(traj: FourierTrajectory, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """q, qd, qdd summed term by term from Swevers et al.'s formula (docs/excitation.md)."""
    q = np.tile(traj.q0, (t.size, 1))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    for i in range(traj.n):
        for ell in range(1, traj.harmonics + 1):
            w = traj.base_frequency * ell
            a, b = traj.a[i, ell - 1], traj.b[i, ell - 1]
            q[:, i] += a / w * np.sin(w * t) - b / w * np.cos(w * t)
            qd[:, i] += a * np.cos(w * t) + b * np.sin(w * t)
            qdd[:, i] += w * (-a * np.sin(w * t) + b * np.cos(w * t))
    return q, qd, qdd


@pytest.fixture(scope="module")
def robot() -> dynid.Robot:
    return dynid.models.kuka_lwr4()


@pytest.fixture(scope="module")
def plan(robot) -> ExperimentTrajectory:
    rng = np.random.default_rng(SEED)
    traj = rest_to_rest(
        FourierTrajectory(
            2 * np.pi / 1.5,
            0.3 * rng.normal(size=(robot.n, 4)),
            0.3 * rng.normal(size=(robot.n, 4)),
            rng.uniform(-0.5, 0.5, robot.n),
        )
    )
    limits = {"qd_max": [1.0] * robot.n, "tau_max": None}
    return ExperimentTrajectory(traj, robot.joint_names, periods=2, limits=limits, model="lwr")


@pytest.fixture(scope="module")
def folder(plan, robot, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("excite") / "out"
    save_trajectory_folder(plan, robot, out, rate=200.0, ros_rate=50.0)
    return out


def test_the_folder_holds_the_four_files(folder) -> None:
    assert sorted(p.name for p in folder.iterdir() if not p.name.startswith(".")) == sorted(FILES)


def test_json_reloads_the_same_trajectory(plan, folder) -> None:
    loaded = load_trajectory(folder / "trajectory.json")
    assert load_trajectory(folder).joint_names == plan.joint_names  # the folder works too
    for name in ("a", "b", "q0"):
        assert np.array_equal(getattr(loaded.trajectory, name), getattr(plan.trajectory, name))
    assert loaded.trajectory.base_frequency == plan.trajectory.base_frequency
    assert (loaded.periods, loaded.ramp, loaded.model) == (2, "rest_to_rest", "lwr")
    assert loaded.limits == plan.limits and loaded.duration == pytest.approx(3.0, rel=1e-15)


def test_csv_parses_back_as_a_log_and_holds_the_series_and_rnea(plan, robot, folder) -> None:
    log = dynid.load_log(folder / "trajectory.csv")
    t = np.arange(601) / 200.0  # 0 .. 3 s inclusive: the end at rest is in the file
    np.testing.assert_array_equal(log.t, t)
    q, qd, qdd = series(plan.trajectory, t)
    np.testing.assert_allclose(log.q, q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(log.qd, qd, rtol=0, atol=1e-12)
    np.testing.assert_allclose(log.qdd, qdd, rtol=0, atol=1e-12)
    # at rest (t = 0, 1.5, 3 s) qd is 0, not rounding noise: the Coulomb torque sign(0) = 0
    at_rest = np.isin(t, [0.0, 1.5, 3.0])
    qd[at_rest], qdd[at_rest] = 0.0, 0.0
    np.testing.assert_allclose(log.tau, robot.rnea(q, qd, qdd), rtol=0, atol=1e-10)
    table = np.loadtxt(folder / "trajectory.csv", delimiter=",", comments="#", skiprows=3)
    assert table.shape == (601, 1 + 4 * robot.n)
    text = (folder / "trajectory.csv").read_text()
    assert "# joint_names: " + ", ".join(robot.joint_names) in text
    # starts and ends at rest, at the same position
    for row in (0, -1):
        np.testing.assert_allclose(log.qd[row], 0.0, atol=1e-12)
        np.testing.assert_allclose(log.qdd[row], 0.0, atol=1e-12)
    np.testing.assert_allclose(log.q[0], log.q[-1], atol=1e-12)


def test_ros_yaml_is_a_joint_trajectory_message(plan, folder) -> None:
    message = yaml.safe_load((folder / "trajectory_ros.yaml").read_text())
    assert set(message) == {"header", "joint_names", "points"}
    assert message["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    assert message["joint_names"] == list(plan.joint_names)
    points = message["points"]
    assert len(points) == 151  # 50 Hz over 3 s, both ends
    t = np.array(
        [p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"] for p in points]
    )
    np.testing.assert_allclose(t, np.arange(151) / 50.0, rtol=0, atol=1e-12)
    assert all(0 <= p["time_from_start"]["nanosec"] < 10**9 for p in points)
    q, qd, qdd = series(plan.trajectory, np.arange(151) / 50.0)
    for key, expected in (("positions", q), ("velocities", qd), ("accelerations", qdd)):
        values = np.array([p[key] for p in points], dtype=float)  # floats, not strings
        np.testing.assert_allclose(values, expected, rtol=0, atol=1e-12)
    assert all(p["effort"] == [] for p in points)


DRIVER = r"""
#include "trajectory.hpp"
#include <cstdio>
#include <cstdlib>
#include <new>

static long allocations = 0;
void* operator new(std::size_t size) {
  ++allocations;
  void* p = std::malloc(size ? size : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

int main() {
  using namespace dynid_trajectory;
  static double times[100000], out[100000][3 * kJoints];
  int count = 0;
  while (count < 100000 && std::scanf("%lf", &times[count]) == 1) ++count;
  const long before = allocations;
  for (int k = 0; k < count; ++k) {
    evaluate(times[k], out[k], out[k] + kJoints, out[k] + 2 * kJoints);
  }
  std::array<double, kJoints> q{}, qd{}, qdd{};
  evaluate(0.5 * kPeriod, q, qd, qdd);
  const long during = allocations - before;
  for (int k = 0; k < count; ++k) {
    for (std::size_t i = 0; i < 3 * kJoints; ++i) std::printf("%.17g ", out[k][i]);
    std::printf("\n");
  }
  std::printf("allocations %ld %s %.17g\n", during, kJointNames[kJoints - 1], q[0]);
  return 0;
}
"""


def test_cpp_header_compiled_with_gxx_equals_python_to_1e_12(plan, folder, tmp_path) -> None:
    compiler = find_compiler()
    if compiler is None:
        pytest.skip("needs a C++ compiler (CXX, g++, c++, clang++)")
    (tmp_path / "driver.cpp").write_text(DRIVER)
    program = tmp_path / "driver"
    subprocess.run(
        [compiler, "-std=c++17", "-O2", "-Wall", "-Wextra", "-Wpedantic", "-Werror",
         "-I", str(folder), str(tmp_path / "driver.cpp"), "-o", str(program)],
        check=True, capture_output=True, text=True,
    )  # fmt: skip
    rng = np.random.default_rng(SEED + 1)
    t = np.concatenate([[0.0, plan.duration, -0.5, plan.duration + 0.5], rng.uniform(0, 3, 996)])
    run = subprocess.run(
        [str(program)], input="\n".join(map(repr, t.tolist())), capture_output=True, text=True,
        check=True,
    )  # fmt: skip
    lines = run.stdout.strip().splitlines()
    values = np.array([line.split() for line in lines[:-1]], dtype=float)
    assert values.shape == (1000, 3 * plan.trajectory.n)
    q, qd, qdd = plan.evaluate(t)
    np.testing.assert_allclose(values, np.hstack([q, qd, qdd]), rtol=0, atol=1e-12)
    # and both the term-by-term series (t clamped to [0, duration]: at rest outside)
    expected = np.hstack(series(plan.trajectory, np.clip(t, 0.0, plan.duration)))
    np.testing.assert_allclose(values, expected, rtol=0, atol=1e-12)
    _, count, last_name, q_half = lines[-1].split()
    assert count == "0" and last_name == plan.joint_names[-1]
    assert float(q_half) == pytest.approx(
        plan.evaluate(0.5 * plan.trajectory.period)[0][0], abs=1e-12
    )


def test_a_trajectory_not_at_rest_is_refused(plan) -> None:
    moving = FourierTrajectory(1.0, np.ones((7, 2)), np.ones((7, 2)), np.zeros(7))
    with pytest.raises(ValueError, match="rest_to_rest"):
        ExperimentTrajectory(moving, plan.joint_names)
    with pytest.raises(ValueError, match="joint_names"):
        ExperimentTrajectory(plan.trajectory, ("a", "b"))
    with pytest.raises(ValueError, match="periods"):
        ExperimentTrajectory(plan.trajectory, plan.joint_names, periods=0)
    with pytest.raises(ValueError, match="ramp"):
        ExperimentTrajectory(plan.trajectory, plan.joint_names, ramp="quintic")
    with pytest.raises(ValueError, match="rate"):
        plan.times(0.0)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda d: d.update(format="other"), "format"),
        (lambda d: d.pop("a"), "a: missing"),
        (lambda d: d.update(b=[[1.0]]), "b"),
        (lambda d: d.update(joint_names="q1"), "joint_names"),
        (lambda d: d.update(periods=1.5), "periods"),
        (lambda d: d.update(limits=[1]), "limits"),
    ],
)
def test_bad_trajectory_files_raise_value_error_naming_the_field(folder, tmp_path, change, field):
    data = json.loads((folder / "trajectory.json").read_text())
    change(data)
    path = tmp_path / "trajectory.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=field):
        load_trajectory(path)


def test_malformed_json_is_a_value_error_naming_the_file(tmp_path) -> None:
    path = tmp_path / "trajectory.json"
    path.write_text("{not json")
    with pytest.raises(ValueError, match="malformed JSON"):
        load_trajectory(path)


URDF = """<robot name="r">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <limit lower="-1" upper="1" effort="80" velocity="2.5"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <limit lower="-1" upper="1" effort="0" velocity="0"/></joint>
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/></joint>
</robot>"""


def test_urdf_velocity_and_effort_limits_by_joint_name(tmp_path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(URDF)
    velocity, effort = urdf_velocity_effort(path, ["j3", "j1", "j2"])
    np.testing.assert_array_equal(velocity, [np.nan, 2.5, np.nan])  # 0 means "not given"
    np.testing.assert_array_equal(effort, [np.nan, 80.0, np.nan])
    path.write_text(URDF.replace('effort="80"', 'effort="-3"'))
    with pytest.raises(ValueError, match="'j1' <limit effort='-3'>"):
        urdf_velocity_effort(path, ["j1"])
