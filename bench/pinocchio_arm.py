"""The same DH arm as a dynid Robot, built as a Pinocchio model (no URDF).

dynid describes each link by its DH row and ten standard parameters about the origin of DH
frame i (docs/conventions.md). Pinocchio wants, per joint, a revolute-Z (or prismatic-Z) joint whose
placement is the constant part of the transform from the parent joint frame, and a body inertia
in the joint frame. The joint frame J_i is where the joint variable enters:

- standard DH, A_{i-1,i} = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i):
  J_i = F_{i-1} Rz(theta_i) Tz(d_i) and F_i = J_i Tx(a_i) Rx(alpha_i). Joint i's placement in
  J_{i-1} is therefore Tx(a_{i-1}) Rx(alpha_{i-1}) Rz(theta_off_i) Tz(d_off_i) (the base
  transform instead of the first factor for joint 1): Rz(q) and Tz commute, so Pinocchio's
  "placement, then Rz(q)" equals "Rz(theta_off + q) Tz(d)". Link i's inertia sits at
  Tx(a_i) Rx(alpha_i) in J_i.
- modified DH, A_{i-1,i} = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i): frame i is J_i, so
  the placement is the whole row at q = 0 and the inertia needs no offset.

The C++ benchmark (cpp/pinocchio_arm.hpp) builds the model the same way.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray


def _rot_x(angle: float) -> NDArray[np.float64]:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rot_z(angle: float) -> NDArray[np.float64]:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _se3(pin: Any, rotation: NDArray[np.float64], translation: NDArray[np.float64]) -> Any:
    return pin.SE3(np.ascontiguousarray(rotation), np.asarray(translation, dtype=float))


def pinocchio_parameters(pi: NDArray[np.float64]) -> NDArray[np.float64]:
    """dynid's [m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz] in Pinocchio's order.

    Pinocchio's dynamic parameters are [m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz], also
    about the frame origin: only Iyy and Ixz swap places.
    """
    return np.asarray(pi, dtype=float)[[0, 1, 2, 3, 4, 5, 7, 6, 8, 9]]


def build_model(robot: Any, pin: Any) -> Any:
    """A ``pinocchio.Model`` of ``robot`` (a dynid Robot): same kinematics, inertias, gravity.

    The rotor inertias become Pinocchio's ``armature`` (which rnea, crba and aba add as dynid
    adds Ia). Pinocchio has no joint friction in its dynamics, so compare with a robot whose
    ``Fv`` and ``Fs`` are zero.
    """
    dh = np.asarray(robot.dh, dtype=float)
    params = np.asarray(robot.params, dtype=float)
    base = np.asarray(robot.base, dtype=float)
    standard = robot.convention == "standard"
    model = pin.Model()
    parent = 0
    for i, (a, alpha, d, theta) in enumerate(dh):
        joint_motion = _rot_z(theta)  # Rz(theta_off) Tz(d_off): the part of the row at q = 0
        if standard:
            # F_{i-1} in J_{i-1}: the previous row's Tx(a) Rx(alpha), or the base for joint 1
            if i == 0:
                prev_rotation, prev_translation = base[:3, :3], base[:3, 3]
            else:
                prev_rotation = _rot_x(dh[i - 1, 1])
                prev_translation = np.array([dh[i - 1, 0], 0.0, 0.0])
            rotation = prev_rotation @ joint_motion
            translation = prev_translation + rotation @ np.array([0.0, 0.0, d])
            # link i's DH frame F_i = J_i Tx(a_i) Rx(alpha_i)
            body_frame = _se3(pin, _rot_x(alpha), np.array([a, 0.0, 0.0]))
        else:
            # Rx(alpha) Tx(a) Rz(theta) Tz(d), preceded by the base for joint 1
            row_rotation = _rot_x(alpha) @ joint_motion
            row_translation = _rot_x(alpha) @ np.array([a, 0.0, 0.0]) + row_rotation @ np.array(
                [0.0, 0.0, d]
            )
            prev_rotation = base[:3, :3] if i == 0 else np.eye(3)
            prev_translation = base[:3, 3] if i == 0 else np.zeros(3)
            rotation = prev_rotation @ row_rotation
            translation = prev_translation + prev_rotation @ row_translation
            body_frame = pin.SE3.Identity()
        joint = pin.JointModelRZ() if robot.joint_types[i] == "R" else pin.JointModelPZ()
        parent = model.addJoint(parent, joint, _se3(pin, rotation, translation), f"joint{i + 1}")
        inertia = pin.Inertia.FromDynamicParameters(pinocchio_parameters(params[i]))
        model.appendBodyToJoint(parent, inertia, body_frame)
    model.gravity = pin.Motion(np.asarray(robot.gravity_vector, dtype=float), np.zeros(3))
    model.armature = np.asarray(robot.Ia, dtype=float).copy()
    return model
