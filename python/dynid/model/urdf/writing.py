"""A DH robot written as URDF text (docs/urdf.md), and written to a file atomically.

Links ``base_link`` (the world, massless), ``link1`` .. ``linkn`` (the DH links) and ``tool``
(massless, at the tool transform); joints named by ``robot.joint_names`` (``q1`` .. ``qn`` by
default, a URDF's own names when the robot was read from one; revolute or prismatic, axis z) and
the fixed ``tool_joint``.

URDF moves a joint's child about (along) an axis through the child's origin, so URDF link i's
frame is *joint i's frame* (:mod:`dynid.model.joint_frames`: where each joint sits, and DH frame
i in link i's frame, K_i). Every constant rotation between consecutive frames is then
Rz(theta) Rx(alpha), whose URDF ``rpy`` is exactly (alpha, 0, theta): no decomposition near a
singularity. Only the base and tool rotations are decomposed into rpy (general rotations).

Each link's inertial is written about its centre of mass with an ``<origin>`` whose axes are
those of DH frame i (rpy of K_i), so the inertia tensor is the robot's, unrotated. The rotor
inertia Ia has no URDF field: it is written in a comment inside the joint,
``<!-- dynid: Ia="..." ... -->``, which :meth:`dynid.Robot.from_urdf` reads back and every other
parser ignores.
"""

from __future__ import annotations

import os
import re
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..joint_frames import joint_frames
from .consistency import BODY_RULE, JOINT_RULE, check_writable, physical_form
from .tree import UNLIMITED

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]


# The characters XML 1.0 does not allow in a document (its Char production): C0 controls other
# than tab, newline and carriage return, surrogates, U+FFFE and U+FFFF.
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def urdf_text(robot: Any, name: str = "robot") -> str:
    """The URDF of ``robot`` (a :class:`dynid.Robot`) as text. ValueError naming the first link
    or joint that breaks the rule of :mod:`.consistency` (URDF consumers need m > 0, a positive
    definite inertia that satisfies the triangle inequalities, and damping, friction and rotor
    inertia >= 0), the rule that :meth:`dynid.Robot.from_urdf` applies to what it reads.
    ValueError naming ``transmission`` for a robot with coupled drives: URDF's per-joint
    ``<dynamics>`` cannot hold per-motor friction mapped through T (docs/transmission.md; a
    model file keeps it)."""
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"name: expected a non-empty robot name, got {name!r}")
    if _NOT_XML.search(name):  # ElementTree writes them as they are: the file would not parse
        raise ValueError(
            f"name: expected characters that XML 1.0 allows (no control characters), got {name!r}"
        )
    for field in ("joint_names", "link_names"):
        bad = [label for label in getattr(robot, field) if _NOT_XML.search(label)]
        if bad:
            raise ValueError(f"{field}: {bad[0]!r} has characters that XML 1.0 does not allow")
    base_link = _free("base_link", robot.link_names)
    tool_link = _free("tool", robot.link_names)
    tool_joint_name = _free("tool_joint", robot.joint_names)
    check_writable(robot, "a URDF", "joint <dynamics>", BODY_RULE, JOINT_RULE)
    links = [physical_form(robot.params[i]) for i in range(robot.n)]
    frames = joint_frames(robot)
    root = ET.Element("robot", name=name)
    root.append(
        ET.Comment(
            f" Written by dynid from a {robot.n}-joint {robot.convention}-DH model. Link i's frame "
            "is joint i's frame (z on its axis); the inertial origins give DH frame i's axes. "
            f"Velocity and effort limits the model does not know are written as {UNLIMITED:g} "
            "(no limit; dynid reads that value back as none): set your arm's. "
        )
    )
    ET.SubElement(root, "link", name=base_link)
    for i in range(robot.n):
        parent_to_joint = frames.placements[i]
        offset = frames.dh_offsets[i]  # DH frame i in URDF link i's frame
        mass, com, inertia = links[i]
        link = ET.SubElement(root, "link", name=robot.link_names[i])
        inertial = ET.SubElement(link, "inertial")
        ET.SubElement(
            inertial,
            "origin",
            xyz=_vector(offset[:3, :3] @ com + offset[:3, 3]),
            rpy=_vector(rpy(offset[:3, :3])),
        )
        ET.SubElement(inertial, "mass", value=_number(mass))
        ET.SubElement(inertial, "inertia", inertia_attributes(inertia))
        kind = "prismatic" if robot.joint_types[i] == "P" else "revolute"
        joint = ET.SubElement(root, "joint", name=robot.joint_names[i], type=kind)
        joint.append(
            ET.Comment(
                f' dynid: Ia="{_number(robot.Ia[i])}" (reflected rotor inertia [kg m^2], '
                "added to M[i, i]; URDF has no field for it) "
            )
        )
        ET.SubElement(joint, "parent", link=base_link if i == 0 else robot.link_names[i - 1])
        ET.SubElement(joint, "child", link=robot.link_names[i])
        ET.SubElement(
            joint,
            "origin",
            xyz=_vector(parent_to_joint[:3, 3]),
            rpy=_vector(rpy(parent_to_joint[:3, :3])),
        )
        ET.SubElement(joint, "axis", xyz="0 0 1")
        lower, upper = robot.qlim[i]
        ET.SubElement(
            joint,
            "limit",
            lower=_number(lower),
            upper=_number(upper),
            effort=_limit(robot.effort_limits[i]),
            velocity=_limit(robot.velocity_limits[i]),
        )
        ET.SubElement(
            joint, "dynamics", damping=_number(robot.Fv[i]), friction=_number(robot.Fs[i])
        )
    ET.SubElement(root, "link", name=tool_link)
    tool_joint = ET.SubElement(root, "joint", name=tool_joint_name, type="fixed")
    ET.SubElement(tool_joint, "parent", link=robot.link_names[-1])
    ET.SubElement(tool_joint, "child", link=tool_link)
    tool = frames.tool
    ET.SubElement(tool_joint, "origin", xyz=_vector(tool[:3, 3]), rpy=_vector(rpy(tool[:3, :3])))
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _free(name: str, taken: Any) -> str:
    """``name``, or ``name_dynid`` (then ``name_dynid2``, ...) when the robot's names hold it."""
    candidate, k = name, 1
    while candidate in taken:
        candidate = f"{name}_dynid{k if k > 1 else ''}"
        k += 1
    return candidate


def _limit(value: float) -> str:
    """A velocity or effort limit: UNLIMITED for none (inf), never 0."""
    return _number(value) if np.isfinite(value) else f"{UNLIMITED:g}"


def write_urdf(text: str, path: str | Path, overwrite: bool = False) -> Path:
    """Write ``text`` to ``path`` through a temporary file and a rename (the file is whole or
    absent). An existing file is a ValueError unless ``overwrite``."""
    if not isinstance(overwrite, bool):
        raise ValueError(f"overwrite: expected True or False, got {overwrite!r}")
    if not isinstance(path, (str, Path)) or not str(path).strip():
        raise ValueError(f"path: expected a file path, got {path!r}")
    target = Path(path)
    if target.is_dir():
        raise ValueError(f"path: {target} is a folder")
    if target.exists() and not overwrite:
        raise ValueError(f"path: {target} exists; pass overwrite=True (--overwrite) to replace it")
    handle, temporary = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return target


def rpy(rotation: Array) -> Array:
    """URDF roll, pitch, yaw of a rotation matrix (R = Rz(yaw) Ry(pitch) Rx(roll))."""
    cos_pitch = float(np.hypot(rotation[0, 0], rotation[1, 0]))
    pitch = float(np.arctan2(-rotation[2, 0], cos_pitch))
    if cos_pitch < 1e-10:  # gimbal lock: roll and yaw share an axis; put it all in roll
        return np.array([np.arctan2(-rotation[1, 2], rotation[1, 1]), pitch, 0.0])
    return np.array(
        [
            np.arctan2(rotation[2, 1], rotation[2, 2]),
            pitch,
            np.arctan2(rotation[1, 0], rotation[0, 0]),
        ]
    )


def inertia_attributes(inertia: Array) -> dict[str, str]:
    """URDF's <inertia> attributes (ixx, ixy, ixz, iyy, iyz, izz) of a 3 x 3 inertia."""
    entries = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2)}
    entries["izz"] = (2, 2)
    return {key: _number(inertia[r, c]) for key, (r, c) in entries.items()}


def _number(value: float) -> str:
    return repr(float(value) + 0.0)  # shortest text reading back to the same double; no -0.0


def _vector(values: Array) -> str:
    return " ".join(_number(v) for v in values)
