"""An experiment's trajectory as a file: the Fourier series with what a controller and a later
``dynid`` command need to replay it (joint names, limits, how it starts and stops, how long).

``trajectory.json`` (written by ``dynid excite``, :mod:`dynid.export.trajectory_out`) holds
:func:`trajectory_to_dict`; :func:`load_trajectory` reads it back into an
:class:`ExperimentTrajectory`, whose :meth:`~ExperimentTrajectory.evaluate` is the function the
other files (CSV, ROS YAML, C++ header) were sampled from.

How it starts and stops (``ramp = "rest_to_rest"``): the series is rest-to-rest
(:func:`dynid.excitation.rest_to_rest`: qd(0) = qdd(0) = 0, so also at every multiple of the
period) and is played for a whole number of periods from t = 0 to t = duration; before 0 and after
the duration the arm stands at q(0) = q(duration). Velocity and acceleration are continuous at
both ends and the limits hold throughout, since the ramp is the optimised series itself; the
jerk jumps at the ends (docs/excitation.md).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .trajectory import FourierTrajectory, _finite_array

#: The ``format`` of trajectory.json and the version this module reads and writes.
FORMAT = "dynid-trajectory"
VERSION = 1
RAMPS = ("rest_to_rest",)

#: Times this close to a multiple of the period [s] are rest instants (qd, qdd set to 0; their
#: true values are below 1e-17 there: qd ~ jerk t^2 / 2).
REST_SNAP = 1e-9

# A rest-to-rest series has qd(0) = qdd(0) = 0 up to rounding of its coefficients.
_REST_TOLERANCE = 1e-9


@dataclass(frozen=True, eq=False)
class ExperimentTrajectory:
    """A trajectory to play on the robot: ``trajectory`` for ``periods`` periods from t = 0."""

    trajectory: FourierTrajectory
    joint_names: tuple[str, ...]
    periods: int = 1
    ramp: str = "rest_to_rest"
    #: the limits it was designed for: q_min, q_max, qd_max, qdd_max, tau_max (lists; tau_max
    #: may be None) and position_margin
    limits: dict[str, Any] = field(default_factory=dict)
    model: str = ""  #: the model it was optimised for (its name)
    condition_number: float = float("nan")  #: excitation_condition_number of the series

    def __post_init__(self) -> None:
        if not isinstance(self.trajectory, FourierTrajectory):
            raise ValueError(
                f"trajectory: expected a FourierTrajectory, got {type(self.trajectory).__name__}"
            )
        names = tuple(self.joint_names)
        if len(names) != self.trajectory.n or not all(isinstance(s, str) for s in names):
            raise ValueError(
                f"joint_names: expected {self.trajectory.n} names, got {self.joint_names!r}"
            )
        object.__setattr__(self, "joint_names", names)
        if isinstance(self.periods, bool) or not isinstance(self.periods, int) or self.periods < 1:
            raise ValueError(f"periods: expected a whole number >= 1, got {self.periods!r}")
        if self.ramp not in RAMPS:
            raise ValueError(f"ramp: expected one of {', '.join(RAMPS)}, got {self.ramp!r}")
        traj = self.trajectory
        _, qd, qdd = traj.evaluate(0.0)
        ell = np.arange(1.0, traj.harmonics + 1)
        # qd(0) = sum_l a_l, qdd(0) = wf sum_l l b_l: zero up to the rounding of these sums
        qd_scale = 1.0 + np.abs(traj.a).sum(axis=1)
        qdd_scale = traj.base_frequency * (1.0 + np.abs(traj.b) @ ell)
        if np.any(np.abs(qd) > _REST_TOLERANCE * qd_scale) or np.any(
            np.abs(qdd) > _REST_TOLERANCE * qdd_scale
        ):
            raise ValueError(
                "trajectory: ramp 'rest_to_rest' needs qd(0) = qdd(0) = 0 "
                "(dynid.excitation.rest_to_rest)"
            )

    @property
    def duration(self) -> float:
        return self.periods * self.trajectory.period

    def evaluate(
        self, t: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """q, qd, qdd at times ``t`` (see FourierTrajectory.evaluate), t clamped to
        [0, duration]: at rest outside. At the rest instants (multiples of the period, within
        REST_SNAP) qd and qdd are exactly 0, not rounding noise of either sign, so that a
        torque predicted there has the Coulomb term sign(0) = 0."""
        times = np.clip(_finite_array(t, "t"), 0.0, self.duration)
        q, qd, qdd = self.trajectory.evaluate(times)
        period = self.trajectory.period
        rest = np.abs(times - period * np.round(times / period)) <= REST_SNAP
        qd, qdd = np.where(rest[..., None] if rest.ndim else rest, 0.0, (qd, qdd))
        return q, qd, qdd

    def times(self, rate: float) -> NDArray[np.float64]:
        """t = k / rate for k = 0, 1, ... up to and including the duration (rate in Hz)."""
        value = _finite_array(rate, "rate")
        if value.ndim != 0 or not value > 0:
            raise ValueError(
                f"rate: expected a positive number of samples per second, got {rate!r}"
            )
        count = int(np.floor(self.duration * float(value) + 1e-9)) + 1
        return np.arange(count) / float(value)


def trajectory_to_dict(plan: ExperimentTrajectory) -> dict[str, Any]:
    """trajectory.json's content (docs/excitation.md, "Files")."""
    traj = plan.trajectory
    return {
        "format": FORMAT,
        "version": VERSION,
        "model": plan.model,
        "joint_names": list(plan.joint_names),
        "base_frequency": traj.base_frequency,
        "period": traj.period,
        "harmonics": traj.harmonics,
        "periods": plan.periods,
        "duration": plan.duration,
        "ramp": plan.ramp,
        "a": traj.a.tolist(),
        "b": traj.b.tolist(),
        "q0": traj.q0.tolist(),
        "limits": plan.limits,
        # JSON has no NaN: an unknown condition number is null
        "condition_number": plan.condition_number if np.isfinite(plan.condition_number) else None,
    }


def trajectory_from_dict(data: Any, where: str = "trajectory") -> ExperimentTrajectory:
    """The inverse of :func:`trajectory_to_dict`; ValueError naming ``where`` and the field."""
    if not isinstance(data, dict):
        raise ValueError(f"{where}: expected a JSON object, got {type(data).__name__}")
    if data.get("format") != FORMAT or data.get("version") != VERSION:
        raise ValueError(
            f"{where}: format/version: expected {FORMAT!r} version {VERSION}, got "
            f"{data.get('format')!r} version {data.get('version')!r}"
        )
    missing = [k for k in ("joint_names", "base_frequency", "a", "b", "q0") if k not in data]
    if missing:
        raise ValueError(f"{where}: {missing[0]}: missing")
    try:
        traj = FourierTrajectory(data["base_frequency"], data["a"], data["b"], data["q0"])
        names = data["joint_names"]
        if not isinstance(names, list):
            raise ValueError(f"joint_names: expected a list of names, got {names!r}")
        limits = data.get("limits", {})
        if not isinstance(limits, dict):
            raise ValueError(f"limits: expected an object, got {limits!r}")
        condition = data.get("condition_number", float("nan"))
        return ExperimentTrajectory(
            traj,
            tuple(names),
            periods=data.get("periods", 1),
            ramp=data.get("ramp", "rest_to_rest"),
            limits=limits,
            model=str(data.get("model", "")),
            condition_number=float("nan") if condition is None else float(condition),
        )
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{where}: {exc}") from None


def load_trajectory(path: str | Path) -> ExperimentTrajectory:
    """Read a trajectory.json written by ``dynid excite`` (or its folder)."""
    file = Path(path)
    if file.is_dir():
        file = file / "trajectory.json"
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise ValueError(f"{file}: not a JSON text file ({exc.reason})") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"{file}: malformed JSON: {exc}") from None
    return trajectory_from_dict(data, str(file))
