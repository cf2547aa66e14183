"""Identification of the drive side of a robot with elastic joints from logs holding the link
positions q, the motor positions theta, the motor torque tau and the elastic (joint) torque tau_J
(paper eqs. (1)-(3) and Sect. III; notes p. 16). Each joint separately, by linear least squares:

- stiffness: tau_J = K (theta - q) [+ an optional sensor offset], paper eq. (3);
- motor side: tau - tau_J = B thetadd + Fv_m thetad + Fs_m sign(thetad), the motor equation
  (paper eq. (2)) with tau_F = Fv_m thetad + Fs_m sign(thetad);
- link side: as for a rigid robot with tau_J in place of tau (paper eq. (7)): ``identify_log`` on
  a :class:`dynid.Log` whose ``tau`` is tau_J and without ``rotor``/``friction`` columns (the motor
  inertia and friction do not act on q). See docs/elastic.md.

Standard deviations are those of ordinary least squares, sigma^2 (A^T A)^-1 with sigma^2 the
residual variance (RSS / (T - p)): valid for white measurement noise on the torques.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .. import _core
from ..model.elastic import ElasticRobot
from ..model.robot import Robot

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]


@dataclass(frozen=True)
class DriveIdentification:
    """Per-joint drive parameters of an elastic-joint robot with their standard deviations
    (all (n,)): see :func:`identify_drives`."""

    stiffness: Array  #: K (N m/rad)
    stiffness_std: Array
    torque_offset: Array  #: constant offset of the tau_J sensor (zeros unless ``offset``)
    torque_offset_std: Array
    motor_inertia: Array  #: B, reflected through the gears (kg m^2)
    motor_inertia_std: Array
    motor_viscous: Array  #: Fv_m (N m s/rad)
    motor_viscous_std: Array
    motor_coulomb: Array  #: Fs_m (N m)
    motor_coulomb_std: Array
    stiffness_rms: Array  #: RMS residual of tau_J = K (theta - q) [+ offset] (N m)
    motor_rms: Array  #: RMS residual of the motor equation (N m)
    samples: int

    def elastic_robot(self, robot: Robot) -> ElasticRobot:
        """The identified drives on ``robot``'s links (e.g. the link model identified from
        tau_J); the motor friction estimates are clipped at zero."""
        return ElasticRobot(
            robot,
            self.stiffness,
            self.motor_inertia,
            np.maximum(self.motor_viscous, 0.0),
            np.maximum(self.motor_coulomb, 0.0),
        )


def identify_stiffness(
    q: ArrayLike, theta: ArrayLike, tau_J: ArrayLike, *, offset: bool = False
) -> tuple[Array, Array, Array, Array, Array]:
    """Joint stiffness per joint from tau_J = K (theta - q) (+ o with ``offset``), paper eq. (3).

    Returns (K, K_std, offset, offset_std, rms), each (n,). ValueError naming the argument for
    bad shapes, naming ``theta`` when a joint's deflection theta - q is identically zero."""
    checks.flag(offset, "offset")
    q_, theta_, tau_J_ = _logs(q=q, theta=theta, tau_J=tau_J)
    deflection = theta_ - q_
    n = q_.shape[1]
    K, K_std, o, o_std, rms = (np.zeros(n) for _ in range(5))
    for j in range(n):
        columns = [deflection[:, j]] + ([np.ones(len(q_))] if offset else [])
        x, std, rms[j] = _fit(
            np.column_stack(columns), tau_J_[:, j], j, "theta", "the deflection theta - q"
        )
        K[j], K_std[j] = x[0], std[0]
        if offset:
            o[j], o_std[j] = x[1], std[1]
    return K, K_std, o, o_std, rms


def identify_motor_side(
    thetad: ArrayLike, thetadd: ArrayLike, tau: ArrayLike, tau_J: ArrayLike
) -> tuple[Array, Array, Array, Array, Array, Array, Array]:
    """Motor inertia and friction per joint from the motor equation (paper eq. (2))
    tau - tau_J = B thetadd + Fv_m thetad + Fs_m sign(thetad).

    Returns (B, B_std, Fv_m, Fv_m_std, Fs_m, Fs_m_std, rms), each (n,). ValueError naming
    ``thetad`` when a joint's motor does not move enough to separate the three terms."""
    thetad_, thetadd_, tau_, tau_J_ = _logs(thetad=thetad, thetadd=thetadd, tau=tau, tau_J=tau_J)
    n = thetad_.shape[1]
    out = np.zeros((7, n))
    # The friction columns from the core's motor friction law (one home: the simulator's and
    # ElasticRobot's), evaluated with unit coefficients: Fv_m's column thetad, Fs_m's sign(thetad).
    ones, zeros = np.ones(n), np.zeros(n)
    viscous = _core._motor_friction(ones, ones, ones, zeros, thetad_, 0.0)
    coulomb = _core._motor_friction(ones, ones, zeros, ones, thetad_, 0.0)
    for j in range(n):
        A = np.column_stack([thetadd_[:, j], viscous[:, j], coulomb[:, j]])
        x, std, out[6, j] = _fit(
            A, tau_[:, j] - tau_J_[:, j], j, "thetad", "motor acceleration, velocity and its sign"
        )
        out[0:6:2, j], out[1:6:2, j] = x, std
    return out[0], out[1], out[2], out[3], out[4], out[5], out[6]


def identify_drives(
    q: ArrayLike,
    theta: ArrayLike,
    thetad: ArrayLike,
    thetadd: ArrayLike,
    tau: ArrayLike,
    tau_J: ArrayLike,
    *,
    offset: bool = False,
) -> DriveIdentification:
    """Stiffness, motor inertia and motor friction of every joint from a log (T, n) each: link
    positions q, motor positions theta with their derivatives thetad and thetadd (differentiate
    and low-pass theta as for q: :mod:`dynid.logs.signal`), motor torque tau and elastic torque
    tau_J.
    ``offset`` fits a constant offset of the tau_J sensor alongside K (the offset is NOT removed
    from tau_J in the motor equation: a bias on tau_J there is absorbed by nothing, so calibrate
    it out first if it is large). See :func:`identify_stiffness`, :func:`identify_motor_side`."""
    K, K_std, o, o_std, k_rms = identify_stiffness(q, theta, tau_J, offset=offset)
    B, B_std, Fv, Fv_std, Fs, Fs_std, m_rms = identify_motor_side(thetad, thetadd, tau, tau_J)
    for value in (K, K_std, o, o_std, k_rms, B, B_std, Fv, Fv_std, Fs, Fs_std, m_rms):
        value.setflags(write=False)
    return DriveIdentification(
        K,
        K_std,
        o,
        o_std,
        B,
        B_std,
        Fv,
        Fv_std,
        Fs,
        Fs_std,
        k_rms,
        m_rms,
        samples=int(np.shape(q)[0]),
    )


# ---- helpers ------------------------------------------------------------------------------------


def _logs(**arrays: ArrayLike) -> list[Array]:
    """(T, n) float arrays of one shape, T >= 2; ValueError naming the argument otherwise."""
    out: list[Array] = []
    for name, value in arrays.items():
        a = checks.real_array(value, name, ndim=2)
        if out and a.shape != out[0].shape:
            first = next(iter(arrays))
            raise ValueError(f"{name}: expected shape {out[0].shape} like {first}, got {a.shape}")
        if a.shape[0] < 2 or a.shape[1] < 1:
            raise ValueError(f"{name}: expected (T, n) with T >= 2 samples, got {a.shape}")
        out.append(a)
    return out


def _fit(A: Array, y: Array, joint: int, name: str, what: str) -> tuple[Array, Array, float]:
    """Least squares y ~ A x with OLS standard deviations and the RMS residual; ValueError naming
    ``name`` and the joint when A's columns are not independent (relative tolerance 1e-10)."""
    T, p = A.shape
    scale = np.linalg.norm(A, axis=0)
    singular = np.linalg.svd(A / np.where(scale > 0, scale, 1.0), compute_uv=False)
    if p >= T or np.any(scale == 0) or singular[-1] < 1e-10 * singular[0]:
        raise ValueError(
            f"{name}: joint {joint} ({joint + 1} in the notes' numbering): the log "
            f"does not separate the columns ({what}); it needs motion on that joint"
        )
    x, *_ = np.linalg.lstsq(A, y, rcond=None)
    residual = y - A @ x
    sigma2 = residual @ residual / (T - p)
    std = np.sqrt(sigma2 * np.diag(np.linalg.inv(A.T @ A)))
    return (
        np.asarray(x, dtype=np.float64),
        np.asarray(std, dtype=np.float64),
        float(np.sqrt(np.mean(residual**2))),
    )
