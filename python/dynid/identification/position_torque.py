"""Joint-side torque that depends on the joint's own position: one harmonic per joint turn.

    tau_pos,j(q_j) = ks_j sin q_j + kc_j cos q_j          (row j only; coefficients unconstrained)

It models what a rigid body with motor inertia and friction cannot: a torque measured at joint j
that is a function of q_j alone, periodic in one turn of the joint. Such a torque comes from the
joint itself, not from the links: a torque sensor or strain-wave gear whose reading or transmitted
torque varies once per output revolution (eccentricity, misalignment: the harmonic drive's
"kinematic error" and torque ripple at the output frequency), or a cable loom / hose / spring
crossing the joint, whose restoring torque -k (q_j - q_0) is ks_j sin q_j + kc_j cos q_j + const
to within k (q - sin q) over the joint's range (sin is the periodic form of the spring; with the
torque offset, the spring's rest position goes into the constant). A general once-per-turn
function is ``offset + ks sin q + kc cos q``, hence the two columns here and the ``offset`` option
for the constant.

Identifiability. For some joints these two columns are combinations of the rigid-body columns
for every motion, so a position torque there cannot be told apart from gravity: a pendulum
across gravity (its torque holds g (c1 cos q + c2 sin q), c its first moments); joint 2 of
``models.kuka_lwr4()`` and of most arms, whose frame-2 origin is fixed (on the vertical axis 1):
link 2's first moments then enter the dynamics only through gravity, which is a sin q2 + b cos q2
in row 2 alone. Adding the columns there would make the fit rank deficient and, in
``physical_least_squares``, let unconstrained columns carry gravity past the mass constraints.
:func:`position_torque_joints` keeps only the joints whose two columns raise the rank of the
model's base regressor (with the drive terms and offsets asked for) by two at random states;
the others are left out and said so.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..model.base_parameters import base_parameters
from ..model.robot import Robot

#: Name prefixes of the coefficients of sin q_j and cos q_j (1-based joint): "ks1", "kc1", ...
SIN_NAME, COS_NAME = "ks", "kc"

#: Random states of the structural identifiability test, and the singular-value ratio below which
#: a direction counts as dependent (structural dependencies leave ~1e-15, independent columns of
#: the 7-joint arms here ~0.1 with the columns scaled to unit norm).
STATES, RANK_TOLERANCE = 60, 1e-8


def position_columns(q: NDArray[np.float64], joints: tuple[int, ...]) -> NDArray[np.float64]:
    """(T, n, 2 len(joints)) columns: for each joint j of ``joints`` (0-based) sin q_j then
    cos q_j in row j, zero elsewhere."""
    q = np.asarray(q, dtype=float)
    if q.ndim == 1:
        q = q[None]
    T, n = q.shape
    columns = np.zeros((T, n, 2 * len(joints)))
    for k, j in enumerate(joints):
        columns[:, j, 2 * k] = np.sin(q[:, j])
        columns[:, j, 2 * k + 1] = np.cos(q[:, j])
    return columns


def position_names(joints: tuple[int, ...]) -> tuple[list[str], list[str]]:
    """Names and expressions of the coefficients of :func:`position_columns`."""
    names, expressions = [], []
    for j in joints:
        names += [f"{SIN_NAME}{j + 1}", f"{COS_NAME}{j + 1}"]
        expressions += [
            f"position torque of joint {j + 1}: coefficient of sin q{j + 1}",
            f"position torque of joint {j + 1}: coefficient of cos q{j + 1}",
        ]
    return names, expressions


def position_torque_joints(
    robot: Robot, rotor: bool, friction: bool, offset: bool
) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """(kept, left out): the joints (0-based) whose sin q_j, cos q_j columns are structurally
    identifiable next to the base columns of ``robot``'s regressor (with the rotor, friction and
    offset columns asked for), and those that are not (module docstring).

    The test: at ``STATES`` random states (q uniform within the limits, qd, qdd uniform in
    [-1, 1] from independent generators), the column-scaled stacked matrix [Y_base | offsets] is
    extended by each joint's two columns in turn; the joint is kept when the numerical rank rises
    by two. Joint by joint, as each joint's columns live in its own row only.
    """
    n = robot.n
    base = base_parameters(robot, "torque", rotor=rotor, friction=friction)
    q = robot.random_configurations(STATES, seed=11)
    rng = np.random.default_rng(12)  # not the generator of q: independent qd, qdd
    qd, qdd = rng.uniform(-1.0, 1.0, (2, STATES, n))
    Y = robot.regressor(q, qd, qdd, rotor=rotor, friction=friction)[..., base.independent]
    if offset:
        Y = np.concatenate([Y, np.broadcast_to(np.eye(n), (STATES, n, n))], axis=2)
    reference = _rank(Y.reshape(-1, Y.shape[2]))
    kept, left_out = [], []
    for j in range(n):
        extended = np.concatenate([Y, position_columns(q, (j,))], axis=2)
        if _rank(extended.reshape(-1, extended.shape[2])) == reference + 2:
            kept.append(j)
        else:
            left_out.append(j)
    return tuple(kept), tuple(left_out)


def _rank(A: NDArray[np.float64]) -> int:
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    s = np.linalg.svd(A / norms, compute_uv=False)
    return int(np.sum(s > RANK_TOLERANCE * s[0]))
