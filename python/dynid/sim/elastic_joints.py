"""Closed-loop simulation of a robot with elastic joints (Spong's model; docs/elastic.md).

The state (q, theta, qd, thetad) follows the link and motor equations (paper eqs. (1)-(2)),

    qdd = M(q)^-1 (K (theta - q) - c - g),   thetadd = B^-1 (tau - K (theta - q) - tau_F(thetad)),

tau_F = Fv_m thetad + Fs_m tanh(thetad / coulomb_band) (``coulomb_band=0``: the exact sign),
integrated in C++ by classical RK4 with h = dt / substeps while the controller's torque, computed
once per control period dt from the link and motor state and tau_J = K (theta - q), is held. The
step must resolve the joints' oscillations, sqrt(K / B) and sqrt(K / M_ii) rad/s.

Controllers: zero torque, :class:`MotorPD`, :class:`KukaLike` (the joint torque feedback of the
DLR/KUKA light-weight robots) or a Python callable.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _core
from .._checks import real_array
from ..model.elastic import ElasticRobot
from .closed_loop import _integer, _number, _vector
from .controllers import Reference, sample_reference

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]


@dataclass(frozen=True)
class MotorPD:
    """Motor PD with constant gravity compensation for a set-point q_d (Tomei 1991; De Luca,
    Siciliano, Zollo 2005): tau = kp (theta_d - theta) - kd thetad + g(q_d),
    theta_d = q_d + K^-1 g(q_d), evaluated in C++. kp, kd: a number or (n,)."""

    kp: ArrayLike
    kd: ArrayLike
    q_d: ArrayLike


@dataclass(frozen=True)
class KukaLike:
    """The joint torque controller of the DLR/KUKA light-weight robots (Albu-Schaeffer, Ott,
    Hirzinger, IJRR 2007), evaluated in C++ once per control period (docs/elastic.md):

        u   = kp e + kd ed + g_c + tau_user                       outer joint impedance law
        tau = u + K_T (u - tau_J) - D_T K_c (thetad - qd)           inner torque loop

    With D_T = 0 the loop turns the motor equation into B_theta thetadd + tau_J +
    B_theta B^-1 tau_F = u, B_theta = B / (1 + K_T): the motor inertia seen by u is shaped down.

    ``model`` is the controller's own :class:`~dynid.ElasticRobot` (its links give g_c, its
    stiffness K_c; it may differ from the plant). The position feedback is motor-side (collocated,
    which keeps the loop passive): e = theta_d - theta, ed = qd_d - thetad, theta_d = q_d +
    K_c^-1 g_c(q_d). ``gravity``: ``"static"`` (g_c(qbar(theta)), qbar solving K_c (theta - qbar)
    = g_c(qbar), Albu-Schaeffer 2007) or ``"desired"`` (g_c(q_d); for a set-point and K_T = D_T
    = 0 this is :class:`MotorPD`). ``reference`` as for
    :func:`dynid.sim.simulate` (a set-point, a tuple (q_d, qd_d, qdd_d) of (K + 1, n) arrays or a
    callable of t; qdd_d is not used). ``tau_user``: None, (n,) or (K + 1, n) [N m], added to u
    (the FRI's commanded torque). Gains: a number >= 0 or (n,)."""

    model: ElasticRobot
    kp: ArrayLike
    kd: ArrayLike
    reference: Reference
    torque_gain: ArrayLike = 0.0
    torque_damping: ArrayLike = 0.0
    gravity: str = "static"
    tau_user: ArrayLike | None = None


@dataclass(frozen=True)
class ElasticSimulation:
    """An elastic-joint run, sampled at t_k = k dt, k = 0..K ((K + 1, n) arrays)."""

    t: Array
    q: Array
    qd: Array
    theta: Array
    thetad: Array
    tau: Array  #: motor torque commanded (held over the period)
    tau_J: Array  #: elastic torque K (theta - q), what the joint torque sensors read


ElasticControllerFunction = Callable[[float, Array, Array, Array, Array, Array], ArrayLike]


def simulate_elastic(
    elastic: ElasticRobot,
    q0: ArrayLike,
    theta0: ArrayLike | None = None,
    qd0: ArrayLike | None = None,
    thetad0: ArrayLike | None = None,
    duration: float = 1.0,
    controller: MotorPD | KukaLike | ElasticControllerFunction | None = None,
    *,
    dt: float = 1e-3,
    substeps: int = 10,
    coulomb_band: float = 1e-3,
) -> ElasticSimulation:
    """Simulate ``elastic`` from (q0, theta0, qd0, thetad0) for ``duration`` s under ``controller``:
    None (zero motor torque), :class:`MotorPD` or :class:`KukaLike` (C++), or a callable
    ``controller(t, q, qd, theta, thetad, tau_J) -> tau`` called once per period (GIL held for the
    call only). ``theta0=None`` puts the springs at the static deflection of q0,
    theta0 = q0 + K^-1 g(q0); velocities default to zero. ValueError naming the argument."""
    if not isinstance(elastic, ElasticRobot):
        raise ValueError(f"elastic: expected a dynid.ElasticRobot, got {type(elastic).__name__}")
    n = elastic.n
    q0 = _vector(q0, "q0", n)
    theta0 = (
        q0 + elastic.link.gravity(q0) / elastic.K
        if theta0 is None
        else _vector(theta0, "theta0", n)
    )
    qd0 = np.zeros(n) if qd0 is None else _vector(qd0, "qd0", n)
    thetad0 = np.zeros(n) if thetad0 is None else _vector(thetad0, "thetad0", n)
    dt = _number(dt, "dt", positive=True)
    duration = _number(duration, "duration", positive=True)
    periods = round(duration / dt)
    if (
        periods < 1
        or periods > 2**31 - 2
        or abs(periods * dt - duration) > 1e-9 * max(duration, dt)
    ):
        raise ValueError(
            f"duration: expected a positive whole number (< 2^31 - 1) of control "
            f"periods dt = {dt:g} s, got {duration:g} s"
        )
    substeps = _integer(substeps, "substeps")
    coulomb_band = _number(coulomb_band, "coulomb_band", positive=False)
    if isinstance(controller, KukaLike):
        return _simulate_kuka_like(
            elastic, controller, (q0, qd0, theta0, thetad0), periods, dt, substeps, coulomb_band
        )
    kp = kd = q_d = np.zeros(n)
    function = None
    if controller is None:
        kind = "none"
    elif isinstance(controller, MotorPD):
        kind = "motor_pd"
        kp, kd = _gain(controller.kp, "kp", n), _gain(controller.kd, "kd", n)
        q_d = _vector(controller.q_d, "q_d", n)
    elif callable(controller):
        kind, function = "callable", controller
    else:
        raise ValueError(
            "controller: expected None, a MotorPD, a KukaLike or a callable, got "
            f"{type(controller).__name__}"
        )
    q, qd, theta, thetad, tau, tau_J = _core._simulate_elastic(
        elastic.link,
        elastic.K,
        elastic.B,
        elastic.Fv_m,
        elastic.Fs_m,
        q0,
        qd0,
        theta0,
        thetad0,
        periods,
        dt,
        substeps,
        coulomb_band,
        kind,
        kp,
        kd,
        q_d,
        function,
    )
    t = np.asarray(np.arange(periods + 1) * dt, dtype=np.float64)
    return ElasticSimulation(t, q, qd, theta, thetad, tau, tau_J)


def _simulate_kuka_like(
    elastic: ElasticRobot,
    controller: KukaLike,
    start: tuple[Array, Array, Array, Array],
    periods: int,
    dt: float,
    substeps: int,
    coulomb_band: float,
) -> ElasticSimulation:
    """simulate_elastic's run under :class:`KukaLike` (arguments checked here, law in C++)."""
    n = elastic.n
    model = controller.model
    if not isinstance(model, ElasticRobot) or model.n != n:
        raise ValueError(
            f"model: expected the controller's dynid.ElasticRobot with {n} joints, got "
            f"{type(model).__name__}"
            + (f" with {model.n}" if isinstance(model, ElasticRobot) else "")
        )
    if controller.gravity not in ("static", "desired"):
        raise ValueError(f"gravity: expected 'static' or 'desired', got {controller.gravity!r}")
    t = np.asarray(np.arange(periods + 1) * dt, dtype=np.float64)
    q_d, qd_d, _ = sample_reference(controller.reference, t, n, "reference")
    tau_user = controller.tau_user
    if tau_user is not None:
        tau_user = real_array(tau_user, "tau_user")
        if tau_user.shape == (n,):
            tau_user = np.broadcast_to(tau_user, (periods + 1, n))
        if tau_user.shape != (periods + 1, n):
            raise ValueError(
                f"tau_user: expected None, shape ({n},) or ({periods + 1}, {n}) (one row per "
                f"control instant), got shape {tau_user.shape}"
            )
        tau_user = np.ascontiguousarray(tau_user)
    q, qd, theta, thetad, tau, tau_J = _core._simulate_elastic_kuka(
        elastic.link,
        elastic.K,
        elastic.B,
        elastic.Fv_m,
        elastic.Fs_m,
        *start,
        periods,
        dt,
        substeps,
        coulomb_band,
        model.link,
        model.K,
        _gain(controller.kp, "kp", n),
        _gain(controller.kd, "kd", n),
        _gain(controller.torque_gain, "torque_gain", n),
        _gain(controller.torque_damping, "torque_damping", n),
        controller.gravity,
        q_d,
        qd_d,
        tau_user,
    )
    return ElasticSimulation(t, q, qd, theta, thetad, tau, tau_J)


def _gain(value: ArrayLike, name: str, n: int) -> Array:
    """A gain >= 0: a number or (n,), as (n,)."""
    a = real_array(value, name)
    if a.ndim > 1 or (a.ndim == 1 and a.shape != (n,)) or np.any(a < 0):
        raise ValueError(f"{name}: expected a number >= 0 or ({n},) of them, got {value!r}")
    return np.ascontiguousarray(np.broadcast_to(a, (n,)))
