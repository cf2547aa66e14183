"""Identification from a measurement log: the Python side of ``dynid identify`` and ``validate``.

A log (``dynid.io``) and a robot model in, an identified torque model out (lecture, "Least
Squares (LS) identification" and "Additional remarks", Robotics 2 pp. 26-28):

1. the log is prepared (``dynid.io.prepare_log``: filtering, differentiation, decimation, sample
   removal; each step only when asked, each in ``log.notes``);
2. the regressor Y(q, qd, qdd) of every sample is computed in one batch call (C++), with the
   rotor (Ia) and friction (Fv, Fs) columns when asked, and reduced to the base parameters
   (``dynid.base_parameters``);
3. optionally one constant column per joint is appended: a torque offset (sensor bias; with
   Coulomb friction it also makes the friction asymmetric, Fs+ != Fs-);
4. the stacked system is solved by OLS or WLS (``dynid.identify.least_squares``).

The result predicts torques on any log (``predict``), is checked on another log
(:func:`validate_log`) and is saved to a folder by :func:`dynid.io.result_files.save_result`
(JSON with everything needed to apply it again, including the model's DH table, plus PNG plots)
and loaded back by :func:`dynid.load_result`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from ._equality import ValueEquality
from .base_parameters import base_parameters
from .identify import least_squares
from .io.log_files import Log
from .io.model_files import model_from_dict, model_to_dict
from .io.preparation import prepare_log
from .robot import Robot
from .validation import error_metrics, validation_table

PathLike = Union[str, Path]

#: Name of the torque-offset coefficient of joint j (1-based): "off1", "off2", ...
OFFSET_NAME = "off"

#: The options of dynid.io.prepare_log that ``preparation`` may hold.
PREPARATION = ("cutoff", "order", "differentiate", "decimate", "min_velocity", "outlier_k",
               "reference_tau")


@dataclass(eq=False)
class LogIdentification(ValueEquality):
    """An identified torque model tau = Y_base(q, qd, qdd) theta (+ offsets): see
    :func:`identify_log`.

    ``theta``, ``std`` and ``relative_std`` (percent) follow ``names``: the base parameters
    (``expressions`` gives each as a combination of the standard ones), then the offsets.
    ``independent`` and ``beta`` are those of :class:`dynid.BaseParameters` for the model's
    regressor columns ``parameter_names``. ``training`` holds the training log's source, size,
    preparation (options and notes, in words) and per-joint fit metrics.
    """

    model: dict[str, Any]  #: the robot model (``dynid.io.model_files`` format): DH table etc.
    rotor: bool
    friction: bool
    offset: bool
    method: str
    parameter_names: list[str]  #: the P standard parameters (regressor columns)
    independent: NDArray[np.int64]  #: base columns among them
    beta: NDArray[np.float64]  #: (count, P): base parameters = beta @ pi
    names: list[str]
    expressions: list[str]
    theta: NDArray[np.float64]
    std: NDArray[np.float64]
    relative_std: NDArray[np.float64]
    condition_number: float
    rank: int
    excluded: tuple[int, ...] = ()
    #: (count, count) covariance of ``theta`` (None for results saved before format version 2)
    covariance: NDArray[np.float64] | None = None
    training: dict[str, Any] = field(default_factory=dict)
    #: the prepared training log (not saved, not compared)
    log: Log | None = field(default=None, repr=False, compare=False)
    _robot: Robot | None = field(default=None, repr=False, compare=False)  # cache of ``robot``

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.model["rows"])

    @property
    def count(self) -> int:
        """Number of base parameters (offsets not included)."""
        return int(self.independent.size)

    @property
    def robot(self) -> Robot:
        """The robot model, rebuilt from ``model`` (its parameters are the prior ones, not the
        identified ones: these exist only as the base combinations ``theta``)."""
        if self._robot is None:
            self._robot = model_from_dict(self.model)
        return self._robot

    def regressor(self, q: Any, qd: Any, qdd: Any) -> NDArray[np.float64]:
        """The (T, n, p) regressor of ``theta``: base columns, then the offset columns."""
        Y = self.robot.regressor(q, qd, qdd, rotor=self.rotor, friction=self.friction)
        if Y.ndim == 2:
            Y = Y[None]
        if Y.shape[-1] != len(self.parameter_names):
            raise ValueError(
                f"model: its regressor has {Y.shape[-1]} columns, the result expects "
                f"{len(self.parameter_names)}"
            )
        Y = Y[..., self.independent]
        if self.offset:
            ones = np.broadcast_to(np.eye(self.n), (Y.shape[0], self.n, self.n))
            Y = np.concatenate([Y, ones], axis=2)
        return Y

    def predict(self, log: Log) -> NDArray[np.float64]:
        """Predicted joint torques (T, n) on ``log`` (qd, qdd computed from q when absent).

        One batch regressor call in C++ for all samples, the base columns, then ``@ theta``.
        """
        log = _with_derivatives(log, self.n, self.model.get("name", ""))
        return self.regressor(log.q, log.qd, log.qdd) @ self.theta

    def summary(self) -> str:
        """Coefficients (value, std, relative std, expression), condition number and rank, and
        the per-joint fit on the training log, as text."""
        options = ", ".join(k for k in ("rotor", "friction", "offset") if getattr(self, k))
        offsets = f" + {self.n} offsets" if self.offset else ""
        columns = "rigid body" + (f", {options}" if options else "")
        model = (f"model: {self.model.get('name') or '?'} ({self.n} joints, "
                 f"{self.model['convention']} DH); columns: {columns}")
        fit = (f"{self.count} base parameters{offsets}, {self.method.upper()}, rank "
               f"{self.rank}/{self.theta.size}, condition number {self.condition_number:.4g}")
        head = [model, fit]
        width = max(11, *(len(name) for name in self.names))
        title = f"  {'coefficient':<{width}}  {'value':>12}  {'std':>10}  {'rel.std':>8}  expression"
        lines = [title]
        for name, value, std, rel, expr in zip(self.names, self.theta, self.std,
                                               self.relative_std, self.expressions):
            lines.append(f"  {name:<{width}}  {value:>12.5g}  {std:>10.3g}  {rel:>7.3g}%  {expr}")
        text = "\n".join(head + lines)
        metrics = self.training.get("metrics")
        if metrics:
            arrays = {k: np.asarray(v, dtype=float) for k, v in metrics.items()}
            text += f"\nfit on the training log ({self.training.get('samples')} samples):\n"
            text += validation_table(arrays)
        return text


def identify_log(
    log: Log,
    robot: Robot,
    *,
    rotor: bool = False,
    friction: bool = False,
    offset: bool = False,
    method: str = "wls",
    exclude_joints: Sequence[int] = (),
    preparation: Mapping[str, Any] | None = None,
) -> LogIdentification:
    """Identify the base parameters of ``robot`` (its DH table, joint types, gravity) on ``log``.

    ``preparation``: options of :func:`dynid.io.prepare_log` (cutoff, order, differentiate,
    decimate, min_velocity, outlier_k) applied first; qd and qdd are computed from q when the log
    lacks them. ``rotor``/``friction`` add the Ia and Fv, Fs columns, ``offset`` one constant
    torque per joint. ``method`` is "ols" or "wls" (weighted by each joint's noise level, the
    default: the joints' torques differ by two orders of magnitude). ``exclude_joints`` (0-based)
    leaves those joints' rows out of the fit. Raises ValueError (RankDeficientError) when the log
    does not excite every base parameter.
    """
    if not isinstance(log, Log):
        raise ValueError(
            f"log: expected a dynid.io.Log, got {type(log).__name__}"
        )
    if not isinstance(robot, Robot):
        raise ValueError(
            f"robot: expected a dynid.Robot, got {type(robot).__name__}"
        )
    options = _options(preparation)
    prepared = _with_derivatives(prepare_log(log, **options), robot.n, robot.name)
    base = base_parameters(robot, "torque", rotor=bool(rotor), friction=bool(friction))
    names, expressions = list(base.names), list(base.expressions)
    if offset:
        names += [f"{OFFSET_NAME}{j}" for j in range(1, robot.n + 1)]
        expressions += [f"torque offset of joint {j}" for j in range(1, robot.n + 1)]
    result = LogIdentification(
        model=model_to_dict(robot), rotor=bool(rotor), friction=bool(friction),
        offset=bool(offset), method=method, parameter_names=list(base.parameter_names),
        independent=base.independent.copy(), beta=base.beta.copy(), names=names,
        expressions=expressions, theta=np.zeros(len(names)), std=np.zeros(len(names)),
        relative_std=np.zeros(len(names)), condition_number=np.nan, rank=0, log=prepared,
        _robot=robot,
    )
    Y = result.regressor(prepared.q, prepared.qd, prepared.qdd)
    fit = least_squares(Y, prepared.tau, method=method, names=names, exclude_joints=exclude_joints)
    result.theta, result.std, result.relative_std = fit.theta, fit.std, fit.relative_std
    result.condition_number, result.rank = fit.condition_number, fit.rank
    result.covariance = fit.covariance
    result.excluded = fit.excluded
    for key in ("params", "Ia", "Fv", "Fs"):  # prior values: no part of the identified model
        result.model.pop(key, None)
    result.training = {
        "source": prepared.source,
        "samples": prepared.T,
        "duration_s": prepared.duration,
        "sampling_rate_hz": prepared.fs,
        "preparation": {k: _plain(v) for k, v in options.items()},
        "notes": list(prepared.notes),
        "metrics": error_metrics(prepared.tau, Y @ fit.theta),
    }
    return result


@dataclass(eq=False)
class LogValidation(ValueEquality):
    """An identified model applied to another log: the prepared log, the predicted torques and
    the per-joint errors (:func:`dynid.validation.error_metrics`)."""

    log: Log  #: the validation log after ``preparation``
    predicted: NDArray[np.float64]
    metrics: dict[str, NDArray[np.float64]]
    preparation: dict[str, Any]
    notes: list[str] = field(default_factory=list)  #: differences from the training preparation


def run_validation(
    result: LogIdentification, log: Log, *, preparation: Mapping[str, Any] | None = None
) -> LogValidation:
    """Prepare ``log`` (``prepare_log(log, **preparation)``), predict its torques with ``result``
    and measure the errors; ``notes`` says where the preparation differs from the training
    log's (a low-pass on one and not the other biases the comparison)."""
    options = _options(preparation)
    prepared = prepare_log(log, **options) if options else log
    predicted = result.predict(prepared)
    notes = []
    trained = result.training.get("preparation", {}).get("cutoff")
    if trained != options.get("cutoff"):
        notes.append(f"the training log was {_filtered(trained)}, this one is "
                     f"{_filtered(options.get('cutoff'))}")
    return LogValidation(prepared, predicted, error_metrics(prepared.tau, predicted), options,
                         notes)


def validate_log(
    result: LogIdentification, log: Log, *, preparation: Mapping[str, Any] | None = None
) -> dict[str, NDArray[np.float64]]:
    """Per-joint errors of ``result`` on another log (``prepare_log(log, **preparation)``
    first): ``rms``, ``relative_rms`` (rms error / rms of the measured torque), ``max_abs``,
    ``r2`` and ``mse`` (see :func:`dynid.validation.error_metrics`)."""
    return run_validation(result, log, preparation=preparation).metrics


def _filtered(cutoff: float | None) -> str:
    return "not low-passed" if cutoff is None else f"low-passed at {cutoff:g} Hz"


def _options(preparation: Mapping[str, Any] | None) -> dict[str, Any]:
    """The prepare_log options given (None values left out), checked by name."""
    options = {k: v for k, v in dict(preparation or {}).items() if v is not None}
    unknown = sorted(set(options) - set(PREPARATION))
    if unknown:
        raise ValueError(f"preparation: unknown option(s) {unknown}; expected some of "
                         f"{', '.join(PREPARATION)} (dynid.io.prepare_log)")
    return options


def _plain(value: Any) -> Any:
    """A JSON-ready record of an option value (a callable reference torque by its name)."""
    if callable(value):
        return f"<{getattr(value, '__name__', type(value).__name__)}>"
    array = np.asarray(value)
    if array.dtype.kind not in "biuf":
        return str(value)
    return array.tolist() if array.size <= 64 else f"<array of shape {array.shape}>"


def _with_derivatives(log: Log, n: int, name: str) -> Log:
    if not isinstance(log, Log):
        raise ValueError(
            f"log: expected a dynid.io.Log, got {type(log).__name__}"
        )
    if log.n != n:
        raise ValueError(f"log: has {log.n} joints, but the model {name!r} has {n}")
    if log.qd is None or log.qdd is None:
        log = prepare_log(log, differentiate="missing")
    return log
