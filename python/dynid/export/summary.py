"""A robot model as text: what ``dynid info`` prints (DH table, limits, transforms, parameters,
drive terms and the base-parameter counts of SPEC section 3)."""

from __future__ import annotations

import numpy as np

from ..model.base_parameters import base_parameters
from ..model.robot import Robot

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
    base-parameter counts per regressor kind. Rounding residue is printed as 0 (``shown``)."""
    lines = [
        f"{robot.name}: {robot.n} joints ({robot.joint_types}), {robot.convention} DH, "
        f"gravity {np.round(robot.gravity_vector, 6).tolist()}"
    ]
    heads = ("a_{i-1}", "alpha_{i-1}") if robot.convention == "modified" else ("a", "alpha")
    lines.append(
        f"  {'row':<4}{'type':<5}{heads[0]:>10}  {heads[1]:>16}  {'d':>10}  "
        f"{'theta':>10}  {'qmin':>8}  {'qmax':>8}"
    )
    # Lengths against the arm's size (1 m at least), angles against one radian.
    size = max(1.0, float(np.abs(robot.dh[:, [0, 2]]).max(initial=0.0)))
    for i, (dh, kind, lim) in enumerate(zip(robot.dh, robot.joint_types, robot.qlim)):
        row = np.where([True, False, True, False], shown(dh, size), shown(dh, 1.0))  # a, d; angles
        alpha = f"{row[1]:.6g} ({np.degrees(row[1]):.4g}°)"
        lines.append(
            f"  {i + 1:<4}{kind:<5}{row[0]:>10.6g}  {alpha:>16}  {row[2]:>10.6g}  "
            f"{row[3]:>10.6g}  {lim[0]:>8.4g}  {lim[1]:>8.4g}"
        )
    for key in ("base", "tool"):
        value = np.asarray(getattr(robot, key))
        if not np.array_equal(value, np.eye(4)):
            lines.append(f"  {key}: {shown(np.round(value, 6), 1.0).tolist()}")
    params = robot.params
    lines.append(
        "parameters (frame-i origin, SPEC order m mx my mz Ixx Ixy Ixz Iyy Iyz Izz); total "
        f"mass {params[:, 0].sum():.4g} kg, physically consistent: "
        f"{'yes' if robot.is_physically_consistent() else 'no'}"
    )
    for i, row in enumerate(params):
        # Each quantity against its own kind in this link: mass, first moments, inertias.
        row = np.concatenate(
            [shown(row[:1], row[0]), shown(row[1:4], np.abs(row[1:4]).max()),
             shown(row[4:], np.abs(row[4:]).max())]
        )  # fmt: skip
        lines.append(f"  link {i + 1}:" + "".join(f"{v:>11.4g}" for v in row))
    for key in ("Ia", "Fv", "Fs"):
        lines.append(f"  {key}: " + " ".join(f"{v:.4g}" for v in getattr(robot, key)))
    if robot.coupled:
        lines.append("  transmission T (motor velocities T qd; Ia, Fv, Fs per motor):")
        lines.extend("    " + " ".join(f"{v:>8.4g}" for v in row) for row in robot.transmission)
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
