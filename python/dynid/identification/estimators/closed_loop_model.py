"""The closed loop of IDIM-IV and DIDIM: the robot of an estimate, simulated under the user's
controller along the reference it tracked (Gautier, Janot & Vandanjon, IEEE TCST 21(2), 2013;
Janot, Vandanjon & Gautier, IEEE TCST 22(1), 2014).

Both estimators need, for an estimate theta_k, the run the robot *would* have made: the direct
dynamic model with the base parameters theta_k, driven by the same control law (PD, PD +
gravity, computed torque, or a Python controller), the same gains and the same reference, from
the measured initial state. ``dynid.sim.simulate`` runs it in C++ (RK4 at the control period,
the torque held over it). Its states give the noise-free regressor Z = Y(q_s, qd_s, qdd_s)
(IDIM-IV's instruments) and its torque the simulated output tau_s (DIDIM).

The robot of theta_k: base parameters are linear combinations beta @ pi of the standard ones
(``dynid.model.base_parameters``), with beta = [I | T] on the independent columns; the standard
vector with the independent entries set to theta_k and every other one zero has exactly these
base parameters, hence the same M(q), c, g and friction (notes, "Dynamic parameters of robots").

The options (``identify_log(estimator_options=...)``, the CLI's flags of the same names):
``controller`` ("pd", "pd_gravity", "computed_torque" or a callable ``(t, q, qd) -> tau`` on the
log's clock), ``kp``, ``kd`` (scalars or one per joint), ``reference`` (a file, a mapping
``{"t", "q_d"[, "qd_d", "qdd_d"]}`` or a callable ``reference(t) -> (q_d, qd_d, qdd_d)``, all on
the log's clock), ``controller_model`` (the robot the controller's gravity / computed torque
use; default the identified robot as given), ``control_period`` (the controller's period in s;
default the prepared log's sample period), ``iterations`` (at most; default 30).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...logs.reference import SampledReference, load_reference
from ...model.robot import Robot
from ...sim.closed_loop import Simulation, simulate
from ...sim.controllers import PD, ComputedTorque, PDGravity, gains
from .base import Problem

CONTROLLERS = ("pd", "pd_gravity", "computed_torque")
OPTIONS = (
    "controller",
    "kp",
    "kd",
    "reference",
    "controller_model",
    "control_period",
    "iterations",
)
DEFAULT_ITERATIONS = 30

#: An iteration has settled when no coefficient moved by more than this many of its standard
#: deviations (the estimate's own uncertainty is the natural scale of "no longer changes").
SETTLED_STD = 1e-3


@dataclass(frozen=True, eq=False)
class ClosedLoop:
    """The controller of the experiment, as the options describe it."""

    controller: str | Callable[..., Any]  #: one of CONTROLLERS, or a Python controller
    kp: NDArray[np.float64] | None
    kd: NDArray[np.float64] | None
    reference: Callable[..., Any] | None  #: reference(t on the log's clock) -> q_d, qd_d, qdd_d
    controller_model: Robot | None  #: for pd_gravity and computed_torque
    control_period: float | None  #: None: each run's sample period
    iterations: int

    def report(self, options: Mapping[str, Any]) -> dict[str, Any]:
        """What the result file records of the loop, JSON-ready: the options as given (arrays
        as lists, callables and robots by their kind, paths as text) and the controller."""
        name = self.controller if isinstance(self.controller, str) else "python"
        return {"options": {k: _plain(v) for k, v in options.items()}, "controller": name}


def closed_loop(problem: Problem) -> ClosedLoop:
    """The options of ``problem`` checked; ValueError naming the option."""
    options: Mapping[str, Any] = problem.options
    n = problem.n
    controller = options.get("controller")
    kp: NDArray[np.float64] | None = None
    kd: NDArray[np.float64] | None = None
    reference: Callable[..., Any] | None = None
    if controller is None:
        raise ValueError(
            f"controller: the closed-loop estimators need the controller of the experiment, "
            f"one of {CONTROLLERS} or a callable controller(t, q, qd) -> tau"
        )
    if isinstance(controller, str):
        if controller not in CONTROLLERS:
            raise ValueError(f"controller: expected one of {CONTROLLERS}, got {controller!r}")
        if options.get("kp") is None or options.get("kd") is None:
            raise ValueError(f"kp, kd: the gains of controller {controller!r} are needed")
        kp, kd = gains(options["kp"], "kp", n), gains(options["kd"], "kd", n)
        if options.get("reference") is None:
            raise ValueError(
                "reference: the trajectory the controller tracked is needed (a file with t and "
                "q_d on the log's clock, a mapping or a callable reference(t))"
            )
        reference = _reference(options["reference"], n)
    elif callable(controller):
        for name in ("kp", "kd", "reference"):
            if options.get(name) is not None:
                raise ValueError(f"{name}: not used with a Python controller (it has its own)")
    else:
        raise ValueError(
            f"controller: expected one of {CONTROLLERS} or a callable controller(t, q, qd) -> "
            f"tau, got {type(controller).__name__}"
        )
    model = options.get("controller_model")
    if model is not None:
        if controller not in ("pd_gravity", "computed_torque"):
            raise ValueError(
                "controller_model: only for controller 'pd_gravity' or 'computed_torque'"
            )
        model = _controller_model(model, problem.robot)
    elif controller in ("pd_gravity", "computed_torque"):
        model = problem.robot
    period = options.get("control_period")
    if period is not None:
        if isinstance(period, (bool, np.bool_)) or not isinstance(period, (int, float)):
            raise ValueError(f"control_period: expected a time > 0 in seconds, got {period!r}")
        if not (np.isfinite(period) and period > 0):
            raise ValueError(f"control_period: expected a time > 0 in seconds, got {period!r}")
        period = float(period)
    iterations = options.get("iterations", DEFAULT_ITERATIONS)
    if (
        isinstance(iterations, (bool, np.bool_))
        or not isinstance(iterations, (int, np.integer))
        or iterations < 1
    ):
        raise ValueError(f"iterations: expected an integer >= 1, got {iterations!r}")
    return ClosedLoop(controller, kp, kd, reference, model, period, int(iterations))


def plant(problem: Problem, theta: NDArray[np.float64]) -> Robot:
    """A robot whose base parameters are theta's rigid-body part (the module docstring): the
    independent standard parameters set to them, the others zero; no Ia, Fv, Fs unless the
    identification has their columns."""
    rigid = problem.model.rigid
    robot = rigid.robot.copy()
    n = robot.n
    pi = np.zeros(rigid.parameter_count)
    pi[rigid.independent] = theta[: rigid.size]
    robot.params = pi[: 10 * n].reshape(n, 10)
    rest = pi[10 * n :]
    robot.Ia = rest[:n] if rigid.rotor else np.zeros(n)
    friction = rest[n:] if rigid.rotor else rest
    robot.Fv = friction[:n] if rigid.friction else np.zeros(n)
    robot.Fs = friction[n:] if rigid.friction else np.zeros(n)
    return robot


def simulate_runs(problem: Problem, loop: ClosedLoop, robot: Robot) -> list[Simulation]:
    """Each training log's run simulated with ``robot`` as the plant, sampled at the log's
    instants (the simulation's own are those divided by the control period)."""
    sims = []
    for run in problem.runs:
        assert run.qd is not None  # prepared: identify_log computed them
        t = run.t - run.t[0]
        dt = loop.control_period or float(np.median(np.diff(t)))
        steps = t / dt
        index = np.rint(steps).astype(np.int64)
        if np.abs(steps - index).max() > 1e-6 or np.any(np.diff(index) <= 0):
            raise ValueError(
                f"control_period: the samples of {run.source or 'the log'} are not whole "
                f"control periods of {dt:.9g} s apart (give the controller's period, or "
                f"resample the log: preparation nonuniform='resample')"
            )
        instants = np.arange(index[-1] + 1) * dt
        controller = _controller(loop, robot, instants + run.t[0], run.t[0])
        try:
            sim = simulate(
                robot,
                run.q[0],
                run.qd[0],
                index[-1] * dt,
                controller,
                dt=dt,
                friction=bool(problem.model.rigid.friction),
            )
        except ValueError as exc:
            if "positive definite" not in str(exc):
                raise
            # An estimate whose M(q) is not positive definite has no direct dynamics: the log
            # leaves the inertial parameters too uncertain for a simulation of the loop.
            raise ValueError(
                f"log: the robot of the estimate has a mass matrix that is not positive "
                f"definite along {run.source or 'the log'}, so the closed loop cannot be "
                f"simulated with it (the log does not determine the inertial parameters well "
                f"enough: a more exciting log, or method 'wls'/'ols')"
            ) from None
        if not (np.all(np.isfinite(sim.q)) and np.all(np.isfinite(sim.tau))):
            raise ValueError(
                "controller: the closed loop simulated with the estimate diverges (check the "
                "controller, its gains, control_period and the reference)"
            )
        sims.append(
            Simulation(
                t=run.t,
                q=sim.q[index],
                qd=sim.qd[index],
                qdd=sim.qdd[index],
                tau=sim.tau[index],
                q_measured=sim.q_measured[index],
            )
        )
    return sims


def simulated_columns(problem: Problem, sims: list[Simulation]) -> NDArray[np.float64]:
    """(T, n, p) the identification's columns at the simulated states, the rows left out zero."""
    Z = np.concatenate([problem.model.regressor(s.q, s.qd, s.qdd) for s in sims])
    return np.where(problem.keep[:, :, None], Z, 0.0)


def simulated_torque(problem: Problem, sims: list[Simulation]) -> NDArray[np.float64]:
    """(T, n) the simulated controller torque, the rows left out zero."""
    return np.where(problem.keep, np.concatenate([s.tau for s in sims]), 0.0)


def _controller(loop: ClosedLoop, robot: Robot, clock: NDArray, t0: float) -> Any:
    """The control law for dynid.sim.simulate at the simulation's instants ``clock`` (on the
    log's clock)."""
    if not isinstance(loop.controller, str):
        function = loop.controller
        return lambda t, q, qd: function(t + t0, q, qd)
    assert loop.reference is not None and loop.kp is not None and loop.kd is not None
    reference = _sampled(loop.reference, clock, robot.n)
    if loop.controller == "pd":
        return PD(loop.kp, loop.kd, reference)
    assert loop.controller_model is not None
    kind = PDGravity if loop.controller == "pd_gravity" else ComputedTorque
    return kind(loop.controller_model, loop.kp, loop.kd, reference)


def _sampled(reference: Callable[..., Any], clock: NDArray, n: int) -> tuple[NDArray, ...]:
    values = reference(clock.copy())
    if not isinstance(values, tuple) or len(values) != 3:
        raise ValueError("reference: expected reference(t) to return (q_d, qd_d, qdd_d)")
    out = []
    for name, value in zip(("q_d", "qd_d", "qdd_d"), values):
        array = np.asarray(value, dtype=float)
        if array.shape != (clock.size, n) or not np.all(np.isfinite(array)):
            raise ValueError(
                f"reference: {name} must be finite, shape ({clock.size}, {n}), got {array.shape}"
            )
        out.append(np.ascontiguousarray(array))
    return tuple(out)


def _reference(value: Any, n: int) -> Callable[..., Any]:
    if isinstance(value, (str, Path)):
        sampled = load_reference(value)
    elif isinstance(value, Mapping):
        unknown = set(value) - {"t", "q_d", "qd_d", "qdd_d"}
        if unknown or "t" not in value or "q_d" not in value:
            raise ValueError(
                f"reference: a mapping needs t and q_d (optionally qd_d, qdd_d), got "
                f"{sorted(value)}"
            )
        sampled = SampledReference(value["t"], value["q_d"], value.get("qd_d"), value.get("qdd_d"))
    elif callable(value):
        return value
    else:
        raise ValueError(
            f"reference: expected a file, a mapping or a callable reference(t), got "
            f"{type(value).__name__}"
        )
    if sampled.n != n:
        raise ValueError(f"reference: has {sampled.n} joints, the robot {n}")
    return sampled


def _controller_model(value: Any, robot: Robot) -> Robot:
    if isinstance(value, (str, Path)):
        from ...model.model_files import load_model

        value = load_model(value)
    if not isinstance(value, Robot) or value.n != robot.n:
        raise ValueError(
            f"controller_model: expected a dynid.Robot (or a model file) with {robot.n} joints, "
            f"got {getattr(value, 'n', type(value).__name__)}"
        )
    return value


def _plain(value: Any) -> Any:
    """An option's value for result.json."""
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, Robot):
        return f"robot {value.name}"
    if isinstance(value, Mapping):
        return "samples"
    if callable(value):
        return "python callable"
    return np.asarray(value, dtype=float).tolist()
