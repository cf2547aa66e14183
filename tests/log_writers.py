"""Log files written as the robots' own tools write them, from a simulated arm (the tests of
dynid.logs.readers). Each writer is kept to its tool's source, cited, and independent of dynid's
readers: the column names, the delimiters and the number formatting are the tool's.

The trajectory is a 3-harmonic Fourier series per joint in closed form (q, qd, qdd exact) and the
torque the robot's inverse dynamics (``robot.rnea``: rigid body, rotor inertia, friction).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

import dynid


@dataclass
class Motion:
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray


def simulate(robot: dynid.Robot, seed: int, seconds: float, fs: float) -> Motion:
    """Base frequency 0.2 Hz, harmonics 1..3, amplitudes decreasing as 1/k."""
    rng = np.random.default_rng(seed)
    n, w = robot.n, 2 * np.pi * 0.2
    t = np.arange(round(seconds * fs)) / fs
    tt = t[:, None]
    q, qd, qdd = (np.zeros((t.size, n)) for _ in range(3))
    for k in range(1, 4):
        a, b = rng.normal(scale=0.5 / k, size=(2, n))
        s, c = np.sin(k * w * tt), np.cos(k * w * tt)
        q += (a * s - b * c) / (k * w)
        qd += a * c + b * s
        qdd += k * w * (b * c - a * s)
    return Motion(t, q, qd, qdd, robot.rnea(q, qd, qdd))


def cpp_default(x: float) -> str:
    """A double as ``std::ostream << x`` writes it by default: 6 significant digits, %g."""
    return f"{x:g}"


# ------------------------------------------------------------------------------ UR RTDE

RTDE_GROUPS = (
    "target_q", "target_qd", "target_current", "target_moment",
    "actual_q", "actual_qd", "actual_current", "actual_current_window",
)  # fmt: skip


def write_rtde(path: Path, m: Motion, *, current: np.ndarray, delimiter: str = " ") -> None:
    """UR's RTDE client library ``examples/record.py`` (csv writer with delimiter " ") or
    ur_rtde's ``startFileRecording`` (","): ``timestamp`` then each VECTOR6D field as
    ``name_0 .. name_5``; values as Python's ``str`` of the float. The target signals are the
    actual ones (a perfect tracking), ``actual_current_window`` a constant."""
    n = m.q.shape[1]
    header = ["timestamp"] + [f"{g}_{j}" for g in RTDE_GROUPS for j in range(n)]
    blocks = {
        "target_q": m.q, "target_qd": m.qd, "target_current": current, "target_moment": m.tau,
        "actual_q": m.q, "actual_qd": m.qd, "actual_current": current,
        "actual_current_window": np.full_like(m.q, 0.5),
    }  # fmt: skip
    table = np.column_stack([m.t] + [blocks[g] for g in RTDE_GROUPS])
    with path.open("w", encoding="utf-8") as handle:
        handle.write(delimiter.join(header) + "\n")
        for row in table:
            handle.write(delimiter.join(str(float(x)) for x in row) + "\n")


# ------------------------------------------------------------------------------ libfranka


def write_libfranka(path: Path, m: Motion, *, old_header: bool = False) -> None:
    """``franka::logToCSV`` (libfranka src/log.cpp; src/logging/robot_state_log.cpp): the
    robot state's and the command's arrays, ``name[i]`` per element, names of a group separated
    by ", " in the old file and "," in the new one; ``time`` in whole ms (``toMSec``), doubles
    with the stream's default 6 significant digits."""
    sep = ", " if old_header else ","
    n = 7

    def names(name: str, size: int) -> str:
        return sep.join(f"{name}[{i}]" for i in range(size))

    state = ["state.q", "state.q_d", "state.dq", "state.dq_d", "state.tau_J",
             "state.tau_ext_hat_filtered"]  # fmt: skip
    command = [("cmd.q_d", 7), ("cmd.dq_d", 7), ("cmd.O_T_EE_d", 16), ("cmd.O_dP_EE_d", 6),
               ("cmd.tau_J_d", 7)]  # fmt: skip
    header = (
        f"time{sep}success_rate{sep}"
        + ",".join(names(s, n) for s in state)
        + ","
        + ",".join(names(c, size) for c, size in command)
    )
    zeros7, pose, twist = np.zeros(7), np.eye(4).ravel(order="F"), np.zeros(6)
    with path.open("w", encoding="utf-8") as handle:
        handle.write(header + "\n")
        for k in range(m.t.size):
            state_values = [m.q[k], m.q[k], m.qd[k], m.qd[k], m.tau[k], zeros7]
            command_values = [m.q[k], m.qd[k], pose, twist, zeros7]
            fields = [str(round(m.t[k] * 1000)), cpp_default(1.0)]
            fields += [cpp_default(x) for arr in state_values + command_values for x in arr]
            handle.write(",".join(fields) + "\n")


# ------------------------------------------------------------------------------ pyfri


def write_pyfri(path: Path, m: Motion, *, start_sec: int = 1_700_000_000) -> None:
    """pyfri's ``ClientApplication.collect_data`` (lbr-stack/pyfri, src/wrapper.cpp):
    ``index,time,record_time_nsec,tsec,tnsec,mp1..mp7,ip1..ip7,mt1..mt7,et1..et7,dt``, each value
    followed by ","; doubles with 6 significant digits, the controller's time as whole seconds
    and nanoseconds."""
    n = 7
    header = ["index", "time", "record_time_nsec", "tsec", "tnsec"]
    header += [f"{p}{j}" for p in ("mp", "ip", "mt", "et") for j in range(1, n + 1)] + ["dt"]
    ns = np.round(m.t * 1e9).astype(np.int64) + 250_000_000  # starts a quarter second in
    dt = m.t[1] - m.t[0]
    with path.open("w", encoding="utf-8") as handle:
        handle.write(",".join(header) + "\n")
        for k in range(m.t.size):
            fields = [str(k), cpp_default(k * dt), str(1_700_000_000_000_000_000 + int(ns[k]))]
            fields += [str(start_sec + int(ns[k] // 10**9)), str(int(ns[k] % 10**9))]
            for values in (m.q[k], m.q[k], m.tau[k], np.zeros(n)):
                fields += [cpp_default(x) for x in values]
            fields.append(cpp_default(dt))
            handle.write(",".join(fields) + "\n")


# ------------------------------------------------------------------------------ ROS CSV


def write_rostopic_csv(path: Path, m: Motion, names: list[str], stamp0: int) -> None:
    """``rostopic echo -p /joint_states`` (ROS 1): ``%time`` (ns), the header fields, then
    ``field.name0..``, ``field.position0..``, ``field.velocity0..``, ``field.effort0..``; the
    names are text columns."""
    n = len(names)
    header = ["%time", "field.header.seq", "field.header.stamp", "field.header.frame_id"]
    for group in ("name", "position", "velocity", "effort"):
        header += [f"field.{group}{j}" for j in range(n)]
    stamps = stamp0 + np.round(m.t * 1e9).astype(np.int64)
    with path.open("w", encoding="utf-8") as handle:
        handle.write(",".join(header) + "\n")
        for k in range(m.t.size):
            fields = [str(stamps[k]), str(k), str(stamps[k]), "", *names]
            for values in (m.q[k], m.qd[k], m.tau[k]):
                fields += [repr(float(x)) for x in values]
            handle.write(",".join(fields) + "\n")
