"""A virtual robot controller that reports what the KUKA LWR's interface reports.

The LWR's Fast Research Interface returns, for the current link position q, the numeric link
inertia matrix M(q) and gravity vector g(q) of the controller's own model, and the elastic joint
torques tau_J measured by the joint torque sensors (paper, Sect. II and eqs. (1)-(3), (7)). For
any :class:`~dynid.Robot` this class produces the same kinds of data, so that the paper's pipeline
can be run, tested and demonstrated without the hardware.

Static readings are the link equation (7), M qdd + c + g = tau_J, of the robot with its drive
terms removed (rotor inertias and friction act on the motor side of the elastic joints).

A commanded motion (:meth:`VirtualController.track`, the torque validation experiment of paper
eq. (33)) is simulated in closed loop (:func:`dynid.sim.simulate`): a 1 kHz joint position
controller (PD + gravity compensation of the controller's model, like FRI's
JointPositionController) drives the whole robot, rotor inertias and friction included, in the
rigid-joint limit of eqs. (1)-(3) (theta = q). The torque sensor sits between the gear and the
link, so it measures the link equation plus the part of the friction that acts on the link side
of it (output bearings), ``link_friction`` times the robot's Fv qd + Fs sgn(qd):

    tau_J = M(q) qdd + c(q, qd) + g(q) + rho F(qd)        (eq. (7) plus link-side friction)

plus the sensor's noise. Unlike a perfectly tracked motion, this shows what the paper's torque
validation shows on the real robot: a tracking error, measured positions that are not the
desired ones, and torque errors of the identified model, which has no friction, of a few tenths
of a N m at the joints with the largest friction.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from ..robot import Robot
from .closed_loop import Simulation, plant_friction, simulate
from .controllers import PDGravity, sample_reference
from .controllers import gains as check_gains

Trajectory = Callable[[NDArray[np.float64]], tuple[NDArray, NDArray, NDArray]]


@dataclass(frozen=True)
class StaticReadings:
    """What the controller returns at a list of configurations."""

    q: NDArray[np.float64]  #: (N, n) measured link positions
    g: NDArray[np.float64]  #: (N, n) numeric gravity vectors
    M: NDArray[np.float64]  #: (N, n, n) numeric link inertia matrices


@dataclass(frozen=True)
class TorqueRecording:
    """Measured link positions and joint torques along a commanded motion."""

    t: NDArray[np.float64]  #: (T,) seconds
    q: NDArray[np.float64]  #: (T, n) measured link positions
    tau: NDArray[np.float64]  #: (T, n) measured elastic joint torques tau_J
    q_desired: NDArray[np.float64]  #: (T, n) the commanded positions
    motion: Simulation  #: the closed-loop run: true q, qd, qdd and the commanded torques


#: Closed-loop bandwidth [rad/s] of the default position controller: each joint's PD gains put
#: its poles at -omega (critically damped) for its inertia M_ii at the start of the motion.
TRACKING_BANDWIDTH = 30.0
#: Coulomb smoothing band [rad/s] of the simulated plant (dynid.sim.simulate's coulomb_band).
COULOMB_BAND = 1e-3


class VirtualController:
    """Controller-like data for any robot, with optional Gaussian noise and a seed.

    Parameters
    ----------
    robot
        The arm whose controller is simulated. Static readings use its links only (the link
        equation (7)); :meth:`track` simulates the whole robot, rotor inertias and friction
        included.
    model_noise
        Relative standard deviation of the errors on the numeric M(q) and g(q): these are the
        controller's own model evaluated numerically, so their errors scale with the values and
        elements that are identically zero stay zero (as the paper found for M_76).
    torque_noise
        Standard deviation [N m] of the joint torque sensor noise.
    position_noise
        Standard deviation [rad or m] of the link position measurement noise.
    link_friction
        Fraction (a scalar or one per joint, in [0, 1]) of the robot's joint friction Fv, Fs that
        acts on the link side of the torque sensor and therefore appears in tau_J (0: none, the
        link equation (7) alone; 1: all of it).
    encoder_counts
        Resolution of the link position sensors in counts per revolution, seen by the position
        controller and in the recorded q (None: exact).
    seed
        Seed of the random generator (configurations and noise).
    """

    def __init__(
        self,
        robot: Robot,
        *,
        model_noise: float = 0.0,
        torque_noise: float = 0.0,
        position_noise: float = 0.0,
        link_friction: ArrayLike = 0.0,
        encoder_counts: float | None = None,
        seed: int | None = 0,
    ) -> None:
        checks.robot(robot)
        for name, value in (
            ("model_noise", model_noise),
            ("torque_noise", torque_noise),
            ("position_noise", position_noise),
        ):
            if not (np.isfinite(value) and value >= 0.0):
                raise ValueError(f"{name}: expected a finite value >= 0, got {value!r}")
        fraction = real_array(link_friction, "link_friction")
        if fraction.ndim == 0:
            fraction = np.full(robot.n, float(fraction))
        if fraction.shape != (robot.n,) or np.any((fraction < 0.0) | (fraction > 1.0)):
            raise ValueError(
                f"link_friction: expected a fraction in [0, 1], scalar or shape ({robot.n},), "
                f"got {link_friction!r}"
            )
        if encoder_counts is not None and not _positive_number(encoder_counts):
            raise ValueError(
                f"encoder_counts: expected a positive count or None, got {encoder_counts!r}"
            )
        self.plant = robot.copy()
        self.robot = robot.rigid_body()
        self.model_noise = float(model_noise)
        self.torque_noise = float(torque_noise)
        self.position_noise = float(position_noise)
        self.link_friction = fraction
        self.encoder_counts = encoder_counts
        self.seed = seed
        self.rng = np.random.default_rng(seed)

    def random_configurations(self, count: int) -> NDArray[np.float64]:
        """``count`` configurations drawn uniformly within the joint limits (paper, Sect. VI)."""
        if int(count) < 1:
            raise ValueError(f"count: expected a positive number of configurations, got {count!r}")
        low, high = self.robot.qlim[:, 0], self.robot.qlim[:, 1]
        return low + (high - low) * self.rng.random((int(count), self.robot.n))

    def read_static(self, q: ArrayLike) -> StaticReadings:
        """The numeric g(q) and M(q) at each configuration (GetCurrentGravityVector and
        GetCurrentMassMatrix), with the measured position."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        g = self._model_error(self.robot.gravity(q))
        M = self._model_error(self.robot.mass_matrix(q))
        M = 0.5 * (M + np.swapaxes(M, -1, -2))  # the controller's M is symmetric
        return StaticReadings(q=self._measure_position(q), g=g, M=M)

    def track(
        self,
        trajectory: Trajectory,
        duration: float,
        rate: float = 1000.0,
        *,
        gains: tuple[ArrayLike, ArrayLike] | None = None,
        substeps: int | None = None,
    ) -> TorqueRecording:
        """Track a commanded motion in closed loop and record q and tau_J at ``rate`` Hz.

        ``trajectory(t)`` returns the desired (q, qd, qdd) for the times t (T,), each (T, n); the
        robot starts on it at rest or moving as it says. The position controller (PD + gravity
        compensation of the controller's model, at ``rate``) has the gains ``(kp, kd)`` or, by
        default, critically damped gains of bandwidth :data:`TRACKING_BANDWIDTH` for the inertia
        at the start. The plant is integrated by RK4 with ``substeps`` steps per period; by
        default as many as the friction band needs for a stable explicit step (2 at 1 kHz for the
        LWR-IV, see :func:`stable_substeps`).
        """
        if not (np.isfinite(duration) and duration > 0.0):
            raise ValueError(f"duration: expected a positive time, got {duration!r}")
        if not (np.isfinite(rate) and rate > 0.0):
            raise ValueError(f"rate: expected a sampling rate > 0, got {rate!r}")
        periods = max(round(duration * rate), 1)
        t = np.arange(periods + 1) / rate
        q_d, qd_d, qdd_d = sample_reference(trajectory, t, self.robot.n, "trajectory")
        if gains is None:
            inertia = np.diag(self.plant.mass_matrix(q_d[0]))
            kp, kd = TRACKING_BANDWIDTH**2 * inertia, 2.0 * TRACKING_BANDWIDTH * inertia
        else:
            if not (isinstance(gains, tuple) and len(gains) == 2):
                raise ValueError(f"gains: expected a tuple (kp, kd), got {gains!r}")
            kp = check_gains(gains[0], "kp", self.robot.n)
            kd = check_gains(gains[1], "kd", self.robot.n)
        if substeps is None:
            substeps = stable_substeps(self.plant, q_d[0], 1.0 / rate, COULOMB_BAND, kd)
        run = simulate(
            self.plant,
            q_d[0],
            qd_d[0],
            periods / rate,
            PDGravity(self.robot, kp, kd, (q_d, qd_d, qdd_d)),
            dt=1.0 / rate,
            substeps=substeps,
            coulomb_band=COULOMB_BAND,
            encoder_counts=self.encoder_counts,
        )
        # The sensor between gear and link: link equation (7) plus the link-side friction.
        tau = self.robot.rnea(run.q, run.qd, run.qdd)
        tau += self.link_friction * plant_friction(self.plant, run.qd, COULOMB_BAND)
        if self.torque_noise > 0.0:
            tau = tau + self.torque_noise * self.rng.standard_normal(tau.shape)
        return TorqueRecording(
            t=t, q=self._measure_position(run.q_measured), tau=tau, q_desired=q_d, motion=run
        )

    def _model_error(self, values: NDArray[np.float64]) -> NDArray[np.float64]:
        if self.model_noise == 0.0:
            return values
        return values * (1.0 + self.model_noise * self.rng.standard_normal(values.shape))

    def _measure_position(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        if self.position_noise == 0.0:
            return q.copy()
        return q + self.position_noise * self.rng.standard_normal(q.shape)


def _positive_number(value: object) -> bool:
    if isinstance(value, (bool, np.bool_)):
        return False
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False
    return bool(np.isfinite(number) and number > 0.0)


def stable_substeps(
    robot: Robot, q: ArrayLike, dt: float, coulomb_band: float, kd: ArrayLike = 0.0
) -> int:
    """Integration steps per control period dt that keep explicit RK4 stable near qd = 0.

    There the friction and the controller's damping act as a viscous term D = diag(Fv + Fs /
    band + Kd) (with coupled drives T^T diag(Fv + Fs / band) T + diag(Kd)), whose fastest mode
    decays at the largest eigenvalue of M^-1 D; RK4 is stable for rate * h < 2.78, and h is
    chosen for rate * h <= 2 (at the configuration q).
    """
    T = robot.transmission
    motor = T.T @ np.diag(robot.Fv + robot.Fs / coulomb_band) @ T
    damping = motor + np.diag(np.broadcast_to(np.asarray(kd, dtype=float), (robot.n,)))
    L = np.linalg.cholesky(robot.mass_matrix(q))
    scaled = np.linalg.solve(L, np.linalg.solve(L, damping).T)  # L^-1 D L^-T
    rate = float(np.linalg.eigvalsh(0.5 * (scaled + scaled.T))[-1])
    return max(1, int(np.ceil(dt * rate / 2.0)))


def paper_validation_trajectory(
    t: NDArray[np.float64], n: int = 7, amplitude: float = np.pi / 2, period: float = 14.0
) -> tuple[NDArray, NDArray, NDArray]:
    """The torque validation motion of paper eq. (33): every joint follows
    q(t) = pi/2 cos(pi t / 7), from q = pi/2 at rest and back, T = 14 s."""
    w = 2.0 * np.pi / period
    t = np.asarray(t, dtype=float)[:, None]
    q = amplitude * np.cos(w * t)
    qd = -amplitude * w * np.sin(w * t)
    qdd = -amplitude * w**2 * np.cos(w * t)
    ones = np.ones((1, n))
    return q * ones, qd * ones, qdd * ones
