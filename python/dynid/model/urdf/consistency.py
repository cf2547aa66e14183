"""The one rule a robot obeys in URDF, applied by both directions (docs/urdf.md).

- A body: m > 0 and an inertia about its centre of mass that is positive definite and satisfies
  the triangle inequalities (``_core.physical_inconsistency``, the rule of ``set_link`` and
  ``Robot.is_physically_consistent``). URDF consumers (simulators, Pinocchio's algorithms) need
  it. In a URDF read by dynid a body is everything that moves with one joint: a massless frame
  link fixed to a link with mass is no body of its own, and is fine.
- A joint: damping (Fv), friction (Fs) and dynid's rotor inertia (Ia) >= 0 (negative ones feed
  energy into the motion).

``to_urdf`` refuses a robot that breaks it; ``from_urdf`` refuses such a file unless called with
``check_physical=False`` (to read the file and repair it).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ... import _core

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]

BODY_RULE = (
    "a URDF link needs m > 0 and a positive definite inertia about its centre of mass that "
    "satisfies the triangle inequalities"
)
JOINT_RULE = "damping, friction and rotor inertia cannot be negative"


def physical_form(params: Array) -> tuple[float, Array, Array]:
    """Mass, centre of mass and inertia about the centre of mass (axes of the parameters' frame)
    of one link's standard parameters [m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz]; the centre
    of mass is taken at the origin when m <= 0."""
    mass = float(params[0])
    com = np.asarray(params[1:4], dtype=float) / mass if mass > 0.0 else np.zeros(3)
    about_origin = np.array(
        [
            [params[4], params[5], params[6]],
            [params[5], params[7], params[8]],
            [params[6], params[8], params[9]],
        ]
    )
    return mass, com, about_origin - mass * ((com @ com) * np.eye(3) - np.outer(com, com))


def body_inconsistency(params: Array) -> str:
    """Why a body with these standard parameters breaks the rule ('' if it does not)."""
    mass, _, inertia = physical_form(params)
    if not mass > 0.0:
        return f"mass {mass!r} is not positive"
    return _core.physical_inconsistency(mass, inertia)


def joint_inconsistency(Ia: float, Fv: float, Fs: float) -> str:
    """Why a joint with these drive terms breaks the rule ('' if it does not)."""
    negative = [
        f"{name} {float(value)!r}"
        for name, value in (("damping (Fv)", Fv), ("friction (Fs)", Fs), ("rotor inertia Ia", Ia))
        if not value >= 0.0
    ]
    return f"negative {', '.join(negative)}" if negative else ""


def check_writable(robot: Any, where: str, per_joint: str, body_rule: str, joint_rule: str) -> None:
    """Refuse, naming the transmission, link or joint, a robot that a file format with one body
    per link and per-joint drive fields (``per_joint``: URDF's ``<dynamics>``, MJCF's armature,
    damping and frictionloss) cannot hold: coupled drives, a link that is no rigid body
    (``body_rule``), negative drive terms (``joint_rule``). ``where``: "a URDF", "MJCF"."""
    if robot.coupled:
        raise ValueError(
            f"transmission: a robot with coupled drives (transmission not the identity) cannot be "
            f"written as {where.split()[-1]}, whose {per_joint} are per joint; save it with "
            "dynid.save_model (a model file keeps the transmission), or write "
            "robot.rigid_body()"
        )
    for i in range(robot.n):
        why = body_inconsistency(robot.params[i])
        if why:
            raise ValueError(
                f"robot: link {i + 1} is not physically consistent ({why}); {body_rule}"
            )
        why = joint_inconsistency(robot.Ia[i], robot.Fv[i], robot.Fs[i])
        if why:
            raise ValueError(f"robot: joint {i + 1} has {why}; in {where} {joint_rule}")
