"""Robots with elastic joints: Spong's reduced model (paper eqs. (1)-(3); notes p. 14-16).

With q the link positions and theta the motor positions reflected through the gears (both (n,)),

    M(q) qdd + c(q, qd) + g(q) = K (theta - q)             link equation, paper eq. (1)
    B thetadd + K (theta - q) + tau_F(thetad) = tau          motor equation, paper eq. (2)
    tau_J = K (theta - q)                                    elastic (joint) torque, eq. (3)

K (stiffness), B (motor inertia) diagonal > 0; tau_F = Fv_m thetad + Fs_m sign(thetad) the
motor-side friction (the paper neglects friction in the link equation). The link side is the
robot's rigid body only, ``robot.rigid_body()``: its own drive terms Ia, Fv, Fs are not used,
since the motor inertia and friction of an elastic joint act on theta, not on q (in the rigid
limit K -> inf, theta -> q and B plays the role of Ia, Fv_m and Fs_m those of Fv and Fs).

The link trajectory is a flat output: from q(t) and its derivatives up to the fourth,
tau_l = M qdd + c + g and its EXACT time derivatives come from the C++ jerk/snap Newton-Euler
recursion (``Robot.rnea_time_derivatives``), then

    theta = q + K^-1 tau_l,  thetad = qd + K^-1 tau_l',  thetadd = qdd + K^-1 tau_l'',
    tau = B thetadd + tau_l + tau_F(thetad)

(the paper's eq. (4) solved for tau). Every call takes one sample (n,) or T samples (T, n); the
per-sample dynamics run in C++ batch calls, the motor equation and its friction too (its one home,
cpp/include/dynid/elastic_motor.hpp, shared with the elastic simulator); the rest is elementwise
NumPy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .. import _core
from .robot import Robot

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]


class ElasticRobot:
    """A robot with elastic joints (Spong's model; see the module docstring).

    Parameters
    ----------
    robot
        The links: a :class:`dynid.Robot`; only ``robot.rigid_body()`` is used (Ia, Fv, Fs
        ignored, see the module docstring).
    stiffness
        Joint stiffness K > 0 per joint (N m/rad, or N/m for prismatic joints): a number or (n,).
    motor_inertia
        Motor inertia B > 0 reflected through the gears (I_m n_r^2, notes p. 16): a number or (n,).
    motor_viscous, motor_coulomb
        Motor-side friction Fv_m >= 0 and Fs_m >= 0 (a number or (n,)); None: zero.
    """

    def __init__(
        self,
        robot: Robot,
        stiffness: ArrayLike,
        motor_inertia: ArrayLike,
        motor_viscous: ArrayLike | None = None,
        motor_coulomb: ArrayLike | None = None,
    ) -> None:
        checks.robot(robot)
        self.link: Robot = robot.rigid_body()
        n = self.link.n
        self.K = _per_joint(stiffness, "stiffness", n, positive=True)
        self.B = _per_joint(motor_inertia, "motor_inertia", n, positive=True)
        self.Fv_m = _per_joint(0.0 if motor_viscous is None else motor_viscous, "motor_viscous", n)
        self.Fs_m = _per_joint(0.0 if motor_coulomb is None else motor_coulomb, "motor_coulomb", n)

    @property
    def n(self) -> int:
        """Number of joints (the state has 2n positions, q and theta)."""
        return self.link.n

    def __repr__(self) -> str:
        return f"ElasticRobot({self.link!r}, K={self.K}, B={self.B})"

    # ---- the model's terms ---------------------------------------------------------------------
    def elastic_torque(self, q: ArrayLike, theta: ArrayLike) -> Array:
        """tau_J = K (theta - q) (paper eq. (3)), what the LWR's joint torque sensors measure."""
        q_, theta_ = self._samples(q=q, theta=theta)
        return self.K * (theta_ - q_)

    def motor_friction(self, thetad: ArrayLike) -> Array:
        """tau_F = Fv_m thetad + Fs_m sign(thetad), sign(0) = 0 (motor side, paper eq. (2))."""
        (thetad_,) = self._samples(thetad=thetad)
        friction: Array = _core._motor_friction(*self._drives, thetad_, 0.0)
        return friction

    def energy(
        self, q: ArrayLike, qd: ArrayLike, theta: ArrayLike, thetad: ArrayLike
    ) -> Array | float:
        """Total energy (notes p. 16): link kinetic 1/2 qd^T M(q) qd + motor kinetic
        1/2 thetad^T B thetad + gravity potential U_g(q) + spring 1/2 (theta-q)^T K (theta-q).
        Conserved along free motion (tau = 0) without motor friction. A float, or (T,)."""
        q_, qd_, theta_, thetad_ = self._samples(q=q, qd=qd, theta=theta, thetad=thetad)
        deflection = theta_ - q_
        extra = 0.5 * np.sum(self.B * thetad_**2 + self.K * deflection**2, axis=-1)
        total = self.link.kinetic_energy(q_, qd_) + self.link.potential_energy(q_) + extra
        return float(total) if np.ndim(total) == 0 else total

    # ---- dynamics ------------------------------------------------------------------------------
    def forward_dynamics(
        self, q: ArrayLike, qd: ArrayLike, theta: ArrayLike, thetad: ArrayLike, tau: ArrayLike
    ) -> tuple[Array, Array]:
        """(qdd, thetadd) from the state (q, qd, theta, thetad) and the motor torque tau:
        qdd = M(q)^-1 (tau_J - c - g) (the rigid body's forward dynamics driven by tau_J, in C++),
        thetadd = B^-1 (tau - tau_J - tau_F(thetad)). One sample (n,) each or T samples (T, n)."""
        q_, qd_, theta_, thetad_, tau_ = self._samples(
            q=q, qd=qd, theta=theta, thetad=thetad, tau=tau
        )
        tau_J = self.K * (theta_ - q_)
        qdd = self.link.forward_dynamics(q_, qd_, tau_J)
        thetadd: Array = _core._motor_acceleration(*self._drives, thetad_, tau_, tau_J, 0.0)
        return qdd, thetadd

    def motor_motion(
        self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, qddd: ArrayLike, qdddd: ArrayLike
    ) -> tuple[Array, Array, Array]:
        """(theta, thetad, thetadd) that make the links follow q(t) with derivatives qd, qdd,
        qddd, qdddd: theta = q + K^-1 tau_l and its two derivatives, tau_l = M qdd + c + g and its
        derivatives exact (``rnea_time_derivatives`` of the rigid body, C++)."""
        theta, thetad, thetadd, _ = self._flat_output(q, qd, qdd, qddd, qdddd)
        return theta, thetad, thetadd

    def inverse_dynamics(
        self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, qddd: ArrayLike, qdddd: ArrayLike
    ) -> tuple[Array, Array]:
        """(theta, tau): the motor position and motor torque that make the links follow q(t)
        (the link trajectory is a flat output; paper eq. (4)): theta from :meth:`motor_motion`,
        tau = B thetadd + K (theta - q) + tau_F(thetad). One sample (n,) each or (T, n)."""
        theta, thetad, thetadd, tau_l = self._flat_output(q, qd, qdd, qddd, qdddd)
        # K (theta - q) is tau_l itself: using it avoids the cancellation in theta - q for stiff K
        tau: Array = _core._motor_torque(*self._drives, thetad, thetadd, tau_l, 0.0)
        return theta, tau

    def _flat_output(
        self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, qddd: ArrayLike, qdddd: ArrayLike
    ) -> tuple[Array, Array, Array, Array]:
        """theta, thetad, thetadd and the link torque tau_l = K (theta - q) for a link motion."""
        q_, qd_, qdd_, qddd_, qdddd_ = self._samples(q=q, qd=qd, qdd=qdd, qddd=qddd, qdddd=qdddd)
        tau_l, tau_l_dot, tau_l_ddot = self.link.rnea_time_derivatives(q_, qd_, qdd_, qddd_, qdddd_)
        return (q_ + tau_l / self.K, qd_ + tau_l_dot / self.K, qdd_ + tau_l_ddot / self.K, tau_l)

    # ---- helpers -------------------------------------------------------------------------------
    @property
    def _drives(self) -> tuple[Array, Array, Array, Array]:
        """(K, B, Fv_m, Fs_m): the drives as the C++ motor equation takes them."""
        return self.K, self.B, self.Fv_m, self.Fs_m

    def _samples(self, **arrays: ArrayLike) -> list[Array]:
        """Each argument as float64 (n,) or (T, n), all of the first one's shape; ValueError
        naming the argument otherwise."""
        n = self.n
        out: list[Array] = []
        first_name, first_shape = "", ()
        for name, value in arrays.items():
            a = checks.real_array(value, name)
            if a.ndim not in (1, 2) or a.shape[-1] != n:
                raise ValueError(f"{name}: expected shape ({n},) or (T, {n}), got {a.shape}")
            if not out:
                first_name, first_shape = name, a.shape
            elif a.shape != first_shape:
                raise ValueError(
                    f"{name}: expected shape {first_shape} like {first_name}, got {a.shape}"
                )
            out.append(a)
        return out


def _per_joint(value: ArrayLike, name: str, n: int, positive: bool = False) -> Array:
    """A number or (n,) of finite values, > 0 (``positive``) or >= 0, as a read-only (n,) array."""
    a = checks.real_array(value, name)
    if a.ndim == 0:
        a = np.full(n, float(a))
    elif a.shape != (n,):
        raise ValueError(f"{name}: expected a number or shape ({n},), got {a.shape}")
    else:
        a = a.copy()
    if positive and not np.all(a > 0.0):
        raise ValueError(f"{name}: expected values > 0, got {a}")
    if not positive and not np.all(a >= 0.0):
        raise ValueError(f"{name}: expected values >= 0, got {a}")
    a.setflags(write=False)
    return a
