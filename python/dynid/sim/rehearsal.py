"""A dry run of an identification experiment: the arm tracks the exciting trajectory under its
controller, and what its sensors would record comes out (issue 21, item 2; docs/uses.md,
"A dry run of the experiment").

The plant is :func:`dynid.sim.simulate` (the C++ closed loop at the controller rate, RK4
substeps, the robot's friction). What is recorded is what a real controller logs:

- the joint positions the controller saw: quantised by the encoder (``encoder_counts`` per
  revolution or metre) when given;
- the joint torques: the torque that acted around each sample instant, the mean over the half
  periods either side (the command is held over each period: (tau_{k-1} + tau_k) / 2, what a
  torque sensor averaging over its sample period reads; the command itself would lead the
  motion by half a period), plus white ``sensor_noise``;
- ``torque_noise`` is a disturbance that acts on the plant (it moves the arm, the log does not
  see it): unmodelled torques, cogging, a noisy amplifier.

The default gains are chosen from the arm itself, so that every joint's loop has the same
bandwidth whatever its size: with m_j = M_jj(q) at the trajectory's start (the joint's own
inertia), kp_j = m_j w^2 and kd_j = 2 m_j w for PD and PD+gravity (critically damped, w = 2 pi
``bandwidth``), and kp = w^2, kd = 2 w for computed torque (whose gains act on accelerations).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from .closed_loop import Simulation, _number, simulate
from .controllers import PD, ComputedTorque, PDGravity, gains

#: The controllers a rehearsal runs (dynid.sim.controllers), by name.
CONTROLLERS = ("pd", "pd_gravity", "computed_torque")
#: Default closed-loop bandwidth [Hz] of the default gains: well above an exciting trajectory's
#: harmonics (0.1-2 Hz), well below a 1 kHz controller's rate.
DEFAULT_BANDWIDTH = 10.0

Reference = Callable[[NDArray[np.float64]], tuple[NDArray[np.float64], ...]]


@dataclass(frozen=True)
class Rehearsal:
    """What the arm's controller would log, and the simulation behind it."""

    t: NDArray[np.float64]  #: (K + 1,) s, the control instants
    q: NDArray[np.float64]  #: (K + 1, n) the positions the controller saw (quantised)
    tau: NDArray[np.float64]  #: (K + 1, n) the logged torque: acted around t_k + sensor noise
    simulation: Simulation  #: the true states and the commanded torques
    kp: NDArray[np.float64]  #: (n,) the gains used
    kd: NDArray[np.float64]
    settings: dict[str, Any]  #: what was simulated, JSON-ready (controller, noise, seed, ...)

    @property
    def tracking_error(self) -> NDArray[np.float64]:
        """(n,) the largest |q_d - q| of each joint over the run (true positions)."""
        return np.asarray(self.settings["tracking_error_max"], dtype=float)


def rehearse(
    robot: Robot,
    reference: Reference,
    duration: float,
    *,
    controller: str = "pd_gravity",
    kp: Any = None,
    kd: Any = None,
    controller_model: Robot | None = None,
    bandwidth: float = DEFAULT_BANDWIDTH,
    rate: float = 1000.0,
    substeps: int = 4,
    friction: bool = True,
    torque_noise: float = 0.0,
    sensor_noise: float = 0.0,
    encoder_counts: float | None = None,
    seed: int = 0,
) -> Rehearsal:
    """Run ``robot`` along ``reference`` (a function t -> (q_d, qd_d, qdd_d), (K + 1, n) each,
    e.g. a trajectory's ``evaluate``) for ``duration`` seconds at ``rate`` Hz under
    ``controller`` ("pd", "pd_gravity" or "computed_torque"; the last two use
    ``controller_model``, default ``robot`` itself) with gains ``kp``, ``kd`` (scalars or per
    joint; default from ``bandwidth``, module docstring). The arm starts on the reference at
    t = 0 (position and velocity). ``sensor_noise`` [N m] is added to the logged torque,
    ``torque_noise`` [N m] acts on the plant, ``encoder_counts`` quantises the positions the
    controller sees and logs; ``seed`` makes both noises repeatable. ValueError naming a bad
    argument.
    """
    if not isinstance(controller, str) or controller not in CONTROLLERS:
        raise ValueError(
            f"controller: expected one of {', '.join(CONTROLLERS)}, got {controller!r}"
        )
    if not callable(reference):
        raise ValueError("reference: expected a function t -> (q_d, qd_d, qdd_d)")
    n = robot.n
    rate = _number(rate, "rate", positive=True)
    bandwidth = _number(bandwidth, "bandwidth", positive=True)
    sensor_noise = _number(sensor_noise, "sensor_noise", positive=False)
    dt = 1.0 / rate
    periods = max(1, round(_number(duration, "duration", positive=True) * rate))
    model = robot if controller_model is None else controller_model
    q0, qd0, _ = (np.asarray(v, dtype=float) for v in reference(np.zeros(1)))
    q0, qd0 = q0.reshape(-1), qd0.reshape(-1)
    if q0.shape != (n,):
        raise ValueError(f"reference: expected (1, {n}) values at t = 0, got {q0.shape}")
    w = 2.0 * np.pi * bandwidth
    default_gains = kp is None or kd is None
    inertia = np.ones(n) if controller == "computed_torque" else np.diag(robot.mass_matrix(q0))
    kp = inertia * w**2 if kp is None else gains(kp, "kp", n)
    kd = inertia * 2.0 * w if kd is None else gains(kd, "kd", n)
    law: Any
    if controller == "pd":
        law = PD(kp, kd, reference)
    elif controller == "pd_gravity":
        law = PDGravity(model, kp, kd, reference)
    else:
        law = ComputedTorque(model, kp, kd, reference)
    run = simulate(
        robot,
        q0,
        qd0,
        periods * dt,
        law,
        dt=dt,
        substeps=substeps,
        friction=friction,
        torque_noise=torque_noise,
        encoder_counts=encoder_counts,
        seed=seed,
    )
    # The torque that acted around each sample instant: the command is held over each period,
    # so over [t_k - dt/2, t_k + dt/2] the mean torque is (tau_{k-1} + tau_k) / 2, what a torque
    # sensor averaging over its sample period (anti-aliased) reads. Logging the command itself
    # would put the torque half a period ahead of accelerations differentiated from the logged
    # motion: a bias of several standard deviations on the inertial parameters at 500 Hz.
    acted = run.tau.copy()
    acted[1:] = 0.5 * (run.tau[:-1] + run.tau[1:])
    # The sensor's noise from its own stream: the plant's disturbance uses ``seed`` itself.
    rng = np.random.default_rng([seed, 1])
    tau = acted + (rng.normal(scale=sensor_noise, size=acted.shape) if sensor_noise else 0.0)
    q_d = reference(run.t)[0]
    settings = {
        "controller": controller,
        "kp": kp.tolist(),
        "kd": kd.tolist(),
        "bandwidth_hz": bandwidth if default_gains else None,
        "rate_hz": rate,
        "duration_s": periods * dt,
        "substeps": substeps,
        "friction": bool(friction),
        "torque_noise": torque_noise,
        "sensor_noise": sensor_noise,
        "encoder_counts": encoder_counts,
        "seed": seed,
        "tracking_error_max": np.abs(q_d - run.q).max(axis=0).tolist(),
    }
    return Rehearsal(run.t, run.q_measured, tau, run, kp, kd, settings)
