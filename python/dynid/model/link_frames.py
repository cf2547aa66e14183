"""One arm described by two DH tables: the link frames of both, and the standard parameters of
one model re-expressed in the frames of the other (e.g. a URDF or CAD prior for identification
with another DH table of the same arm).

Two tables describe the same arm when, for every link i, its frames in both are fixed to the same
body: W_i(q) = C W'_i(q) X_i for all q, with X_i a constant transform and C a constant change of
world frame that leaves gravity alone (here: a translation; the worlds' axes must agree). Only
the translations are unknown once the rotations are checked: p_i(q) - p'_i(q) = t + R'_i(q) x_i is
linear in t and x_1..x_n, solved by least squares on random configurations and checked exact.
The parameters then follow from the pseudo-inertia (:mod:`dynid.model.pseudo_inertia`): with
r' = R_X r + x the coordinates in frame i' of a point given in frame i,
J' = T J T^T (T = [[R_X, x], [0, 1]]), so J = T^-1 J' T^-T.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .. import _core
from . import robot_fields
from .pseudo_inertia import pseudo_inertia, standard_from_pseudo_inertia
from .robot import Robot

#: Configurations at which the frames are compared.
SAMPLES = 8

#: Rotations and positions must agree to this (relative to the arm's size for positions).
TOLERANCE = 1e-9


def link_frames(robot: Robot, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """World poses (T, n, 4, 4) of the DH frames 1..n at the configurations q (T, n): base ·
    A_1 ... A_i (the tool transform excluded), from one C++ forward pass per sample
    (``dynid::link_frames``, cpp/src/kinematics.cpp)."""
    frames: NDArray[np.float64] = _core._link_frames(robot, np.atleast_2d(q))
    return frames


def express_in_frames_of(model: Robot, robot: Robot) -> Robot:
    """A copy of ``robot`` carrying ``model``'s standard parameters (and drive terms)
    re-expressed in ``robot``'s DH frames. ValueError naming ``model`` unless both describe the
    same arm (same joints, same joint variables, link frames on the same bodies, worlds differing
    by a translation, same gravity)."""
    if (model.n, model.joint_types) != (robot.n, robot.joint_types):
        raise ValueError(
            f"model: {model.n} joints {model.joint_types!r}, the robot has "
            f"{robot.n} joints {robot.joint_types!r}"
        )
    if not np.allclose(model.gravity_vector, robot.gravity_vector, rtol=0, atol=1e-12):
        raise ValueError("model: its gravity differs from the robot's")
    q = robot.random_configurations(SAMPLES, seed=0)
    mine, theirs = link_frames(robot, q), link_frames(model, q)
    size = max(1.0, float(np.abs(mine[..., :3, 3]).max()))
    # Rotations: R_X,i = R'_i(q)^T R_i(q) constant.
    rotation = np.einsum("tnji,tnjk->tnik", theirs[..., :3, :3], mine[..., :3, :3])
    if np.abs(rotation - rotation[:1]).max() > TOLERANCE:
        raise ValueError(
            "model: its link frames are not fixed to the robot's links (the "
            "rotation between them changes with q): not the same arm or joint "
            "convention"
        )
    # Translations: p_i - p'_i = t + R'_i x_i, linear least squares in (t, x_1..x_n).
    n, T = robot.n, q.shape[0]
    A: NDArray[np.float64] = np.zeros((T, n, 3, 3 + 3 * n))
    A[..., :3] = np.eye(3)
    for i in range(n):
        A[:, i, :, 3 + 3 * i : 6 + 3 * i] = theirs[:, i, :3, :3]
    b = (mine[..., :3, 3] - theirs[..., :3, 3]).reshape(-1)
    A = A.reshape(-1, 3 + 3 * n)
    solution = np.linalg.lstsq(A, b, rcond=None)[0]
    if np.abs(A @ solution - b).max() > TOLERANCE * size:
        raise ValueError(
            "model: its link frames are not fixed to the robot's links, or its "
            "world frame is rotated against the robot's: not the same arm"
        )
    out = robot.copy()
    params = np.empty((n, 10))
    for i in range(n):
        transform = np.eye(4)
        transform[:3, :3] = rotation[0, i]
        transform[:3, 3] = solution[3 + 3 * i : 6 + 3 * i]
        inverse = np.linalg.inv(transform)
        params[i] = standard_from_pseudo_inertia(
            inverse @ pseudo_inertia(model.params[i]) @ inverse.T
        )
    out.params = params
    robot_fields.copy_group(model, out, "drive")
    return out
