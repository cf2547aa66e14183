"""A robot model as text: what ``dynid info`` prints (DH table, limits, transforms, parameters,
drive terms and the base-parameter counts of docs/base_parameters.md, "Base parameters")."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..model import robot_fields
from ..model.base_parameters import base_parameters
from ..model.robot import Robot
from ..model.robot_fields import RobotField

#: What is printed as 0: values below this fraction of the scale they are read against (one part
#: in 10^9: below anything measured on a robot). URDF imports leave rounding residue (6e-17 rad
#: of alpha from cos(pi/2), 5e-12 rad from an rpy written with 9 digits, 1e-100 in a product of
#: inertia) that reads as if it meant something. Display only: the model keeps the exact values.
ROUNDING_RESIDUE = 1e-9


def shown(values: np.ndarray, scale: float) -> np.ndarray:
    """``values`` with |v| <= ROUNDING_RESIDUE * scale as 0 (never -0)."""
    values = np.asarray(values, dtype=float)
    return np.where(np.abs(values) <= ROUNDING_RESIDUE * scale, 0.0, values) + 0.0


def model_summary(robot: Robot) -> str:
    """The DH table with joint limits, base/tool transforms when not the identity, the standard
    parameters per link, the drive terms (with the transmission T when coupled) and the
    base-parameter counts per regressor kind. Rounding residue is printed as 0 (``shown``).

    Every field of dynid.model.robot_fields is printed, in the table's order, by its layout
    (``shown``); fields flagged ``omit_default`` only when they differ from their default."""
    lines = _title(robot) + _joint_table(robot)
    fresh = robot_fields.defaults(robot)
    for field in robot_fields.FIELDS:
        if not (field.omit_default and robot_fields.is_default(robot, field, fresh)):
            lines += _LAYOUTS[field.shown](robot, field)
    counts = [
        (label, base_parameters(robot, "torque", rotor=rotor, friction=friction).count)
        for label, rotor, friction in (
            ("rigid body", False, False),
            ("+ rotor", True, False),
            ("+ friction", False, True),
            ("+ rotor + friction", True, True),
        )
    ]
    lines.append(
        "base parameters: torque "
        + ", ".join(f"{c} ({label})" for label, c in counts)
        + f"; gravity {base_parameters(robot, 'gravity').count}; inertia "
        f"{base_parameters(robot, 'inertia').count}"
    )
    return "\n".join(lines)


def _title(robot: Robot) -> list[str]:
    """The fields shown "title": name, joints, convention and gravity on the first line."""
    return [
        f"{robot.name}: {robot.n} joints ({robot.joint_types}), {robot.convention} DH, "
        f"gravity {np.round(robot.gravity_vector, 6).tolist()}"
    ]


def _joint_table(robot: Robot) -> list[str]:
    """The DH table (field shown "joint table"), one row per joint, with a column per word of
    the label of each field shown "joint columns" (qlim: qmin, qmax)."""
    columns = [f for f in robot_fields.FIELDS if f.shown == "joint columns"]
    heads = ("a_{i-1}", "alpha_{i-1}") if robot.convention == "modified" else ("a", "alpha")
    lines = [
        f"  {'row':<4}{'type':<5}{heads[0]:>10}  {heads[1]:>16}  {'d':>10}  {'theta':>10}"
        + "".join(f"  {head:>8}" for f in columns for head in f.label.split())
    ]
    values = np.column_stack([np.asarray(getattr(robot, f.attribute)) for f in columns])
    # Lengths against the arm's size (1 m at least), angles against one radian.
    size = max(1.0, float(np.abs(robot.dh[:, [0, 2]]).max(initial=0.0)))
    for i, (dh, kind) in enumerate(zip(robot.dh, robot.joint_types)):
        row = np.where([True, False, True, False], shown(dh, size), shown(dh, 1.0))  # a, d; angles
        alpha = f"{row[1]:.6g} ({np.degrees(row[1]):.4g}°)"
        lines.append(
            f"  {i + 1:<4}{kind:<5}{row[0]:>10.6g}  {alpha:>16}  {row[2]:>10.6g}  "
            f"{row[3]:>10.6g}" + "".join(f"  {v:>8.4g}" for v in values[i])
        )
    return lines


def _transform(robot: Robot, field: RobotField) -> list[str]:
    value = np.asarray(getattr(robot, field.attribute))
    return [f"  {field.key}: {shown(np.round(value, 6), 1.0).tolist()}"]


def _links(robot: Robot, field: RobotField) -> list[str]:
    params = getattr(robot, field.attribute)
    lines = [
        "parameters (frame-i origin, standard order m mx my mz Ixx Ixy Ixz Iyy Iyz Izz); total "
        f"mass {params[:, 0].sum():.4g} kg, physically consistent: "
        f"{'yes' if robot.is_physically_consistent() else 'no'}"
    ]
    for i, row in enumerate(params):
        # Each quantity against its own kind in this link: mass, first moments, inertias.
        row = np.concatenate(
            [shown(row[:1], row[0]), shown(row[1:4], np.abs(row[1:4]).max()),
             shown(row[4:], np.abs(row[4:]).max())]
        )  # fmt: skip
        lines.append(f"  link {i + 1}:" + "".join(f"{v:>11.4g}" for v in row))
    return lines


def _per_joint(robot: Robot, field: RobotField) -> list[str]:
    label = field.label or field.key
    return [f"  {label}: " + " ".join(f"{v:.4g}" for v in getattr(robot, field.attribute))]


def _names(robot: Robot, field: RobotField) -> list[str]:
    return [f"  {field.label}: " + " ".join(getattr(robot, field.attribute))]


def _matrix(robot: Robot, field: RobotField) -> list[str]:
    rows = getattr(robot, field.attribute)
    return [f"  {field.label}:"] + ["    " + " ".join(f"{v:>8.4g}" for v in row) for row in rows]


def _printed_elsewhere(robot: Robot, field: RobotField) -> list[str]:
    return []  # in the title or the joint table


#: The printer of each layout of dynid.model.robot_fields.LAYOUTS.
_LAYOUTS: dict[str, Callable[[Robot, RobotField], list[str]]] = {
    "title": _printed_elsewhere,
    "joint table": _printed_elsewhere,
    "joint columns": _printed_elsewhere,
    "names": _names,
    "transform": _transform,
    "links": _links,
    "per joint": _per_joint,
    "matrix": _matrix,
}
