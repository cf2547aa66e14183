"""A robot's parameters written into the user's own URDF (``dynid export --urdf OUT --into
USER.urdf``; docs/export.md, "Into your own URDF").

Only what dynid identifies changes: each chain link's ``<inertial>`` and each chain joint's
``<dynamics damping friction>`` and rotor-inertia comment (``<!-- dynid: Ia="..." -->``, which
``Robot.from_urdf`` reads; URDF has no field for it). Everything else -- link and joint names,
meshes, limits, ``ros2_control`` and Gazebo tags, comments, the text before and after the root
element -- is kept.

The robot's parameters live in its DH frames; the URDF's inertials live in its link frames.
``express_in_frames_of`` first carries the parameters to the DH frames that ``Robot.from_urdf``
assigns to this URDF's chain (checking that both describe the same arm), then each body is moved
into the frame of the URDF link that its joint moves (a constant transform: both frames are fixed
to the same body). A body of the DH model is that link plus the links fixed to it
(``Robot.from_urdf`` merges them): the fixed links keep their own inertials and the moving link
gets the rest, unless the rest is not a body that can exist (then the moving link gets the whole
body and the fixed links' inertials are removed, with a warning naming them).
"""

from __future__ import annotations

import re
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..model.link_frames import express_in_frames_of
from ..model.robot import Robot
from ..model.urdf.consistency import body_inconsistency, joint_inconsistency, physical_form
from ..model.urdf.reading import (
    _bodies,
    _dh_frames_at_zero,
    _poses_at_zero,
    dh_model_from_urdf,
    standard_parameters,
)
from ..model.urdf.tree import MOVABLE, ROTOR_COMMENT, _text, read_tree, serial_chain
from ..model.urdf.writing import _number, _vector, inertia_attributes

_NAMESPACE = re.compile(r'xmlns:([A-Za-z_][\w.-]*)\s*=\s*"([^"]*)"')


def urdf_into_text(
    robot: Robot,
    urdf: str | Path,
    *,
    base_link: str | None = None,
    tip_link: str | None = None,
) -> str:
    """The text of ``urdf`` (a path or the XML) with ``robot``'s link inertials and joint drive
    terms in place of its own. ValueError when the robot is not the arm of the URDF's chain
    (from ``base_link`` to ``tip_link``), has coupled drives, or has a link or joint that a URDF
    cannot hold (the rule of ``to_urdf``)."""
    if robot.coupled:
        raise ValueError(
            "transmission: a robot with coupled drives cannot be written into a URDF, whose "
            "joint <dynamics> are per joint; write robot.rigid_body()"
        )
    for i in range(robot.n):
        why = joint_inconsistency(robot.Ia[i], robot.Fv[i], robot.Fs[i])
        if why:
            raise ValueError(f"robot: joint {i + 1} has {why}")
    raw = _text(urdf)
    text = raw.decode("utf-8") if isinstance(raw, bytes) else raw
    target = Robot.from_urdf(
        text,
        base_link=base_link,
        tip_link=tip_link,
        convention=robot.convention,
        gravity=robot.gravity_vector,
        check_physical=False,
    )
    try:
        moved = express_in_frames_of(robot, target)
    except ValueError as exc:
        raise ValueError(f"into: the robot is not the arm of this URDF's chain ({exc})") from None
    tree = read_tree(text)
    chain = serial_chain(tree, base_link, tip_link)
    joints = [joint for joint in chain if joint.type in MOVABLE]
    model = dh_model_from_urdf(text, base_link, tip_link, robot.convention, check_physical=False)
    poses = _poses_at_zero(tree, chain[0].parent)
    frames = _dh_frames_at_zero(model.dh, model.base, robot.convention)[1:]
    bodies = _bodies(tree, joints)

    for prefix, uri in _NAMESPACE.findall(text):  # keep the file's own prefixes
        ET.register_namespace(prefix, uri)
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True, insert_pis=True))
    root = ET.fromstring(text, parser=parser)
    links = {element.get("name"): element for element in root.findall("link")}
    joint_elements = {element.get("name"): element for element in root.findall("joint")}
    for i, joint in enumerate(joints):
        to_dh = np.linalg.inv(frames[i])
        params = np.array(moved.params[i], dtype=float)
        fixed = [link for link in bodies[i] if link != joint.child and tree.links[link] is not None]
        rest = params.copy()
        for link in fixed:
            inertial = tree.links[link]
            assert inertial is not None
            rest -= standard_parameters(
                inertial.mass, to_dh @ poses[link] @ inertial.origin, inertial.inertia
            )
        if fixed and body_inconsistency(rest):
            warnings.warn(
                f"into: link {joint.child!r} minus the links fixed to it ({', '.join(fixed)}) is "
                "no body that can exist; the whole identified body is written into "
                f"{joint.child!r} and the inertials of {', '.join(fixed)} are removed",
                UserWarning,
                stacklevel=2,
            )
            rest = params
            for link in fixed:
                element = links[link]
                for inertial_element in element.findall("inertial"):
                    element.remove(inertial_element)
        why = body_inconsistency(rest)
        if why:
            raise ValueError(
                f"robot: link {i + 1} (URDF link {joint.child!r}) is not physically consistent "
                f"({why}); a URDF link needs m > 0 and a positive definite inertia about its "
                "centre of mass that satisfies the triangle inequalities"
            )
        # DH frame i in the URDF link's frame: constant, both are fixed to the body.
        pose = np.linalg.inv(poses[joint.child]) @ frames[i]
        _set_inertial(links[joint.child], rest, pose)
        _set_drive_terms(joint_elements[joint.name], robot.Ia[i], robot.Fv[i], robot.Fs[i])
    body = ET.tostring(root, encoding="unicode")
    # The root's start tag as the user wrote it (ElementTree drops namespace declarations no
    # element uses, e.g. xmlns:xacro), and the text around the root (comments, declaration).
    start = re.search(r"<robot\b[^>]*>", text)
    end = text.rfind("</robot>")
    if start is not None:
        body = re.sub(r"<robot\b[^>]*>", lambda _: start.group(0), body, count=1)
    before = text[: start.start()] if start else ""
    after = text[end + len("</robot>") :] if end >= 0 else "\n"
    return before + body + after


#: Entries below this fraction of the largest of their kind are rounding (frame changes of
#: zeros) and written as 0: 1e-14 relative, far below any identified value's precision.
ROUNDING = 1e-14


def _set_inertial(link: ET.Element, params: NDArray[np.float64], pose: NDArray[np.float64]) -> None:
    """Set the link's <inertial> to the body of ``params``, given in the frame whose pose in the
    link's frame is ``pose``: centre of mass and inertia in the link's axes. The existing
    <origin>, <mass>, <inertia> elements are updated in place (their order, other attributes and
    the user's comments kept); missing ones are added."""
    mass, com, inertia = physical_form(params)
    R = pose[:3, :3]
    com_link = _cleaned(R @ com + pose[:3, 3])
    inertia_link = _cleaned(R @ inertia @ R.T)
    element = link.find("inertial")
    if element is None:  # a new first child, indented as the link's children are
        outer = link.text if link.text and link.text.strip() == "" else "\n"
        element = ET.Element("inertial")
        element.tail = outer if len(link) else _closing_indent(outer)
        element.text = outer + "  "
        link.insert(0, element)
        link.text = outer
    values = {
        "origin": {"xyz": _vector(com_link), "rpy": "0 0 0"},
        "mass": {"value": _number(mass)},
        "inertia": inertia_attributes(inertia_link),
    }
    for tag, attributes in values.items():
        child = element.find(tag)
        if child is None:
            child = ET.SubElement(element, tag)
            if len(element) > 1:  # indented as its siblings, before the closing tag
                previous = element[-2]
                child.tail, previous.tail = previous.tail, element.text
            else:
                child.tail = _closing_indent(element.text or "")
        for key, value in attributes.items():
            child.set(key, value)


def _cleaned(values: NDArray[np.float64]) -> NDArray[np.float64]:
    scale = float(np.abs(values).max())
    return np.where(np.abs(values) < ROUNDING * scale, 0.0, values)


def _closing_indent(indent: str) -> str:
    """The whitespace before an element's closing tag, from that before its children."""
    if "\n" not in indent:
        return indent
    head, _, spaces = indent.rpartition("\n")
    return head + "\n" + spaces[: max(0, len(spaces) - 2)]


def _set_drive_terms(joint: ET.Element, Ia: float, Fv: float, Fs: float) -> None:
    """Set <dynamics damping friction> (other attributes kept) and the rotor-inertia comment."""
    dynamics = joint.find("dynamics")
    if dynamics is None:
        dynamics = ET.SubElement(joint, "dynamics")
        if len(joint) > 1:
            previous = joint[-2]
            dynamics.tail, previous.tail = previous.tail, joint.text
    dynamics.set("damping", _number(Fv))
    dynamics.set("friction", _number(Fs))
    comment_text = (
        f' dynid: Ia="{_number(Ia)}" (reflected rotor inertia [kg m^2], added to M[i, i]) '
    )
    for comment in joint.iter(ET.Comment):  # type: ignore[arg-type]
        if ROTOR_COMMENT.search(comment.text or ""):
            comment.text = comment_text
            return
    if Ia != 0.0:
        added = ET.Comment(comment_text)
        added.tail = joint.text
        joint.insert(0, added)
