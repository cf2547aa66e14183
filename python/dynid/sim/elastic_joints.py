"""Closed-loop simulation of a robot with elastic joints (Spong's model; docs/elastic.md).

The state (q, theta, qd, thetad) follows the link and motor equations (paper eqs. (1)-(2)),

    qdd = M(q)^-1 (K (theta - q) - c - g),   thetadd = B^-1 (tau - K (theta - q) - tau_F(thetad)),

tau_F = Fv_m thetad + Fs_m tanh(thetad / coulomb_band) (``coulomb_band=0``: the exact sign),
integrated in C++ by classical RK4 with h = dt / substeps while the controller's torque, computed
once per control period dt from the link and motor state and tau_J = K (theta - q), is held. The
step must resolve the joints' oscillations, sqrt(K / B) and sqrt(K / M_ii) rad/s.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _core
from .._checks import real_array
from ..elastic import ElasticRobot
from .closed_loop import _integer, _number, _vector

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
    controller: MotorPD | ElasticControllerFunction | None = None,
    *,
    dt: float = 1e-3,
    substeps: int = 10,
    coulomb_band: float = 1e-3,
) -> ElasticSimulation:
    """Simulate ``elastic`` from (q0, theta0, qd0, thetad0) for ``duration`` s under ``controller``:
    None (zero motor torque), :class:`MotorPD` (C++), or a callable
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
            f"controller: expected None, a MotorPD or a callable, got {type(controller).__name__}"
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


def _gain(value: ArrayLike, name: str, n: int) -> Array:
    """A gain >= 0: a number or (n,), as (n,)."""
    a = real_array(value, name)
    if a.ndim > 1 or (a.ndim == 1 and a.shape != (n,)) or np.any(a < 0):
        raise ValueError(f"{name}: expected a number >= 0 or ({n},) of them, got {value!r}")
    return np.ascontiguousarray(np.broadcast_to(a, (n,)))
