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
4. the stacked system is solved by OLS or WLS (``dynid.streaming``: the regressor chunk by
   chunk into triangular factors, the solver of ``dynid.identify.least_squares``).

The result predicts torques on any log (``predict``), is checked on another log
(:func:`validate_log`) and is saved to a folder (JSON with everything needed to apply it again,
including the model's DH table, plus PNG plots) and loaded back (:func:`load_result`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from .base_parameters import base_parameters
from .io import Log, prepare_log
from .model_files import model_from_dict, model_to_dict
from .robot import Robot
from .streaming import LeastSquaresAccumulator
from .validation import error_metrics, validation_table

PathLike = Union[str, Path]

#: Name of the torque-offset coefficient of joint j (1-based): "off1", "off2", ...
OFFSET_NAME = "off"

#: Samples per regressor chunk folded into the least-squares factors.
STREAM_CHUNK = 8192

#: The options of dynid.io.prepare_log that ``preparation`` may hold.
PREPARATION = ("cutoff", "order", "differentiate", "decimate", "min_velocity", "outlier_k",
               "reference_tau")


@dataclass(eq=False)
class LogIdentification:
    """An identified torque model tau = Y_base(q, qd, qdd) theta (+ offsets): see :func:`identify_log`.

    ``theta``, ``std`` and ``relative_std`` (percent) follow ``names``: the base parameters
    (``expressions`` gives each as a combination of the standard ones), then the offsets.
    ``independent`` and ``beta`` are those of :class:`dynid.BaseParameters` for the model's
    regressor columns ``parameter_names``. ``training`` holds the training log's source, size,
    preparation (options and notes, in words) and per-joint fit metrics.
    """

    model: dict[str, Any]  #: the robot model (``dynid.model_files`` format): DH table etc.
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
    training: dict[str, Any] = field(default_factory=dict)
    log: Log | None = field(default=None, repr=False)  #: the prepared training log (not saved)
    _robot: Robot | None = field(default=None, repr=False)

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
        robot = self.robot
        total = robot.n * (10 + int(self.rotor) + 2 * int(self.friction))
        if total != len(self.parameter_names):
            raise ValueError(
                f"model: its regressor has {total} columns, the result expects "
                f"{len(self.parameter_names)}"
            )
        # Only the base columns, selected in C++ (no full (T, n, P) array).
        Y = robot.regressor(
            q, qd, qdd, rotor=self.rotor, friction=self.friction, columns=self.independent
        )
        if Y.ndim == 2:
            Y = Y[None]
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

    def save(self, folder: PathLike, log: Log | None = None, plots: bool = True) -> Path:
        """Write ``result.json`` and, when ``plots``, ``torques.png`` and ``residuals.png`` of the
        fit on ``log`` (default: the training log, when kept) into ``folder``; returns the JSON
        path."""
        from .result_files import save_result

        log = log if log is not None else self.log
        return save_result(self, folder, log if plots else None)


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
        raise ValueError(  # noqa: TRY004 -- SPEC 2: bad input raises ValueError
            f"log: expected a dynid.io.Log, got {type(log).__name__}"
        )
    if not isinstance(robot, Robot):
        raise ValueError(  # noqa: TRY004 -- SPEC 2: bad input raises ValueError
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
    # The regressor chunk by chunk into the triangular factors (dynid.streaming): memory bounded
    # by a chunk whatever the log's length; a second pass predicts the torques for the metrics.
    chunks = [slice(k, k + STREAM_CHUNK) for k in range(0, prepared.T, STREAM_CHUNK)]
    accumulator = LeastSquaresAccumulator(robot.n, len(names), exclude_joints=exclude_joints)
    for c in chunks:
        accumulator.add(result.regressor(prepared.q[c], prepared.qd[c], prepared.qdd[c]),
                        prepared.tau[c])
    fit = accumulator.solve(method=method, names=names)
    predicted = np.concatenate(
        [result.regressor(prepared.q[c], prepared.qd[c], prepared.qdd[c]) @ fit.theta
         for c in chunks]
    )
    result.theta, result.std, result.relative_std = fit.theta, fit.std, fit.relative_std
    result.condition_number, result.rank = fit.condition_number, fit.rank
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
        "metrics": error_metrics(prepared.tau, predicted),
    }
    return result


def validate_log(
    result: LogIdentification, log: Log, *, preparation: Mapping[str, Any] | None = None
) -> dict[str, NDArray[np.float64]]:
    """Per-joint errors of ``result`` on another log (``prepare_log(log, **preparation)``
    first): ``rms``, ``relative_rms`` (rms error / rms of the measured torque), ``max_abs``,
    ``r2`` and ``mse`` (see :func:`dynid.validation.error_metrics`)."""
    options = _options(preparation)
    prepared = prepare_log(log, **options) if options else log
    return error_metrics(prepared.tau, result.predict(prepared))


def load_result(path: PathLike) -> LogIdentification:
    """A result saved by :meth:`LogIdentification.save`: its folder or its ``result.json``."""
    from .result_files import load_result as _load

    return _load(path)


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
        raise ValueError(  # noqa: TRY004 -- SPEC 2: bad input raises ValueError
            f"log: expected a dynid.io.Log, got {type(log).__name__}"
        )
    if log.n != n:
        raise ValueError(f"log: has {log.n} joints, but the model {name!r} has {n}")
    if log.qd is None or log.qdd is None:
        log = prepare_log(log, differentiate="missing")
    return log
