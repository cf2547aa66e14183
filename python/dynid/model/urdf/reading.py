"""A URDF serial chain as a DH model: table, base and tool, standard parameters, limits, friction.

Bodies: body i (i = 1..n) is everything that moves rigidly with joint i's child link at q = 0:
the links reached from it through fixed joints, and also through joints off the chain, which
are held at position 0 (the fingers of a gripper, say; Pinocchio's ``buildReducedModel`` with
the zero configuration does the same). Links that do not move with any chain joint (the base
and what is fixed to it, links above ``base_link``) belong to the world and are left out.

The bodies so merged and the chain's joints must obey the rule ``to_urdf`` applies
(:mod:`.consistency`), unless ``check_physical=False``: a massless frame link merged into a body
with mass is no body of its own.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ... import _checks as checks
from .consistency import BODY_RULE, JOINT_RULE, body_inconsistency, joint_inconsistency
from .frames import PARALLEL, dh_frames, dh_modified, dh_standard, nearly_parallel
from .tree import MOVABLE, Joint, UrdfTree, read_tree, serial_chain

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]


@dataclass
class DHModel:
    """What ``Robot.from_dh`` needs, and the drive terms, read from a URDF."""

    name: str
    dh: Array  # (n, 4)
    joint_types: str
    convention: str
    base: Array  # (4, 4)
    tool: Array  # (4, 4)
    params: Array  # (n, 10)
    qlim: Array  # (n, 2)
    velocity_limits: Array  # (n,), inf: none
    effort_limits: Array  # (n,), inf: none
    Ia: Array  # (n,)
    Fv: Array
    Fs: Array
    joint_names: list[str]
    link_names: list[str]  # child link of each joint


def dh_model_from_urdf(
    urdf: str | Path,
    base_link: str | None = None,
    tip_link: str | None = None,
    convention: str = "standard",
    check_physical: bool = True,
) -> DHModel:
    """Read ``urdf`` (a path or the XML text) into a DH model (see
    :meth:`dynid.Robot.from_urdf`)."""
    if convention not in ("standard", "modified"):
        raise ValueError(f"convention: expected 'standard' or 'modified', got {convention!r}")
    check_physical = checks.flag(check_physical, "check_physical")
    tree = read_tree(urdf)
    chain = serial_chain(tree, base_link, tip_link)
    poses = _poses_at_zero(tree, chain[0].parent)  # links below base_link, in its coordinates
    joints = [joint for joint in chain if joint.type in MOVABLE]
    # joint i's axis at q = 0: through the child's origin, along the axis in the child's axes
    points = np.array([poses[j.child][:3, 3] for j in joints])
    axes = np.array([poses[j.child][:3, :3] @ j.axis for j in joints])
    _warn_nearly_parallel(joints, axes)
    tip = poses[chain[-1].child]
    dh, base_pose = dh_frames(points, axes, tip, convention)
    frames = _dh_frames_at_zero(dh, base_pose, convention)
    bodies = _bodies(tree, joints)
    model = DHModel(
        name=tree.name,
        dh=dh,
        joint_types="".join("P" if j.type == "prismatic" else "R" for j in joints),
        convention=convention,
        base=base_pose,
        tool=np.linalg.inv(frames[-1]) @ tip,
        params=_link_parameters(tree, bodies, poses, frames[1:]),
        qlim=np.array([_limits(j) for j in joints]),
        velocity_limits=np.array([j.velocity_limit for j in joints]),
        effort_limits=np.array([j.effort_limit for j in joints]),
        Ia=np.array([j.rotor_inertia for j in joints]),
        Fv=np.array([j.damping for j in joints]),
        Fs=np.array([j.friction for j in joints]),
        joint_names=[j.name for j in joints],
        link_names=[j.child for j in joints],
    )
    if check_physical:
        _check_physical(tree, joints, bodies, model)
    return model


def _link_parameters(
    tree: UrdfTree, bodies: list[list[str]], poses: dict[str, Array], frames: list[Array]
) -> Array:
    """(n, 10): the inertials of body i (see the module docstring) in DH frame i, summed (zero
    for a body without any)."""
    params = np.zeros((len(bodies), 10))
    for i, links in enumerate(bodies):
        to_frame = np.linalg.inv(frames[i])
        for link in links:
            inertial = tree.links[link]
            if inertial is not None:
                params[i] += standard_parameters(
                    inertial.mass, to_frame @ poses[link] @ inertial.origin, inertial.inertia
                )
    return params


def _check_physical(
    tree: UrdfTree, joints: list[Joint], bodies: list[list[str]], model: DHModel
) -> None:
    """Refuse what ``to_urdf`` refuses (the rule of :mod:`.consistency`), applied to the bodies
    as merged: a massless link fixed to one with mass is no body of its own. Names the link (and
    those merged into it) or the joint."""
    repair = "Robot.from_urdf(..., check_physical=False) reads it anyway (to repair it)"
    for i, joint in enumerate(joints):
        with_inertial = [link for link in bodies[i] if tree.links[link] is not None]
        merged = [link for link in with_inertial if link != joint.child]
        body = f"link {joint.child!r} (moved by joint {joint.name!r}"
        if merged:
            more = ", ..." if len(merged) > 5 else ""
            body += f"; merged with {', '.join(repr(link) for link in merged[:5])}{more}"
        body += ")"
        if not with_inertial:
            raise ValueError(f"{body} has no <inertial>, nor has any link fixed to it; {repair}")
        why = body_inconsistency(model.params[i])
        if why:
            raise ValueError(f"{body} is not physically consistent ({why}); {BODY_RULE}; {repair}")
        why = joint_inconsistency(model.Ia[i], model.Fv[i], model.Fs[i])
        if why:
            raise ValueError(f"joint {joint.name!r} has {why}; {JOINT_RULE}; {repair}")


def _warn_nearly_parallel(joints: list[Joint], axes: Array) -> None:
    for i, angle in nearly_parallel(axes):
        # treated as parallel: axes misplaced by ~angle; else the common normal is ~1/angle away
        # and parameters about it lose ~eps / angle^2 (measured against Pinocchio: docs/urdf.md)
        snapped = angle < PARALLEL
        error = angle if snapped else 2.2e-16 / angle**2
        warnings.warn(
            f"joints {joints[i].name!r} and {joints[i + 1].name!r}: axes {angle:.1e} rad from "
            f"parallel, {'treated as parallel' if snapped else 'common normal far away'}; a DH "
            f"table cannot represent them exactly: expect errors of ~{error:.0e} relative "
            "(docs/urdf.md)",
            stacklevel=4,
        )  # the caller of Robot.from_urdf


def standard_parameters(mass: float, pose: Array, inertia: Array) -> Array:
    """[m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz] about a frame's origin (docs/conventions.md,
    "Inertial parameters") of a body of ``mass`` whose centre-of-mass frame has ``pose`` in that
    frame and whose inertia about the centre of mass is ``inertia`` in centre-of-mass axes: rotate
    it (R I R^T), then Steiner."""
    rotation, c = pose[:3, :3], pose[:3, 3]
    about_origin = rotation @ inertia @ rotation.T + mass * ((c @ c) * np.eye(3) - np.outer(c, c))
    i = 0.5 * (about_origin + about_origin.T)
    return np.array([mass, *(mass * c), i[0, 0], i[0, 1], i[0, 2], i[1, 1], i[1, 2], i[2, 2]])


def _limits(joint: Joint) -> tuple[float, float]:
    # Continuous joints have no limits in URDF (any <limit lower upper> is ignored, as the URDF
    # specification says); one turn, (-pi, pi], is what qlim then holds. A revolute or prismatic
    # joint without lower/upper gets Robot's defaults: (-pi, pi) and (-1, 1) m.
    if joint.limits is not None:
        return joint.limits
    return (-1.0, 1.0) if joint.type == "prismatic" else (-np.pi, np.pi)


def _poses_at_zero(tree: UrdfTree, base: str) -> dict[str, Array]:
    """Every link below ``base`` (and ``base``) -> its pose in base coordinates, joints at 0."""
    poses = {base: np.eye(4)}
    stack = [base]
    while stack:
        link = stack.pop()
        for joint in tree.children(link):
            poses[joint.child] = poses[link] @ joint.origin
            stack.append(joint.child)
    return poses


def _bodies(tree: UrdfTree, joints: list[Joint]) -> list[list[str]]:
    """The links of body i (moved by chain joint i, 0-based), joint i's child first; links of the
    world left out."""
    index = {joint.child: i for i, joint in enumerate(joints)}
    bodies: list[list[str]] = [[] for _ in joints]
    stack = [(joint.child, i) for i, joint in enumerate(joints)]
    while stack:
        link, body = stack.pop()
        bodies[body].append(link)
        for joint in tree.children(link):
            if joint.child not in index:  # not the next chain joint's child
                stack.append((joint.child, body))
    return bodies


def _dh_frames_at_zero(dh: Array, base: Array, convention: str) -> list[Array]:
    """Poses of DH frames 0..n at q = 0 (base times the rows' transforms)."""
    transform = dh_standard if convention == "standard" else dh_modified
    frames = [base]
    for row in dh:
        frames.append(frames[-1] @ transform(*row))
    return frames
