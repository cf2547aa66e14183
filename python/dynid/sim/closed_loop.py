"""Closed-loop simulation of a robot under a controller at the controller's rate.

The plant follows the state equations of the notes ("State equations", "Dynamic simulation"):
with x = (q, qd),

    xd = (qd,  M(q)^-1 (tau - c(q, qd) - g(q) - F(qd))),    M(q) = B(q) + diag(Ia),

F(qd) = Fv qd + Fs tanh(qd / coulomb_band) the robot's friction (Coulomb smoothed in a small band
so that a fixed-step integrator does not chatter around qd = 0; ``coulomb_band=0`` is the exact
sign(qd) of docs/conventions.md, "Drive terms and the torque model"). A controller runs once per
control period dt from the measured state and its torque is held over the period (zero-order hold)
while the plant is integrated with ``substeps`` fixed steps h = dt / substeps: classical Runge-Kutta
4 (``method="rk4"``) or semi-implicit (symplectic) Euler, qd += h qdd(q, qd), q += h qd
(``method="euler"``). The whole loop runs in C++ without the GIL; a Python controller takes the GIL
for its call only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _core
from .._checks import real_array
from ..model.robot import Robot
from .controllers import PD, ComputedTorque, Controller, PDGravity, gains, sample_reference

METHODS = ("rk4", "euler")


@dataclass(frozen=True)
class Simulation:
    """A closed-loop run, sampled at the control instants t_k = k dt, k = 0..K."""

    t: NDArray[np.float64]  #: (K + 1,) seconds
    q: NDArray[np.float64]  #: (K + 1, n) joint positions
    qd: NDArray[np.float64]  #: (K + 1, n) joint velocities
    qdd: NDArray[np.float64]  #: (K + 1, n) accelerations at t_k under the torque held from t_k
    tau: NDArray[np.float64]  #: (K + 1, n) commanded torques (before torque noise)
    q_measured: NDArray[np.float64]  #: (K + 1, n) positions the controller saw (quantised)


def simulate(
    robot: Robot,
    q0: ArrayLike,
    qd0: ArrayLike | None = None,
    duration: float = 1.0,
    controller: Controller | None = None,
    *,
    dt: float = 1e-3,
    substeps: int = 1,
    method: str = "rk4",
    friction: bool = True,
    coulomb_band: float = 1e-3,
    torque_noise: float = 0.0,
    encoder_counts: float | None = None,
    seed: int = 0,
) -> Simulation:
    """Simulate ``robot`` from (q0, qd0) for ``duration`` seconds under ``controller``.

    Parameters
    ----------
    robot
        The plant: its links, rotor inertias Ia (in M) and, with ``friction``, its Fv and Fs.
    q0, qd0
        Initial state (n,); ``qd0=None`` starts at rest.
    duration
        Simulated time [s], a whole number of control periods dt.
    controller
        :class:`PD`, :class:`PDGravity`, :class:`ComputedTorque` (run in C++), a callable
        ``controller(t, q, qd) -> tau`` called once per control period with the measured q, qd
        (n,) (GIL held for the call only), or None for zero torque (free motion).
    dt
        Control period [s] (1e-3: a 1 kHz controller); the torque is held over it.
    substeps
        Integration steps per control period (h = dt / substeps).
    method
        ``"rk4"`` (error O(h^4)) or ``"euler"`` (semi-implicit Euler, O(h), energy error bounded).
    friction
        Include the robot's Fv qd + Fs tanh(qd / coulomb_band) in the plant.
    coulomb_band
        Velocity [rad/s or m/s] of the Coulomb smoothing; 0 for the exact sign(qd). Explicit
        integration of its slope Fs / band is stable for about h < 2.8 M_ii band / Fs_i.
    torque_noise
        Standard deviation [N m] of white noise added to each joint's torque once per control
        period (seeded; the returned ``tau`` is the command before the noise).
    encoder_counts
        Encoder counts per revolution (per metre for prismatic joints), at least 1: the controller
        sees the quantised q and, as velocity, the backward difference of the quantised positions
        over dt (at t = 0 the known qd0). None: the controller sees the exact state.
    seed
        Seed of the torque noise.
    """
    if not isinstance(robot, _core.Model):
        raise ValueError(f"robot: expected a dynid.Robot, got {type(robot).__name__}")
    n = robot.n
    q0 = _vector(q0, "q0", n)
    qd0 = np.zeros(n) if qd0 is None else _vector(qd0, "qd0", n)
    dt = _number(dt, "dt", positive=True)
    duration = _number(duration, "duration", positive=True)
    periods = round(duration / dt)
    if periods > 2**31 - 2:
        raise ValueError(
            f"duration: at most 2^31 - 2 control periods, got {periods} "
            f"({duration:g} s at dt = {dt:g} s)"
        )
    if periods < 1 or abs(periods * dt - duration) > 1e-9 * max(duration, dt):
        raise ValueError(
            f"duration: expected a positive whole number of control periods dt = {dt:g} s, "
            f"got {duration:g} s"
        )
    substeps = _integer(substeps, "substeps")
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"method: expected 'rk4' or 'euler' (semi-implicit Euler), got {method!r}")
    if not isinstance(friction, (bool, np.bool_)):
        raise ValueError(f"friction: expected True or False, got {friction!r}")
    coulomb_band = _number(coulomb_band, "coulomb_band", positive=False)
    torque_noise = _number(torque_noise, "torque_noise", positive=False)
    counts = (
        0.0 if encoder_counts is None else _number(encoder_counts, "encoder_counts", positive=True)
    )
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: expected an integer >= 0, got {seed!r}")

    t = (np.arange(periods + 1) * dt).astype(np.float64)
    law = _controller_arguments(controller, robot, t, n)
    q, qd, qdd, tau, q_measured = _core._simulate(
        robot,
        q0,
        qd0,
        periods,
        dt,
        substeps,
        method,
        bool(friction),
        coulomb_band,
        torque_noise,
        counts,
        int(seed),
        record_measured=True,
        **law,
    )
    assert q_measured is not None  # asked for with record_measured=True
    return Simulation(t=t, q=q, qd=qd, qdd=qdd, tau=tau, q_measured=q_measured)


def plant_friction(robot: Robot, qd: ArrayLike, coulomb_band: float = 1e-3) -> NDArray[np.float64]:
    """The friction torque the simulator's plant applies, Fv qd + Fs tanh(qd / coulomb_band)
    (sign(qd) for a zero band), for one sample (n,) or T samples (T, n). With coupled drives
    (``robot.transmission`` T) the friction acts on the motor velocities T qd and reaches the
    joints as T^T (Fv T qd + Fs tanh(T qd / band)) (docs/transmission.md). The law is the
    simulator's own, evaluated in C++ (``dynid::friction`` with a band, cpp/src/friction.cpp)."""
    qd = real_array(qd, "qd")
    if qd.shape[-1:] != (robot.n,) or qd.ndim > 2:
        raise ValueError(f"qd: expected shape ({robot.n},) or (T, {robot.n}), got {qd.shape}")
    band = _number(coulomb_band, "coulomb_band", positive=False)
    friction: NDArray[np.float64] = _core._friction(robot, qd, band)
    return friction


def _controller_arguments(
    controller: Controller | None, robot: Robot, t: NDArray, n: int
) -> dict[str, Any]:
    """The keyword arguments of _core._simulate that describe the control law."""
    law: dict[str, Any] = {
        "model": None,
        "kp": None,
        "kd": None,
        "q_d": None,
        "qd_d": None,
        "qdd_d": None,
        "function": None,
    }
    if controller is None:  # zero torque: a PD law with zero gains
        zeros = np.zeros(n)
        return {**law, "kind": "pd", "kp": zeros, "kd": zeros, "q_d": np.zeros((len(t), n))}
    if isinstance(controller, (PD, PDGravity, ComputedTorque)):
        if isinstance(controller, (PDGravity, ComputedTorque)):
            if not isinstance(controller.model, _core.Model) or controller.model.n != n:
                raise ValueError(
                    f"model: expected the controller's model, a dynid.Robot with {n} joints, got "
                    f"{getattr(controller.model, 'n', type(controller.model).__name__)}"
                )
            law["model"] = controller.model
        q_d, qd_d, qdd_d = sample_reference(controller.reference, t, n)
        return {
            **law,
            "kind": controller.kind,
            "kp": gains(controller.kp, "kp", n),
            "kd": gains(controller.kd, "kd", n),
            "q_d": q_d,
            "qd_d": qd_d,
            "qdd_d": qdd_d,
        }
    if callable(controller):
        return {**law, "kind": "callable", "function": controller}
    raise ValueError(
        "controller: expected PD, PDGravity, ComputedTorque, a callable controller(t, q, qd) -> "
        f"tau or None, got {type(controller).__name__}"
    )


def _vector(value: ArrayLike, name: str, n: int) -> NDArray[np.float64]:
    array = real_array(value, name)
    if array.shape != (n,):
        raise ValueError(f"{name}: expected shape ({n},), got {array.shape}")
    return array


def _number(value: Any, name: str, *, positive: bool) -> float:
    bound = "> 0" if positive else ">= 0"
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected a finite number {bound}, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a finite number {bound}, got {value!r}") from None
    if not np.isfinite(number) or number < 0.0 or (positive and number == 0.0):
        raise ValueError(f"{name}: expected a finite number {bound}, got {value!r}")
    return number


def _integer(value: Any, name: str) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name}: expected an integer >= 1, got {value!r}")
    if value > 2**31 - 1:
        raise ValueError(f"{name}: expected an integer below 2^31, got {value!r}")
    return int(value)
