"""Uniform time scaling of a trajectory: its torques from the stored ones, no dynamics recomputed.

Notes ("Dynamic scaling of trajectories", pp. 37-40). A trajectory q_d(t), t in [0, T], is executed
k times slower (k > 1) or faster (k < 1) as q_s(r) with r = k t in [0, kT], so that
q_d(t) = q_s(kt): the same path, the same positions at the mapped instants, with
q_s' = qd_d / k and q_s'' = qdd_d / k^2 (p. 37). The model is linear in the acceleration and
quadratic in the velocity, so the inertial and Coriolis/centrifugal torque scales as 1/k^2 while
gravity, depending on the position only, does not scale (p. 38):

    tau_s(kt) = (tau_d(t) - g(q_d(t))) / k^2 + g(q_d(t)).

The notes neglect dissipative terms there. With the drive terms of docs/conventions.md,
"Drive terms and the torque model" (tau = (B + diag(Ia)) qdd + c + g + Fv qd + Fs sign(qd)) the
rotor inertia is inertial and scales with the rest of the 1/k^2 part, viscous friction scales as 1/k
and Coulomb friction, sign(qd / k) = sign(qd), not at all:

    tau_s(kt) = (tau_d - g - Fv qd_d - Fs sign(qd_d)) / k^2 + g + Fv qd_d / k + Fs sign(qd_d),

exact for every sample: only the stored total torque tau_d and gravity torque g are needed, plus
the original velocity and the friction coefficients when the model has friction.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .. import _core
from .._checks import real_array
from ..model.robot import Robot


def check_scale(k: Any) -> float:
    """The time-scaling factor k > 0 and finite, as a float (``ValueError`` naming ``k``)."""
    real = isinstance(k, (int, float, np.integer, np.floating)) and not isinstance(
        k, (bool, np.bool_)
    )
    try:
        value = float(k) if real else np.nan
    except OverflowError:  # a Python int beyond float range
        value = np.inf
    if not np.isfinite(value) or value <= 0:
        raise ValueError(
            f"k: expected a finite time-scaling factor k > 0 (t' = k t: k > 1 slows down, "
            f"k < 1 speeds up), got {k!r}"
        )
    return value


def scale_time(t: ArrayLike, k: float) -> NDArray[np.float64]:
    """The scaled trajectory's time grid, t' = k t (notes p. 37, r(t) = k t).

    Sample i of the original trajectory at t_i and sample i of the scaled one at k t_i share the
    same position; a duration T becomes k T (notes p. 40: T = 0.5 s, k = 2 -> T' = 1 s).
    """
    k = check_scale(k)
    times = real_array(t, "t")
    with np.errstate(over="ignore"):
        scaled = k * times
    if not np.all(np.isfinite(scaled)):
        raise ValueError(f"k: k t overflows float64 (k = {k!r}, max |t| = {np.abs(times).max():g})")
    return scaled


def scale_motion(
    qd: ArrayLike, qdd: ArrayLike, k: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Velocities and accelerations of the scaled trajectory at t' = k t: (qd / k, qdd / k^2).

    The positions are the original ones (q_s(kt) = q_d(t)); notes p. 37.
    """
    k = check_scale(k)
    qd = real_array(qd, "qd")
    qdd = real_array(qdd, "qdd")
    if qd.shape != qdd.shape:
        raise ValueError(f"qdd: expected the shape of qd {qd.shape}, got {qdd.shape}")
    with np.errstate(over="ignore"):
        return _finite(qd / k, k), _finite(qdd / k / k, k)


def _finite(scaled: NDArray[np.float64], k: float) -> NDArray[np.float64]:
    if not np.all(np.isfinite(scaled)):
        raise ValueError(f"k: the scaled values overflow float64 (k = {k!r} is too small)")
    return scaled


def scale_torques(
    tau: ArrayLike,
    tau_gravity: ArrayLike,
    k: float,
    *,
    qd: ArrayLike | None = None,
    robot: Robot | None = None,
) -> NDArray[np.float64]:
    """Torques of the trajectory executed with time scaled by k (t' = k t), from the stored ones.

    Parameters
    ----------
    tau
        (T, n) or (n,): the total torques stored along the original trajectory (inverse dynamics
        or measured), including drive terms if the model has them.
    tau_gravity
        Same shape: the gravity torques g(q) at the same samples.
    k
        Scaling factor, finite and > 0: k > 1 slows down (the torque above gravity shrinks by
        1/k^2), k < 1 speeds up. Sample i of the result belongs to time k t_i
        (:func:`scale_time`).
    qd, robot
        Needed only when the torques contain friction: the original velocities (same shape as
        ``tau``) and the robot whose ``Fv`` and ``Fs`` produced them. The rotor inertias ``Ia``
        need nothing: being inertial, they scale with the 1/k^2 part. Without ``robot`` the
        torques are taken as frictionless (notes p. 38, "dissipative terms neglected").

    Returns
    -------
    The scaled torques, shape of ``tau``: (tau - g - f) / k^2 + g + Fv qd / k + Fs sign(qd)
    with f = Fv qd + Fs sign(qd) (see the module docstring; notes p. 38).
    """
    k = check_scale(k)
    constant, viscous, inertial = _parts(tau, tau_gravity, qd, robot)
    with np.errstate(over="ignore"):
        scaled = inertial / k / k + viscous / k + constant  # k * k could overflow for huge k
    return _finite(scaled, k)


def _parts(
    tau: ArrayLike, tau_gravity: ArrayLike, qd: ArrayLike | None, robot: Robot | None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The stored torque split by how it scales: (g + Fs sign(qd), Fv qd, the inertial rest)."""
    tau = real_array(tau, "tau")
    gravity = real_array(tau_gravity, "tau_gravity")
    if tau.ndim not in (1, 2) or tau.size == 0:
        raise ValueError(f"tau: expected shape (T, n) or (n,), got {tau.shape}")
    if gravity.shape != tau.shape:
        raise ValueError(f"tau_gravity: expected the shape of tau {tau.shape}, got {gravity.shape}")
    if robot is None:
        if qd is not None:
            raise ValueError(
                "robot: qd was given without the robot whose Fv, Fs produced the friction torques"
            )
        return gravity, np.zeros_like(tau), tau - gravity
    checks.robot(robot)
    if tau.shape[-1] != robot.n:
        raise ValueError(f"tau: expected {robot.n} joints (robot.n) per sample, got {tau.shape}")
    if qd is None:
        raise ValueError("qd: the original velocities are needed to scale the friction torques")
    qd = real_array(qd, "qd")
    if qd.shape != tau.shape:
        raise ValueError(f"qd: expected the shape of tau {tau.shape}, got {qd.shape}")
    # The friction law's two terms from the C++ core (dynid::friction_terms, exact sign: band 0):
    # T^T (Fv . T qd) and T^T (Fs . sign(T qd)) with coupled drives (docs/transmission.md); they
    # scale the same way. sign(w / k) = sign(w) for k > 0, sign(0) = 0.
    terms = _core._friction_terms(robot, qd, 0.0)
    viscous, coulomb = terms[..., 0, :], terms[..., 1, :]
    inertial = tau - gravity - viscous - coulomb  # (B + diag(Ia)) qdd + c: scales as 1/k^2
    return gravity + coulomb, viscous, inertial


def scaling_for_torque_limits(
    tau: ArrayLike,
    tau_gravity: ArrayLike,
    tau_max: ArrayLike,
    *,
    qd: ArrayLike | None = None,
    robot: Robot | None = None,
) -> float:
    """The smallest k such that the trajectory scaled by any k' >= k respects |tau| <= tau_max.

    Notes p. 39: the original motion (T = 0.5 s) "maybe violates the torque limit at joint 1";
    slowing it down by k shrinks the torque above gravity. With s = 1/k the scaled torque of each
    sample and joint is h(s) = a + b s + d s^2 (:func:`scale_torques`: a = g + Fs sign(qd),
    b = Fv qd, d = the inertial part), so k = 1 / s* with s* the first s > 0 at which some
    |h(s)| reaches tau_max (a root of a quadratic per sample and joint); every slower scaling
    (s < s*) stays within the limits. The result may be below 1: the motion can then be sped up.

    Parameters are those of :func:`scale_torques`, plus ``tau_max``: (n,) positive torque limits
    (or a scalar for all joints). Raises ValueError naming ``tau_max`` when even an infinitely
    slow motion violates them (|g + Fs sign(qd)| > tau_max at some sample). Returns 0.0 when no
    speed reaches the limits (the torques do not grow with the speed).
    """
    a, b, d = _parts(tau, tau_gravity, qd, robot)  # h(s) = a + b s + d s^2, s = 1/k
    n = a.shape[-1]
    limits = real_array(tau_max, "tau_max")
    if limits.ndim > 1 or (limits.ndim == 1 and limits.shape != (n,)) or np.any(limits <= 0):
        raise ValueError(
            f"tau_max: expected a positive limit per joint, shape ({n},) or a scalar, got "
            f"{limits!r}"
        )
    if np.any(np.abs(a) > limits):
        index = tuple(int(i[0]) for i in np.nonzero(np.abs(a) > limits))
        raise ValueError(
            f"tau_max: the gravity (and Coulomb friction) torque alone exceeds the limit at "
            f"sample/joint {index}: no time scaling can respect it"
        )
    first = np.full(a.shape, np.inf)
    for bound in (limits, -limits):  # first positive root of d s^2 + b s + (a - bound) = 0
        first = np.minimum(first, _first_positive_root(d, b, a - bound))
    s_star = float(first.min())
    return 0.0 if s_star == np.inf else 1.0 / s_star


def _first_positive_root(
    d: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Elementwise smallest root s > 0 of d s^2 + b s + c = 0 (inf where there is none)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        disc = b * b - 4.0 * d * c
        root = np.sqrt(np.where(disc >= 0, disc, np.nan))
        # Numerically stable pair: q = -(b + sign(b) sqrt(disc)) / 2, roots q / d and c / q.
        qv = -0.5 * (b + np.where(b >= 0, 1.0, -1.0) * root)
        candidates = np.stack([qv / d, c / qv, np.where(d == 0, -c / b, np.nan)])
    candidates = np.where(np.isfinite(candidates) & (candidates > 0), candidates, np.inf)
    return candidates.min(axis=0)
