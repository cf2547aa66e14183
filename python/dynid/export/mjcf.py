"""A DH robot written as MuJoCo MJCF (docs/export.md, "MuJoCo").

MJCF is the one robot format with fields for every drive term of dynid's torque model
(docs/conventions.md, "Drive terms and the torque model"): the rotor inertia Ia is the joint's
``armature`` (added to M[i, i], as dynid adds it), viscous friction Fv its ``damping`` and
Coulomb friction Fs its ``frictionloss``. The bodies are the joint frames of
:mod:`dynid.model.joint_frames` (body i: z on joint i's axis), nested from the world body; each
body's ``inertial`` holds the link's mass, centre of mass and full inertia about it, expressed in
the body's axes (``fullinertia``, so MuJoCo's own eigen-decomposition chooses the principal
axes). Gravity is ``<option gravity>``; the tool frame is a ``site``; one ``motor`` actuator per
joint (gear 1, unlimited) lets a controller apply joint torques.

MuJoCo's mass matrix (``mj_fullM``) is then dynid's M(q) and its bias force (``mj_rne`` without
accelerations) dynid's C(q, qd) qd + g(q): tests/test_mjcf.py checks both to 1e-9 at random
states. Damping and frictionloss act through MuJoCo's passive forces and friction constraints.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from ..model.joint_frames import joint_frames
from ..model.urdf.consistency import check_writable, physical_form
from ..model.urdf.writing import write_urdf as write_text

#: What MuJoCo needs of a body and a joint (its compiler refuses the rest).
BODY_RULE = (
    "a MuJoCo body needs m > 0 and a positive definite inertia about its centre of mass that "
    "satisfies the triangle inequalities"
)
JOINT_RULE = "armature (Ia), damping (Fv) and frictionloss (Fs) cannot be negative"


def mjcf_text(robot: Any, name: str | None = None) -> str:
    """The MJCF of ``robot`` (a :class:`dynid.Robot`) as text; ``name`` the model's name
    (default: the robot's). ValueError naming the first link or joint that MuJoCo would refuse,
    and for a robot with coupled drives (MJCF's joint fields are per joint)."""
    name = robot.name if name is None else name
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"name: expected a non-empty model name, got {name!r}")
    check_writable(robot, "MJCF", "armature, damping and frictionloss", BODY_RULE, JOINT_RULE)
    names = list(robot.joint_names)
    frames = joint_frames(robot)
    root = ET.Element("mujoco", model=name)
    root.append(
        ET.Comment(
            f" Written by dynid from a {robot.n}-joint {robot.convention}-DH model. Body i's frame "
            "is joint i's frame (z on its axis); armature = rotor inertia Ia, damping = Fv, "
            "frictionloss = Fs; a motor's ctrlrange is the joint's effort limit (MJCF has no "
            "velocity limit). "
        )
    )
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    ET.SubElement(root, "option", gravity=_vector(robot.gravity_vector))
    parent = ET.SubElement(root, "worldbody")
    for i in range(robot.n):
        placement, offset = frames.placements[i], frames.dh_offsets[i]
        body = ET.SubElement(
            parent,
            "body",
            name=robot.link_names[i],
            pos=_vector(placement[:3, 3]),
            quat=_vector(_quaternion(placement[:3, :3])),
        )
        attributes = {
            "name": names[i],
            "type": "slide" if robot.joint_types[i] == "P" else "hinge",
            "axis": "0 0 1",
            "armature": _number(robot.Ia[i]),
            "damping": _number(robot.Fv[i]),
            "frictionloss": _number(robot.Fs[i]),
        }
        lower, upper = robot.qlim[i]
        if np.isfinite(lower) and np.isfinite(upper):
            attributes["range"] = _vector([lower, upper])
        ET.SubElement(body, "joint", attributes)
        mass, com, inertia = physical_form(robot.params[i])
        R = offset[:3, :3]  # DH frame i's axes in the body's
        inertia_in_body = R @ inertia @ R.T
        ET.SubElement(
            body,
            "inertial",
            pos=_vector(R @ com + offset[:3, 3]),
            mass=_number(mass),
            fullinertia=_vector(inertia_in_body[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]),
        )
        parent = body
    ET.SubElement(
        parent,
        "site",
        name="tool",
        pos=_vector(frames.tool[:3, 3]),
        quat=_vector(_quaternion(frames.tool[:3, :3])),
    )
    actuators = ET.SubElement(root, "actuator")
    for joint, effort in zip(names, robot.effort_limits):
        motor = {"name": f"{joint}_motor", "joint": joint, "gear": "1"}
        if np.isfinite(effort):  # gear 1: the control is the joint torque (autolimits)
            motor["ctrlrange"] = _vector([-effort, effort])
        ET.SubElement(actuators, "motor", motor)
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def write_mjcf(
    robot: Any, path: str | Path, *, name: str | None = None, overwrite: bool = False
) -> Path:
    """Write ``robot`` as MJCF to ``path``, atomically (the file is whole or absent); an
    existing file is a ValueError unless ``overwrite``."""
    return write_text(mjcf_text(robot, name), path, overwrite=overwrite)


def _quaternion(rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """MuJoCo's (w, x, y, z) of a rotation matrix."""
    x, y, z, w = Rotation.from_matrix(rotation).as_quat()
    return np.array([w, x, y, z])


def _number(value: float) -> str:
    return repr(float(value) + 0.0)  # shortest text reading back to the same double; no -0.0


def _vector(values: Any) -> str:
    return " ".join(_number(v) for v in np.asarray(values, dtype=float).ravel())
