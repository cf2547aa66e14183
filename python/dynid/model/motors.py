"""The motors on the chain (notes, "Placement of motors along the chain" and "Resulting dynamic
model", pp. 12-13): the model seen from the motor side, and the gyroscopic coupling the notes'
simplifying assumption leaves out.

Motor i sits on link i - 1 and turns its joint through a gear of ratio n_i: theta_m,i = n_i q_i,
tau_i = n_i tau_m,i. Its rotor's kinetic energy with "only the spinning rotor velocity" counted
(p. 13) is 1/2 I_m,i n_i^2 qd_i^2: the model's reflected rotor inertia Ia_i = I_m,i n_i^2
(docs/conventions.md, "Drive terms"), so that B(q) + B_m with B_m = diag(Ia). Seen from the motor
side, row i divided by n_i (p. 13):

    (I_m,i + b_ii(q) / n_i^2) thetadd_m,i + (1/n_i) (sum_{j != i} b_ij(q) qdd_j + f_i(q, qd))
        = tau_m,i,

so with large gear ratios each motor sees its own rotor inertia I_m,i plus the link inertia
divided by n_i^2, and the couplings divided by n_i: :func:`motor_side`.

**The gyroscopic terms.** The rotor spins about its axis z_i (joint i's axis: the motor is
coaxial with its joint) with angular velocity omega_{i-1} + n_i qd_i z_i, omega_{i-1} that of the
link carrying it. Its axial kinetic energy 1/2 I_m,i (z_i . omega_{i-1} + n_i qd_i)^2 holds,
besides the spinning term and the rotor's part of link i - 1's own inertia, the cross term
n_i I_m,i qd_i (z_i . omega_{i-1}) = n_i I_m,i qd_i sum_{k<i} (z_i . z_k) qd_k (revolute
joints k), i.e. an inertia matrix term

    B_g,ik = B_g,ki = n_i I_m,i (z_i . z_k)(q)   (k < i, joint k revolute),

position-dependent, hence with Coriolis/centrifugal terms of its own (Christoffel symbols of
B_g; d(z_i . z_k)/dq_j = (z_j x z_i) . z_k for k <= j < i, zero otherwise: the terms for j < k
cancel). :func:`gyroscopic_inertia` and :func:`gyroscopic_torque` compute them; they grow with
n_i I_m,i while the spinning term grows with n_i^2 I_m,i, which is why the notes' model, for high
gear ratios, keeps the latter only.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from .robot import Robot


def motor_side(
    robot: Robot, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, gear_ratios: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(tau_m, I_eff) for T samples (T, n): the motor torques before the gears,
    tau_m,i = tau_i / n_i (``robot.rnea``: links, Ia, friction), and each motor's effective
    inertia I_m,i + b_ii(q) / n_i^2 (notes p. 13), with I_m,i = Ia_i / n_i^2 (module
    docstring). ValueError naming a bad argument."""
    checks.robot(robot)
    n = _ratios(gear_ratios, robot.n)
    tau = robot.rnea(q, qd, qdd)
    M = robot.mass_matrix(q)  # B(q) + diag(Ia)
    diagonal = np.diagonal(M, axis1=-2, axis2=-1)  # b_ii + Ia_i
    return tau / n, diagonal / n**2


def gyroscopic_inertia(
    robot: Robot, q: ArrayLike, motor_inertias: ArrayLike, gear_ratios: ArrayLike
) -> NDArray[np.float64]:
    """B_g(q), (n, n) or (T, n, n): the rotors' gyroscopic coupling (module docstring) for the
    rotors' axial inertias I_m (n,) [kg m^2] and gear ratios n (n,)."""
    checks.robot(robot)
    I_m, n = _inertias(motor_inertias, robot.n), _ratios(gear_ratios, robot.n)
    z, revolute = _axes(robot, q)
    dots = np.einsum("...ia,...ka->...ik", z, z)  # z_i . z_k
    lower = np.tril(np.ones((robot.n, robot.n)), -1) * revolute[None, :]  # k < i, k revolute
    # rotor i spins about joint i's axis only when joint i is revolute
    coupling = (n * I_m * revolute)[:, None] * lower * dots
    return coupling + np.swapaxes(coupling, -1, -2)


def gyroscopic_torque(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    motor_inertias: ArrayLike,
    gear_ratios: ArrayLike,
) -> NDArray[np.float64]:
    """The torque (T, n) the gyroscopic coupling adds to ``robot.rnea``: B_g(q) qdd + c_g(q, qd),
    c_g from the Christoffel symbols of B_g (module docstring)."""
    checks.robot(robot)
    q2, qd2, qdd2 = (
        np.atleast_2d(real_array(v, k)) for v, k in ((q, "q"), (qd, "qd"), (qdd, "qdd"))
    )
    if not (q2.shape == qd2.shape == qdd2.shape) or q2.shape[-1] != robot.n:
        raise ValueError(f"q, qd, qdd: expected shape (T, {robot.n}) each")
    I_m, n = _inertias(motor_inertias, robot.n), _ratios(gear_ratios, robot.n)
    z, revolute = _axes(robot, q2)
    B = gyroscopic_inertia(robot, q2, I_m, n)
    # dB_ik/dq_j for k < i: n_i I_m,i (z_j x z_i) . z_k when k <= j < i and joint j revolute
    cross = np.cross(z[:, :, None, :], z[:, None, :, :])  # [t, j, i] = z_j x z_i
    triple = np.einsum("tjia,tka->tijk", cross, z)  # [t, i, j, k] = (z_j x z_i) . z_k
    a = np.arange(robot.n)
    i, k, j = np.meshgrid(a, a, a, indexing="ij")  # indexed [i, k, j], as dB_lower below
    where = (k <= j) & (j < i) & (revolute[k] > 0) & (revolute[j] > 0)
    scale = (n * I_m * revolute)[:, None, None]
    dB_lower = np.where(where, scale * triple.transpose(0, 1, 3, 2), 0.0)  # [t, i, k, j]
    dB = dB_lower + np.swapaxes(dB_lower, 1, 2)  # dB[t, a, b, j] = d B_ab / d q_j
    # c_a = sum_bc Gamma_abc qd_b qd_c, Gamma_abc = 1/2 (dB_ab/dq_c + dB_ac/dq_b - dB_bc/dq_a)
    first = np.einsum("tabc,tb,tc->ta", dB, qd2, qd2)
    last = np.einsum("tbca,tb,tc->ta", dB, qd2, qd2)
    c = first - 0.5 * last
    tau: NDArray[np.float64] = np.einsum("tab,tb->ta", B, qdd2) + c
    return tau


def _axes(robot: Robot, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The joint axes z_i in world coordinates, (..., n, 3) (the angular rows of the geometric
    Jacobian of a revolute joint), and 1 for a revolute joint, 0 for a prismatic one."""
    J = robot.jacobian(q)
    revolute = np.array([1.0 if t == "R" else 0.0 for t in robot.joint_types])
    # a prismatic joint's angular column is zero: its axis from the linear rows instead
    axes = np.where(revolute[:, None] > 0, np.swapaxes(J[..., 3:, :], -1, -2), 0.0)
    return axes, revolute


def _ratios(value: ArrayLike, n: int) -> NDArray[np.float64]:
    ratios = np.broadcast_to(real_array(value, "gear_ratios"), (n,)).astype(float)
    if np.any(ratios == 0):
        raise ValueError(f"gear_ratios: expected non-zero values, got {ratios}")
    return ratios


def _inertias(value: ArrayLike, n: int) -> NDArray[np.float64]:
    inertias = np.broadcast_to(real_array(value, "motor_inertias"), (n,)).astype(float)
    if np.any(inertias < 0):
        raise ValueError(f"motor_inertias: expected values >= 0, got {inertias}")
    return inertias
