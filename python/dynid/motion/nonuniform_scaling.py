"""Non-uniform time scaling: a path q_s(r) executed with any timing r(t), its torques from the
ones stored along the path once (notes, "Dynamic scaling of trajectories", p. 37).

With q(t) = q_s(r(t)), r strictly increasing (r' > 0), the chain rule gives (p. 37)

    qd(t)  = q_s'(r) rd,        qdd(t) = q_s''(r) rd^2 + q_s'(r) rdd,

and since the model is linear in the acceleration and quadratic in the velocity
(c(q, a v) = a^2 c(q, v)), the torque splits into parts that each scale with one power of the
timing:

    tau(t) = rd^2 [B(q_s) q_s'' + c(q_s, q_s')] + rdd B(q_s) q_s' + g(q_s)
             + rd Fv q_s' + Fs sign(q_s'),

B including the rotor inertias (docs/conventions.md, "Drive terms and the torque model"; the
notes neglect the dissipative terms: viscous friction scales with rd, Coulomb friction, sign(q_s'
rd) = sign(q_s') for rd > 0, not at all). The bracket, the "path momentum" B(q_s) q_s', gravity
and the two friction terms depend on the path only: :func:`path_torques` computes them once (three
inverse-dynamics calls per sample), :func:`retimed_torques` any timing's torque from them with no
dynamics. Uniform scaling r = t / k (dynid.motion.time_scaling, p. 38) is the case rdd = 0,
rd = 1/k.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from ..model.robot import Robot
from .time_scaling import _parts


@dataclass(frozen=True)
class PathTorques:
    """The torques of a path q_s(r), each (T, n) at its samples r_i, split by how they scale
    with the timing (module docstring)."""

    inertial: NDArray[np.float64]  #: B(q_s) q_s'' + c(q_s, q_s'): times rd^2
    momentum: NDArray[np.float64]  #: B(q_s) q_s' (rotor inertias included): times rdd
    gravity: NDArray[np.float64]  #: g(q_s): unscaled
    viscous: NDArray[np.float64]  #: Fv q_s' (through the transmission): times rd
    coulomb: NDArray[np.float64]  #: Fs sign(q_s'): unscaled (rd > 0)


def path_torques(
    robot: Robot, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike, *, friction: bool = True
) -> PathTorques:
    """The parts of the torque along the path q_s(r) sampled as ``q``, ``dq`` = dq_s/dr and
    ``ddq`` = d^2q_s/dr^2, (T, n) each; ``friction=False`` leaves out the robot's friction
    (the notes' "dissipative terms neglected"). ValueError naming a bad argument."""
    checks.robot(robot)
    q, dq, ddq = (real_array(v, name) for v, name in ((q, "q"), (dq, "dq"), (ddq, "ddq")))
    if q.ndim != 2 or q.shape[1] != robot.n:
        raise ValueError(f"q: expected shape (T, {robot.n}), got {q.shape}")
    for value, name in ((dq, "dq"), (ddq, "ddq")):
        if value.shape != q.shape:
            raise ValueError(f"{name}: expected the shape of q {q.shape}, got {value.shape}")
    gravity = robot.gravity(q)
    # rnea with zero velocity: B q_s' + g (sign(0) = 0: no Coulomb term, no viscous term).
    momentum = robot.rnea(q, np.zeros_like(q), dq) - gravity
    # The torque split by how it scales, as uniform time scaling splits it (time_scaling._parts:
    # g + Coulomb, viscous, the inertial rest).
    constant, viscous, inertial = _parts(robot.rnea(q, dq, ddq), gravity, dq, robot)
    coulomb = constant - gravity
    if not friction:
        viscous, coulomb = np.zeros_like(q), np.zeros_like(q)
    return PathTorques(inertial, momentum, gravity, viscous, coulomb)


def retimed_torques(path: PathTorques, rd: ArrayLike, rdd: ArrayLike) -> NDArray[np.float64]:
    """The torque (T, n) of the path executed with the timing r(t): ``rd`` = dr/dt > 0 and
    ``rdd`` = d^2r/dt^2 at the instants where r(t) equals the path's samples, (T,) each
    (module docstring)."""
    rd, rdd = real_array(rd, "rd"), real_array(rdd, "rdd")
    rows = path.gravity.shape[0]
    for value, name in ((rd, "rd"), (rdd, "rdd")):
        if value.shape != (rows,):
            raise ValueError(
                f"{name}: expected shape ({rows},), one per path sample, got {value.shape}"
            )
    if np.any(rd <= 0):
        raise ValueError("rd: the timing r(t) must be strictly increasing (dr/dt > 0)")
    a, b = rd[:, None], rdd[:, None]
    with np.errstate(over="ignore", invalid="ignore"):
        tau = a * a * path.inertial + b * path.momentum + path.gravity + a * path.viscous
        tau = tau + path.coulomb
    if not np.all(np.isfinite(tau)):
        raise ValueError("rd, rdd: the re-timed torque overflows float64")
    return tau
