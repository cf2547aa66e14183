"""Control laws for :func:`dynid.sim.simulate`, run in C++ at the controller rate.

Each law is a small description (gains, a desired trajectory and, where it uses one, the
controller's own model of the robot); :func:`~dynid.sim.simulate` samples the desired trajectory
at the control instants and runs the law in C++ (``cpp/src/controllers.cpp``). The controller's
model may differ from the simulated robot, so that a model mismatch shows in the tracking.

The desired trajectory (``reference``) is one of

- a setpoint q_d, shape (n,): qd_d = qdd_d = 0;
- a tuple ``(q_d, qd_d, qdd_d)`` of arrays (K + 1, n) sampled at t_k = k dt, k = 0..K;
- a callable ``reference(t) -> (q_d, qd_d, qdd_d)`` taking the (K + 1,) control instants and
  returning three (K + 1, n) arrays (e.g. :func:`dynid.sim.paper_validation_trajectory`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import real_array
from ..model.robot import Robot

Reference = Union[ArrayLike, tuple[ArrayLike, ArrayLike, ArrayLike], Callable[..., Any]]


@dataclass(frozen=True)
class PD:
    """tau = Kp (q_d - q) + Kd (qd_d - qd); ``kp``, ``kd`` a scalar or one gain per joint."""

    kp: ArrayLike
    kd: ArrayLike
    reference: Reference

    kind = "pd"


@dataclass(frozen=True)
class PDGravity:
    """PD with gravity compensation, tau = Kp e + Kd ed + g_model(q) (Takegaki-Arimoto): for a
    setpoint and an exact gravity model, V = T + 1/2 e^T Kp e never increases and q -> q_d."""

    model: Robot
    kp: ArrayLike
    kd: ArrayLike
    reference: Reference

    kind = "pd_gravity"


@dataclass(frozen=True)
class ComputedTorque:
    """Computed torque, tau = M(q) (qdd_d + Kd ed + Kp e) + c(q, qd) + g(q) + F(qd) of ``model``
    (notes, "inverse dynamics"): with the plant's exact model the tracking error obeys
    edd + Kd ed + Kp e = 0 up to the zero-order hold of the torque."""

    model: Robot
    kp: ArrayLike
    kd: ArrayLike
    reference: Reference

    kind = "computed_torque"


Controller = Union[PD, PDGravity, ComputedTorque, Callable[..., Any]]


def gains(value: ArrayLike, name: str, n: int) -> NDArray[np.float64]:
    """A scalar or (n,) gain as (n,) float64, finite and >= 0."""
    array = real_array(value, name)
    if array.ndim == 0:
        array = np.full(n, float(array))
    if array.shape != (n,):
        raise ValueError(f"{name}: expected a scalar or shape ({n},), got shape {array.shape}")
    if np.any(array < 0.0):
        raise ValueError(f"{name}: expected gains >= 0, got {array}")
    return array


def sample_reference(
    reference: Reference, t: NDArray[np.float64], n: int, name: str = "reference"
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The desired (q_d, qd_d, qdd_d) at the control instants ``t``, each (len(t), n);
    ``name`` is the argument named in errors."""
    rows = len(t)
    if callable(reference):
        values = reference(t.copy())
        source = f"{name}(t)"
    else:
        values = reference
        source = name
    if isinstance(values, tuple):
        if len(values) != 3:
            raise ValueError(f"{name}: expected (q_d, qd_d, qdd_d), got a tuple of {len(values)}")
        out = []
        for label, value in zip(("q_d", "qd_d", "qdd_d"), values):
            array = real_array(value, f"{name} ({label})")
            if array.shape != (rows, n):
                raise ValueError(
                    f"{name}: expected {source} {label} of shape ({rows}, {n}) (one row per "
                    f"control instant k dt, k = 0..{rows - 1}), got shape {array.shape}"
                )
            out.append(np.ascontiguousarray(array))
        return out[0], out[1], out[2]
    setpoint = real_array(values, name)
    if setpoint.shape != (n,):
        raise ValueError(
            f"{name}: expected a setpoint of shape ({n},), a tuple (q_d, qd_d, qdd_d) of "
            f"({rows}, {n}) arrays or a callable of t, got shape {setpoint.shape}"
        )
    zeros = np.zeros((rows, n))
    return np.ascontiguousarray(np.broadcast_to(setpoint, (rows, n))), zeros, zeros
