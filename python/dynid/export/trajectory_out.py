"""The files of ``dynid excite``: an experiment's trajectory as controllers and dynid read it.

Written into one folder, whole or not at all (:func:`dynid.export.output_folder.output_folder`):

- ``trajectory.json``: :func:`dynid.excitation.trajectory_files.trajectory_to_dict`, read back by
  :func:`dynid.excitation.load_trajectory`;
- ``trajectory.csv``: dynid's CSV log layout (docs/data.md, "CSV":
  ``t,q1..,qd1..,qdd1..,tau1..``, each number in the shortest text that reads back exactly) at
  the controller rate, tau the torque the model predicts; the joint names in a comment line, so
  that ``dynid.load_log`` reads it as a log;
- ``trajectory_ros.yaml``: a ROS 2 ``trajectory_msgs/msg/JointTrajectory`` as YAML;
- ``trajectory.hpp``: :mod:`dynid.export.trajectory_cpp`.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..excitation.trajectory_files import ExperimentTrajectory, trajectory_to_dict
from .output_folder import PathLike, output_folder
from .trajectory_cpp import cpp_header

if TYPE_CHECKING:
    from ..model.robot import Robot

FILES = ("trajectory.json", "trajectory.csv", "trajectory_ros.yaml", "trajectory.hpp")


def save_trajectory_folder(
    plan: ExperimentTrajectory,
    model: Robot,
    folder: PathLike,
    *,
    rate: float = 1000.0,
    ros_rate: float = 100.0,
    overwrite: bool = False,
    inputs: Iterable[PathLike | None] = (),
    report: bool = False,
) -> Path:
    """Write the four files of ``plan`` into ``folder`` (see the module), and with ``report``
    report.html (:mod:`dynid.export.report_excite`: the trajectory against its limits);
    ``model`` predicts the torque (rnea: links, rotor inertia, friction). Returns the folder."""
    if model.n != plan.trajectory.n:
        raise ValueError(f"model: expected {plan.trajectory.n} joints, got {model.n}")
    t = plan.times(rate)
    ros_t = plan.times(ros_rate)
    with output_folder(folder, overwrite, inputs=inputs) as staging:
        text = json.dumps(trajectory_to_dict(plan), indent=1, allow_nan=False) + "\n"
        (staging / "trajectory.json").write_text(text, encoding="utf-8")
        (staging / "trajectory.csv").write_text(trajectory_csv(plan, model, t), encoding="utf-8")
        (staging / "trajectory_ros.yaml").write_text(ros_yaml(plan, ros_t), encoding="utf-8")
        (staging / "trajectory.hpp").write_text(cpp_header(plan), encoding="utf-8")
        if report:
            from .report import write_page  # matplotlib: imported when the page is written
            from .report_excite import excite_sections

            write_page(
                staging, f"dynid excite: {plan.model or model.name}", excite_sections(plan, model)
            )
    return Path(folder)


def trajectory_csv(plan: ExperimentTrajectory, model: Robot, t: NDArray[np.float64]) -> str:
    """t, q, qd, qdd and the predicted tau at times ``t``, dynid's CSV layout."""
    q, qd, qdd = plan.evaluate(t)
    tau = model.rnea(q, qd, qdd)
    n = plan.trajectory.n
    header = ["t"] + [f"{s}{j}" for s in ("q", "qd", "qdd", "tau") for j in range(1, n + 1)]
    rows = np.column_stack([t, q, qd, qdd, tau])
    lines = [
        f"# dynid excite: model {plan.model!r}, {plan.periods} period(s) of "
        f"{plan.trajectory.period:.17g} s, ramp {plan.ramp}; tau predicted by the model",
        "# joint_names: " + ", ".join(plan.joint_names),
        ",".join(header),
    ]
    lines += [",".join(map(repr, row.tolist())) for row in rows]  # shortest exact text
    return "\n".join(lines) + "\n"


def ros_yaml(plan: ExperimentTrajectory, t: NDArray[np.float64]) -> str:
    """A ROS 2 trajectory_msgs/msg/JointTrajectory (header, joint_names, points with positions,
    velocities, accelerations, empty effort, time_from_start {sec, nanosec}) as YAML."""
    q, qd, qdd = plan.evaluate(t)
    names = ", ".join(json.dumps(name) for name in plan.joint_names)  # JSON strings are YAML
    lines = [
        "# trajectory_msgs/msg/JointTrajectory written by dynid excite",
        "header:",
        "  stamp: {sec: 0, nanosec: 0}",
        "  frame_id: ''",
        f"joint_names: [{names}]",
        "points:",
    ]
    nanoseconds = np.rint(t * 1e9).astype(np.int64)
    for k in range(t.size):
        sec, nanosec = divmod(int(nanoseconds[k]), 1_000_000_000)
        lines += [
            f"  - positions: {_flow(q[k])}",
            f"    velocities: {_flow(qd[k])}",
            f"    accelerations: {_flow(qdd[k])}",
            "    effort: []",
            f"    time_from_start: {{sec: {sec}, nanosec: {nanosec}}}",
        ]
    return "\n".join(lines) + "\n"


def _flow(values: NDArray[np.float64]) -> str:
    return "[" + ", ".join(_yaml_float(v) for v in values) + "]"


def _yaml_float(value: float) -> str:
    """17 significant digits in a form every YAML reader takes as a float: YAML 1.1 (PyYAML)
    needs a point in the mantissa and a signed exponent ("1.0e-05", not "1e-05")."""
    text = repr(float(value))
    mantissa, _, exponent = text.partition("e")
    if "." not in mantissa:
        mantissa += ".0"
    return mantissa + ("e" + exponent if exponent else "")
