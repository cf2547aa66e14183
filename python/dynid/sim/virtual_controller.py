"""A virtual robot controller that reports what the KUKA LWR's interface reports.

The LWR's Fast Research Interface returns, for the current link position q, the numeric link
inertia matrix M(q) and gravity vector g(q) of the controller's own model, and the elastic joint
torques tau_J measured by the joint torque sensors (paper, Sect. II and eqs. (1)-(3), (7)). For
any :class:`~dynid.Robot` this class produces the same kinds of data, so that the paper's pipeline
can be run, tested and demonstrated without the hardware.

Only the link equation (7) is simulated: M qdd + c + g = tau_J. The rotor inertias and the
friction act on the motor side of the elastic joints and do not appear in tau_J, so the model is
the robot with its drive terms removed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..robot import Robot

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


class VirtualController:
    """Controller-like data for any robot, with optional Gaussian noise and a seed.

    Parameters
    ----------
    robot
        The arm whose controller is simulated; its drive terms are ignored (link dynamics only).
    model_noise
        Relative standard deviation of the errors on the numeric M(q) and g(q): these are the
        controller's own model evaluated numerically, so their errors scale with the values and
        elements that are identically zero stay zero (as the paper found for M_76).
    torque_noise
        Standard deviation [N m] of the joint torque sensor noise.
    position_noise
        Standard deviation [rad or m] of the link position measurement noise.
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
        seed: int | None = 0,
    ) -> None:
        for name, value in (
            ("model_noise", model_noise),
            ("torque_noise", torque_noise),
            ("position_noise", position_noise),
        ):
            if not (np.isfinite(value) and value >= 0.0):
                raise ValueError(f"{name}: expected a finite value >= 0, got {value!r}")
        self.robot = robot.rigid_body()
        self.model_noise = float(model_noise)
        self.torque_noise = float(torque_noise)
        self.position_noise = float(position_noise)
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

    def track(self, trajectory: Trajectory, duration: float, rate: float = 1000.0) -> TorqueRecording:
        """Run a commanded motion (tracked perfectly) and record q and tau_J at ``rate`` Hz.

        ``trajectory(t)`` returns (q, qd, qdd) for the times t (T,), each (T, n).
        """
        if not (np.isfinite(duration) and duration > 0.0):
            raise ValueError(f"duration: expected a positive time, got {duration!r}")
        if not (np.isfinite(rate) and rate > 0.0):
            raise ValueError(f"rate: expected a positive sampling rate, got {rate!r}")
        t = np.arange(round(duration * rate) + 1) / rate
        q, qd, qdd = trajectory(t)
        tau = self.robot.rnea(q, qd, qdd)  # link equation (7): M qdd + c + g = tau_J
        if self.torque_noise > 0.0:
            tau = tau + self.torque_noise * self.rng.standard_normal(tau.shape)
        return TorqueRecording(t=t, q=self._measure_position(q), tau=tau)

    def _model_error(self, values: NDArray[np.float64]) -> NDArray[np.float64]:
        if self.model_noise == 0.0:
            return values
        return values * (1.0 + self.model_noise * self.rng.standard_normal(values.shape))

    def _measure_position(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        if self.position_noise == 0.0:
            return q.copy()
        return q + self.position_noise * self.rng.standard_normal(q.shape)


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
