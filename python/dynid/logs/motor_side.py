"""Motor-side logs mapped to the joint side (issue 20, item 1; docs/data.md, "Motor-side logs").

A drive's encoder and current loop see the motor, not the joint: motor angles theta (before the
gear) and motor torques tau_m. With the gear ratios N (motor angle over joint angle) and the
transmission coupling T of the robot (docs/transmission.md: theta_dot / N = T q_dot), the
motors turn as

    theta = R (q + joint_offsets),   R = diag(N) T                       (notes p. 11-12)

so q = R^-1 theta - joint_offsets, and by virtual work (theta_dot^T tau_m = q_dot^T R^T tau_m)
the joint torques are tau = R^T tau_m. ``joint_offsets`` are the joint angles R^-1 theta at the
model's zero (the Staubli TX40: (0, pi/2, -pi/2, 0, 0, 0), the README's q2 - pi/2, q3 + pi/2).
The velocities and accelerations of a log that has them map as q (without the offsets).

This module reads the robot's fields only (``gear_ratios``, ``transmission``, ``joint_offsets``);
it imports nothing of the model (docs/architecture.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .log import Log

if TYPE_CHECKING:
    from ..model.robot import Robot


def motor_matrix(robot: Robot) -> NDArray[np.float64]:
    """R = diag(gear_ratios) T: motor angles theta = R (q + joint_offsets)."""
    gear_ratios = np.asarray(robot.gear_ratios, dtype=float)
    return gear_ratios[:, None] * np.asarray(robot.transmission, dtype=float)


def motor_to_joint(log: Log, robot: Robot) -> Log:
    """The joint-side log of a motor-side ``log`` (motor angles in ``q``, motor torques in
    ``tau``): q = R^-1 theta - joint_offsets, tau = R^T tau_m with R = diag(gear_ratios) T of
    ``robot``. ValueError naming ``log`` or ``robot`` when they do not fit."""
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    if not all(hasattr(robot, name) for name in ("gear_ratios", "transmission", "joint_offsets")):
        raise ValueError(f"robot: expected a dynid.Robot, got {type(robot).__name__}")
    if log.n != robot.n:
        raise ValueError(
            f"log: has {log.n} motors (columns) but the robot has {robot.n} joints; a motor-side "
            "log holds one motor per joint"
        )
    R = motor_matrix(robot)
    offsets = np.asarray(robot.joint_offsets, dtype=float)

    def joint_side(theta: NDArray[np.float64]) -> NDArray[np.float64]:
        # R^-1 theta for every sample at once: solve R X = theta^T (R is invertible: the
        # transmission's check and non-zero gear ratios).
        return np.ascontiguousarray(np.linalg.solve(R, theta.T).T)

    arrays = {"q": joint_side(log.q) - offsets, "tau": log.tau @ R}  # rows: (R^T tau_m)^T
    for name in ("qd", "qdd"):
        value = getattr(log, name)
        if value is not None:
            arrays[name] = joint_side(value)
    coupled = not np.array_equal(robot.transmission, np.eye(robot.n))
    ratios = np.array2string(np.asarray(robot.gear_ratios), separator=", ")
    note = (
        "motor side mapped to the joints: q = R^-1 theta - joint_offsets, tau = R^T tau_m, "
        f"R = diag(gear_ratios) T (gear ratios {ratios}{', coupled' if coupled else ''})"
    )
    return log.replace(note=note, **arrays)
