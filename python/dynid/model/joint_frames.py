"""The frames of a DH chain as a tree of joints, for the file formats that move a joint's child
about an axis through the child's origin (URDF, MJCF; docs/urdf.md, docs/export.md).

In those formats body i's frame is *joint i's frame*: z on joint i's axis, at q_i = 0 there.

- standard DH: frame i-1 turned by q_i (Rz(q_i), or Tz(q_i) if prismatic); DH frame i sits at
  K_i = A_i(q=0) = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) in it;
- modified DH: DH frame i without its own offsets, frame i-1 times Rx(alpha_{i-1}) Tx(a_{i-1})
  Rz(q_i); DH frame i sits at K_i = Rz(theta_i) Tz(d_i) in it (K_i = identity without offsets).

Every constant rotation between consecutive frames is then Rz(theta) Rx(alpha): no
decomposition near a singularity. The base transform is folded into joint 1's placement and
the tool transform is given in body n's frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]


@dataclass(frozen=True)
class JointFrames:
    """``placements[i]``: joint i+1's frame in its parent's (the world for joint 1, then body
    i's frame); ``dh_offsets[i]``: DH frame i+1 in body i+1's frame (K_{i+1}); ``tool``: the tool
    frame in body n's frame. All 4 x 4 homogeneous transforms."""

    placements: list[Array]
    dh_offsets: list[Array]
    tool: Array


def joint_frames(robot: Any) -> JointFrames:
    """The joint frames of ``robot`` (a :class:`dynid.Robot`), as the module docstring says."""
    dh = np.asarray(robot.dh, dtype=float)
    standard = robot.convention == "standard"
    placements, offsets = [], []
    parent_to_joint = robot.base @ (np.eye(4) if standard else rx_tx(dh[0]))
    for i in range(robot.n):
        a, alpha, d, theta = dh[i]
        offset = dh_offset(a, alpha, d, theta, standard)
        placements.append(parent_to_joint)
        offsets.append(offset)
        parent_to_joint = offset if standard or i + 1 == robot.n else offset @ rx_tx(dh[i + 1])
    return JointFrames(placements, offsets, parent_to_joint @ robot.tool)


def dh_offset(a: float, alpha: float, d: float, theta: float, standard: bool) -> Array:
    """K_i: DH frame i in body i's frame (the module docstring)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    pose = np.eye(4)
    pose[:3, :3] = [[ct, -st, 0.0], [st, ct, 0.0], [0.0, 0.0, 1.0]]
    pose[2, 3] = d
    if standard:
        pose[:3, :3] = pose[:3, :3] @ [[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]]
        pose[:2, 3] = a * ct, a * st
    return pose


def rx_tx(row: Array) -> Array:
    """Rx(alpha_{i-1}) Tx(a_{i-1}) of a modified row."""
    a, alpha = row[0], row[1]
    ca, sa = np.cos(alpha), np.sin(alpha)
    return np.array(
        [[1.0, 0.0, 0.0, a], [0.0, ca, -sa, 0.0], [0.0, sa, ca, 0.0], [0.0, 0.0, 0.0, 1.0]]
    )
