"""Identification from a measurement log: the Python side of ``dynid identify`` and ``validate``.

A log (``dynid.logs``) and a robot model in, an identified torque model out (lecture, "Least
Squares (LS) identification" and "Additional remarks", Robotics 2 pp. 26-28):

1. the log is prepared (``dynid.prepare_log``: filtering, differentiation, decimation, sample
   removal; each step only when asked, each in ``log.notes``);
2. the regressor Y(q, qd, qdd) of every sample is computed in one batch call (C++), with the
   rotor (Ia) and symmetric friction (Fv, Fs) columns when asked, and reduced to the base
   parameters (``dynid.model.base_parameters``);
3. optionally the asymmetric friction columns are appended
(``dynid.identification.friction_models``: Fv+,
   Fv-, Fs+, Fs- per joint, in place of Fv, Fs); one constant column per joint: a torque offset
   (sensor bias; with Coulomb friction it also makes the friction asymmetric, Fs+ != Fs-); and,
   optionally, a
   position torque ks_j sin q_j + kc_j cos q_j per joint (``dynid.identification.position_torque``:
   a once-per-turn torque of the joint's sensor, gear or cables; only on the joints where it is
   structurally identifiable);
4. the stacked system is solved by OLS or WLS (``dynid.identification.streaming``: the regressor
chunk by
   chunk into triangular factors, the solver of ``dynid.identification.identify.least_squares``);
5. with ``physical=True``, the standard parameters are then estimated by the physically
   consistent semidefinite programme (``dynid.identification.physical.physical_least_squares``:
   same columns,
   same WLS weights, the asymmetric friction coefficients >= 0, the offsets and position
   torques unconstrained, optionally a prior model),
   and the result carries
   that robot (``result.robot``, saved with the result) and its base values as ``theta``.

The result predicts torques on any log (``predict``), is checked on another log
(:func:`validate_log`) and is saved to a folder by :func:`dynid.export.result_files.save_result`
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

from .._equality import ValueEquality
from ..logs import signal as sig
from ..logs.log_files import Log, load_log
from ..logs.preparation import prepare_log
from ..model.base_parameters import BaseParameters, base_parameters
from ..model.model_files import load_model, model_from_dict, model_to_dict
from ..model.robot import Robot
from .blocks.base import Block, Context
from .blocks.model import IdentificationModel, kept
from .blocks.offset import OFFSET_NAME as OFFSET_NAME  # its name here before the blocks
from .blocks.registry import build_blocks, friction_model
from .blocks.rigid_body import RigidBody
from .estimators.base import EstimatorFit, Problem
from .estimators.registry import LEAST_SQUARES, estimator, method_name
from .identify import VARIANCE_FLOOR, LeastSquaresResult, relative_std
from .physical import physical_least_squares
from .separable import estimate_nonlinear
from .serial_correlation import (
    WHITE_CORRELATION_TIME,
    WIDTH_PER_WINDOW,
    LongRunAccumulator,
    autocorrelation,
    correlation_note,
    correlation_window,
    scaled_inverse,
)
from .streaming import LeastSquaresAccumulator
from .validation import error_metrics, validation_table

PathLike = Union[str, Path]

#: prior_weight of ``identify_log(physical=True, prior=...)`` when none is given: on the LWR4+
#: logs (docs/real_data.md, "Physically consistent identification") the largest decade at which
#: the relative training residual of the physical fit rises by less than 10 % over the prior-free
#: fit; it pins the masses near the prior's while leaving the excited directions to the data.
DEFAULT_PRIOR_WEIGHT = 1e-5

#: Samples per regressor chunk folded into the least-squares factors.
STREAM_CHUNK = 8192
#: Largest training regressor (bytes) that :func:`identify_log` keeps between the least-squares
#: pass and the prediction of the training log, so that the log's regressor is computed once;
#: a longer log's regressor is computed again chunk by chunk (memory bounded by a chunk).
REGRESSOR_CACHE_BYTES = 1 << 29

#: The options of dynid.prepare_log that ``preparation`` may hold.
PREPARATION = (
    "rest_velocity",
    "cutoff",
    "order",
    "differentiate",
    "decimate",
    "min_velocity",
    "outlier_k",
    "reference_tau",
    "nonuniform",
    "trim_edges",
)


@dataclass(eq=False)
class LogIdentification(ValueEquality):
    """An identified torque model tau = Y_base(q, qd, qdd) theta (+ offsets): see
    :func:`identify_log`.

    ``theta``, ``std`` and ``relative_std`` (percent) follow ``names``: the base parameters
    (``expressions`` gives each as a combination of the standard ones), then the asymmetric
    friction coefficients, the offsets and the position torques, when asked for.
    ``independent`` and ``beta`` are those of :class:`dynid.BaseParameters` for the model's
    regressor columns ``parameter_names``. ``training`` holds the training log's source, size,
    preparation (options and notes, in words) and per-joint fit metrics.

    ``friction`` says whether the regressor's symmetric friction columns (Fv, Fs) are among the
    ``parameter_names``; ``asymmetric_friction`` whether the asymmetric ones
    (:mod:`dynid.identification.friction_models`) follow the base parameters instead;
    ``friction_model`` names the model ("none", "symmetric", "asymmetric", or a registered
    friction block's).

    ``blocks`` are the column blocks after the base parameters, in order
    (:mod:`dynid.identification.blocks`: asymmetric friction, offsets, position torque, ...);
    ``identification_model`` puts them behind the base columns, each with its slice of
    ``theta``. ``offset``, ``asymmetric_friction`` and ``position_joints`` are read from them.

    A physically consistent result (``identify_log(physical=True)``) has ``physical`` set (the
    solver's report: status, solver, times, prior, prior_weight, margin) and ``model`` holds the
    identified standard parameters and drive terms, so ``robot`` is the identified robot;
    ``theta`` holds its base values (beta @ pi) and the other coefficients; ``std`` is inf and
    ``covariance`` None (the constrained estimate has no least-squares covariance).
    """

    model: dict[str, Any]  #: the robot model (``dynid.model.model_files`` format): DH table etc.
    rotor: bool
    friction: bool
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
    physical: dict[str, Any] | None = None  #: the physically consistent fit's report, if any
    #: the column blocks after the base parameters (:mod:`dynid.identification.blocks`)
    blocks: tuple[Block, ...] = ()
    #: identified from motor currents (``dynid.identify_drive_gains``): the drive gains k
    #: ("gains", "gains_std", tau = k * current), the payload that fixed their scale and the
    #: runs; JSON-ready
    drive_gains: dict[str, Any] | None = None
    #: a registered estimator's report (``method`` not "ols"/"wls": its name, options and what
    #: it did, e.g. iterations or outliers; :mod:`dynid.identification.estimators`); JSON-ready
    estimator: dict[str, Any] | None = None
    #: the prepared training log, the first one of several (not saved, not compared)
    log: Log | None = field(default=None, repr=False, compare=False)
    #: (T, n) the torques predicted on ``log`` when identified (not saved, not compared)
    fitted: NDArray[np.float64] | None = field(default=None, repr=False, compare=False)
    #: every prepared training log, in the order given (not saved, not compared)
    logs: tuple[Log, ...] = field(default=(), repr=False, compare=False)
    #: the torques predicted on each of ``logs`` when identified (not saved, not compared)
    fitted_logs: tuple[NDArray[np.float64], ...] = field(default=(), repr=False, compare=False)
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
        """The robot model, rebuilt from ``model``. For a least-squares result its parameters are
        not the identified ones (these exist only as the base combinations ``theta``); for a
        physically consistent one (``physical`` set) it is the identified robot."""
        if self._robot is None:
            self._robot = model_from_dict(self.model)
        return self._robot

    @property
    def identification_model(self) -> IdentificationModel:
        """The base columns of ``robot``'s regressor, then ``blocks``: each block's columns and
        its slice of ``theta``."""
        rigid = RigidBody(self.robot, self.rotor, self.friction, self.independent)
        return IdentificationModel(rigid, tuple(self.blocks))

    def _block(self, key: str) -> Block | None:
        return next((b for b in self.blocks if b.key == key), None)

    @property
    def offset(self) -> bool:
        """Whether the model has one torque offset per joint (the ``offset`` block)."""
        return self._block("offset") is not None

    @property
    def asymmetric_friction(self) -> bool:
        """Whether the asymmetric friction columns (Fv+, Fv-, Fs+, Fs-; Fs with offsets) are in
        ``theta`` after the base parameters (then ``friction`` is False)."""
        return self._block("asymmetric_friction") is not None

    @property
    def position_joints(self) -> tuple[int, ...]:
        """Joints (0-based) with a position torque ks_j sin q_j + kc_j cos q_j."""
        block = self._block("position_torque")
        return tuple(getattr(block, "joints", ()))

    @property
    def friction_model(self) -> str:
        """The friction model: "none", "symmetric", "asymmetric" (:mod:`.friction_models`) or
        that of a registered friction block."""
        for block in self.blocks:
            if block.friction_model is not None:
                return block.friction_model
        return "symmetric" if self.friction else "none"

    @property
    def offsets(self) -> NDArray[np.float64]:
        """(n,) the identified torque offsets (zeros without ``offset``)."""
        where = self.identification_model.slice("offset")
        if where is None:
            return np.zeros(self.n)
        return np.asarray(self.theta[where], dtype=float)

    @property
    def position_torque(self) -> bool:
        """Whether the model has position-torque columns (on ``position_joints``)."""
        return bool(self.position_joints)

    def regressor(self, q: Any, qd: Any, qdd: Any) -> NDArray[np.float64]:
        """The (T, n, p) regressor of ``theta``: base columns, then the asymmetric friction
        columns, the offset columns and the position-torque columns (sin q_j, cos q_j of each of
        ``position_joints``), as many as the options ask for."""
        model = self.identification_model
        total = model.rigid.parameter_count
        if total != len(self.parameter_names):
            raise ValueError(
                f"model: its regressor has {total} columns, the result expects "
                f"{len(self.parameter_names)}"
            )
        return model.regressor(q, qd, qdd)

    def extra_columns(self, q: Any, qd: Any) -> NDArray[np.float64]:
        """(T, n, e) the columns of ``theta`` after the base parameters (asymmetric friction,
        offsets, position torque): functions of q and qd only, none of the robot's parameters."""
        return self.identification_model.extra_columns(q, qd)

    def extra_torque(self, q: Any, qd: Any) -> NDArray[np.float64]:
        """(T, n) the torque of the :meth:`extra_columns` (asymmetric friction, offsets,
        position torque): what the identified model adds to the rigid-body (+ rotor, symmetric
        friction) torque of its base parameters."""
        model = self.identification_model
        return model.extra_columns(q, qd) @ self.theta[model.rigid.size : model.size]

    def predict(self, log: Log) -> NDArray[np.float64]:
        """Predicted joint torques (T, n) on ``log`` (qd, qdd computed from q when absent).

        One batch regressor call in C++ for all samples, the base columns, then ``@ theta``.
        """
        log = _with_derivatives(log, self.n, self.model.get("name", ""))
        return self.regressor(log.q, log.qd, log.qdd) @ self.theta

    def summary(self) -> str:
        """Coefficients (value, std, relative std, expression), condition number and rank, and
        the per-joint fit on the training log, as text."""
        options = ", ".join(
            [k for k in ("rotor", "friction") if getattr(self, k)]
            + [block.key.replace("_", " ") for block in self.blocks]
        )
        offsets = "".join(f" + {block.describe()}" for block in self.blocks)
        columns = "rigid body" + (f", {options}" if options else "")
        model = (
            f"model: {self.model.get('name') or '?'} ({self.n} joints, "
            f"{self.model['convention']} DH); columns: {columns}"
        )
        fit = (
            f"{self.count} base parameters{offsets}, {self.method.upper()}, rank "
            f"{self.rank}/{self.theta.size}, condition number {self.condition_number:.4g}"
        )
        head = [model, fit]
        if self.drive_gains is not None:  # identified from motor currents
            gains = ", ".join(f"{k:.6g}" for k in self.drive_gains.get("gains", []))
            head.append(f"drive gains k (tau = k * current): {gains}")
        if self.physical is not None:
            report = self.physical
            prior = (
                f"prior {report.get('prior')} (weight {report.get('prior_weight'):g})"
                if report.get("prior")
                else "no prior"
            )
            head.append(
                f"physically consistent fit: SDP, {report.get('solver')} status "
                f"{report.get('status')}, {prior}; the values are the base parameters of "
                "the identified robot (no standard deviations)"
            )
        width = max(11, *(len(name) for name in self.names))
        title = (
            f"  {'coefficient':<{width}}  {'value':>12}  {'std':>10}  {'rel.std':>8}  expression"
        )
        lines = [title]
        for name, value, std, rel, expr in zip(
            self.names, self.theta, self.std, self.relative_std, self.expressions
        ):
            # No standard deviation (a physical fit: inf) is a dash, not "inf inf%".
            spread = f"{std:>10.3g}  {rel:>7.3g}%" if np.isfinite(std) else f"{'-':>10}  {'-':>8}"
            lines.append(f"  {name:<{width}}  {value:>12.5g}  {spread}  {expr}")
        text = "\n".join(head + lines)
        metrics = self.training.get("metrics")
        runs = self.training.get("logs") or []
        if metrics:
            arrays = {k: np.asarray(v, dtype=float) for k, v in metrics.items()}
            what = f"the {len(runs)} training logs" if runs else "the training log"
            text += f"\nfit on {what} ({self.training.get('samples')} samples):\n"
            text += validation_table(arrays)
        for k, run in enumerate(runs, start=1):  # several logs: each one's own fit
            arrays = {m: np.asarray(v, dtype=float) for m, v in run.get("metrics", {}).items()}
            text += f"\nfit on log {k}, {run.get('source')} ({run.get('samples')} samples):\n"
            text += validation_table(arrays)
        return text


def unfitted(
    robot: Robot, base: BaseParameters, blocks: Sequence[Block], *, rotor: bool, method: str
) -> LogIdentification:
    """The result before the fit (identify_log, identify_drive_gains): the torque model's
    structure -- ``base`` (:func:`dynid.base_parameters` of ``robot``), then ``blocks`` -- its
    coefficients' names and expressions, and zeros where the fit writes."""
    names, expressions = list(base.names), list(base.expressions)
    for block in blocks:
        names += block.names()
        expressions += block.expressions()
    return LogIdentification(
        # Without the parameters and drive terms: their values were a prior, no part of the
        # identified model.
        model=model_to_dict(robot, identified=False),
        rotor=rotor,
        friction=base.friction,
        method=method,
        parameter_names=list(base.parameter_names),
        independent=base.independent.copy(),
        beta=base.beta.copy(),
        names=names,
        expressions=expressions,
        theta=np.zeros(len(names)),
        std=np.zeros(len(names)),
        relative_std=np.zeros(len(names)),
        condition_number=np.nan,
        rank=0,
        blocks=tuple(blocks),
        _robot=robot,
    )


def identify_log(
    log: Log | PathLike | Sequence[Log | PathLike],
    robot: Robot,
    *,
    rotor: bool = False,
    friction: bool | str = False,
    offset: bool = False,
    method: str = "wls",
    exclude_joints: Sequence[int] = (),
    preparation: Mapping[str, Any] | None = None,
    physical: bool = False,
    prior: Robot | PathLike | None = None,
    prior_weight: float | None = None,
    position_torque: bool = False,
    estimator_options: Mapping[str, Any] | None = None,
) -> LogIdentification:
    """Identify the base parameters of ``robot`` (its DH table, joint types, gravity) on ``log``.

    ``log`` is a :class:`dynid.Log`, the path of a log file (``dynid.load_log`` with its
    defaults) or a list of them: several runs of the same arm, each prepared separately (no
    filter runs across two logs), their regressor rows stacked in one least-squares problem
    (chunk by chunk, :mod:`dynid.identification.streaming`), so the WLS weights come from the
    residuals of all logs together. ``training["metrics"]`` is then the fit on all samples and
    ``training["logs"]`` holds each log's source, size, notes and metrics (absent for one log).

    ``preparation``: options of :func:`dynid.prepare_log` (cutoff, order, differentiate,
    decimate, outlier_k, nonuniform, trim_edges) applied first; qd and qdd are computed from q
    when the log lacks them. ``min_velocity`` (scalar or per joint) leaves out the rows of joint
    j where |qd_j| < min_velocity, not whole samples (joint j's friction is only in its own
    rows), and the training errors are computed on the rows kept. ``rotor`` adds the Ia
    columns; ``friction`` the friction model: False ("none"), True or "symmetric" (Fv qd +
    Fs sign(qd)), or "asymmetric" (Fv+, Fv-, Fs+, Fs- per joint, a coefficient per direction
    of motion; with ``offset`` Fv+, Fv-, Fs, the offset carrying the
    Coulomb asymmetry: :mod:`dynid.identification.friction_models`), or "stribeck" (smooth
    Stribeck friction per drive and direction, whose velocity scales are estimated first by
    separable least squares and then held fixed: :mod:`dynid.identification.blocks.stribeck`,
    :mod:`dynid.identification.separable`). ``offset`` adds one constant
    torque per joint. ``position_torque`` adds ks_j sin q_j + kc_j cos q_j on every joint where
    these two columns are structurally identifiable next to the others
    (:func:`dynid.identification.position_torque.position_torque_joints`; the joints left out are
    named in
    ``training["notes"]``): a joint-side torque that depends on the joint's own position (torque
    sensor or gear ripple once per turn, cable or spring stiffness; docs/identification.md).
    ``method`` is "ols" or "wls" (weighted by each joint's noise level, the
    default: the joints' torques differ by two orders of magnitude) or a registered estimator
    (:mod:`dynid.identification.estimators`, :func:`~dynid.identification.estimators.methods`;
    docs/identification.md, "Estimators"), which starts from the WLS fit and takes its own
    ``estimator_options`` (its report is ``result.estimator``). ``exclude_joints`` (0-based)
    leaves those joints' rows out of the fit. Raises ValueError (RankDeficientError) when the log
    does not excite every base parameter. OLS and WLS standard deviations account for the
    residuals' correlation in time when there is any (a filtered log, a model error; Newey-West,
    :mod:`dynid.identification.serial_correlation`; a training note says so).

    ``physical=True`` estimates physically consistent standard parameters instead
    (:func:`dynid.physical_least_squares`, same columns; WLS weights 1/sigma_j from the
    least-squares residuals; the asymmetric friction coefficients >= 0, the offsets and
    position torques unconstrained; excluded joints weighted 0). ``prior`` is a
    Robot, a URDF file or a model file (``dynid.load_model``: JSON/YAML or a built-in name) of
    the same arm, in any DH table (re-expressed in ``robot``'s frames by
    :func:`dynid.model.link_frames.express_in_frames_of` when needed); ``prior_weight`` defaults to
    ``DEFAULT_PRIOR_WEIGHT`` when a prior is given. A log that does not excite every base
    parameter is then a RuntimeWarning, not an error: the constraints and the prior fix the
    unexcited directions (without a prior, any values the constraints allow), which the physical
    fit's UserWarning says too (its extra columns named ``extra[k]``). Raises
    :class:`dynid.PhysicalIdentificationError` when the solver fails.
    """
    logs = _training_logs(log)
    if not isinstance(robot, Robot):
        raise ValueError(f"robot: expected a dynid.Robot, got {type(robot).__name__}")
    if not isinstance(physical, (bool, np.bool_)):
        raise ValueError(f"physical: expected True or False, got {physical!r}")
    kind = friction_model(friction)
    symmetric = kind == "symmetric"
    if not isinstance(position_torque, (bool, np.bool_)):
        raise ValueError(f"position_torque: expected True or False, got {position_torque!r}")
    if not physical and (prior is not None or prior_weight is not None):
        raise ValueError("prior: a prior (and prior_weight) needs physical=True")
    prior_robot = _prior_model(prior) if prior is not None else None
    if prior_robot is not None and prior_weight is None:
        prior_weight = DEFAULT_PRIOR_WEIGHT
    options = _options(preparation)
    method = method_name(method)
    estimator_options = _estimator_options(method, estimator_options)
    if physical and method not in LEAST_SQUARES and estimator(method).no_physical:
        raise ValueError(f"physical: not with method {method!r}: {estimator(method).no_physical}")
    context = Context(robot, bool(rotor), kind, bool(offset), bool(position_torque))
    built = build_blocks(context)  # in column order (dynid.identification.blocks.registry)
    block_notes = [note for block in built for note in block.notes()]
    blocks = kept(built)
    # Each log prepared on its own: filters and derivatives never run across two recordings;
    # min_velocity leaves out rows per joint and per log (_moving_rows), not whole samples.
    runs = [
        _with_derivatives(prepare_log(one, **_sample_options(options)), robot.n, robot.name)
        for one in logs
    ]
    prepared = runs[0]
    masks = [_moving_rows(_signals(run)[1], options.get("min_velocity")) for run in runs]
    row_masks = [mask for mask, _ in masks]
    rows_note = masks[0][1]
    base = base_parameters(robot, "torque", rotor=bool(rotor), friction=symmetric)
    # A block's nonlinear parameters (the Stribeck friction's velocity scales) are estimated
    # first, by separable least squares, and held fixed from here on (physical fit included).
    rigid = RigidBody(robot, bool(rotor), symmetric, base.independent)
    separable = estimate_nonlinear(
        rigid, blocks, runs, row_masks, method=method, exclude_joints=exclude_joints
    )
    blocks, block_notes = separable.blocks, block_notes + list(separable.notes)
    result = unfitted(robot, base, blocks, rotor=bool(rotor), method=method)
    result.log = prepared
    names = result.names
    model = result.identification_model
    # The logs' regressor is computed once (C++ batch calls). Least squares: chunk by chunk,
    # log after log, into the triangular factors (dynid.identification.streaming: the rows of
    # all logs stacked, never the whole matrix), the chunks kept for the prediction below when
    # they fit in REGRESSOR_CACHE_BYTES (otherwise computed again, the memory bounded by a
    # chunk). Physical: the standard columns of all logs, which the SDP needs anyway; the base
    # columns are a selection of them.
    chunks = [
        (r, slice(k, k + STREAM_CHUNK))
        for r, run in enumerate(runs)
        for k in range(0, run.T, STREAM_CHUNK)
    ]
    total = sum(run.T for run in runs)
    starts = np.cumsum([0] + [run.T for run in runs])
    standard: NDArray[np.float64] | None = None
    if physical:
        standard = np.concatenate(
            [
                _masked(
                    np.concatenate(
                        [
                            model.rigid.standard_columns(*_signals(run)),
                            model.extra_columns(*_signals(run)[:2]),
                        ],
                        axis=2,
                    ),
                    rows,
                )
                for run, rows in zip(runs, row_masks)
            ]
        )
        selected = np.concatenate(
            [base.independent, np.arange(len(base.parameter_names), standard.shape[2])]
        )

    def chunk_regressor(r: int, c: slice) -> NDArray[np.float64]:
        run = runs[r]
        if standard is not None:
            span = slice(starts[r] + c.start, starts[r] + min(c.stop, run.T))
            return standard[span][..., selected]
        q, qd, qdd = _signals(run)
        if separable.rigid_columns is not None:  # the base columns, computed once already
            rigid_columns = separable.rigid_columns[r][c]
            return np.concatenate([rigid_columns, model.extra_columns(q[c], qd[c])], axis=2)
        return model.regressor(q[c], qd[c], qdd[c])

    cache: dict[int, NDArray[np.float64]] = {}
    keep = standard is None and total * robot.n * len(names) * 8 <= REGRESSOR_CACHE_BYTES
    accumulator = LeastSquaresAccumulator(robot.n, len(names), exclude_joints=exclude_joints)
    for i, (r, c) in enumerate(chunks):
        Y = chunk_regressor(r, c)
        if keep:
            cache[i] = Y
        rows = row_masks[r]
        accumulator.add(Y, runs[r].tau[c], None if rows is None else rows[c])
    # The physical fit needs the least squares only for the rank, the condition number and the
    # WLS weights: directions the data do not excite are then fixed by the constraints and the
    # prior, so rank deficiency is a warning there instead of an error.
    fit = accumulator.solve(
        method=method if method in LEAST_SQUARES else "wls",
        names=names,
        on_rank_deficient="warn" if physical else "raise",
    )
    fit = separable.widen(fit)  # the nonlinear parameters' uncertainty in the coefficients'
    row_weights = None
    if method not in LEAST_SQUARES:  # a registered estimator, from the WLS fit
        Y_all = np.concatenate(
            [cache[i] if i in cache else chunk_regressor(r, c) for i, (r, c) in enumerate(chunks)]
        )
        outcome = _estimate(method, estimator_options, Y_all, runs, row_masks, starts, fit, result)
        del Y_all
        fit, row_weights = outcome.result, outcome.row_weights
        result.estimator = {"method": method, "options": dict(estimator_options), **outcome.report}
        block_notes += list(outcome.notes)
    result.theta, result.std, result.relative_std = fit.theta, fit.std, fit.relative_std
    result.condition_number, result.rank = fit.condition_number, fit.rank
    result.covariance = fit.covariance
    result.excluded = fit.excluded
    if standard is not None:
        tau = np.concatenate(
            [
                run.tau if rows is None else np.where(rows, run.tau, 0.0)
                for run, rows in zip(runs, row_masks)
            ]
        )
        _physical(
            result,
            standard,
            tau,
            fit.noise_variance,
            prior_robot,
            prior_weight or 0.0,
            prior,
            row_weights,
        )
    fitted = np.concatenate(
        [
            (cache[i] if i in cache else chunk_regressor(r, c)) @ result.theta
            for i, (r, c) in enumerate(chunks)
        ]
    )
    result.fitted_logs = tuple(fitted[starts[r] : starts[r + 1]] for r in range(len(runs)))
    result.fitted, result.logs = result.fitted_logs[0], tuple(runs)
    if method in LEAST_SQUARES and standard is None:
        # Filtered logs (and model errors) correlate the residuals of neighbouring samples: the
        # independent-samples standard deviations would be too small (serial_correlation.py).
        block_notes += _correlation_robust_std(
            result,
            fit,
            [run.tau for run in runs],
            row_masks,
            starts,
            [(r, c, cache.get(i)) for i, (r, c) in enumerate(chunks)],
            chunk_regressor,
            fitted,
            separable.added,
        )
    plain = {k: _plain(v) for k, v in options.items()}
    if len(runs) == 1:
        result.training = {
            "source": prepared.source,
            "format": prepared.format,
            "samples": prepared.T,
            "duration_s": prepared.duration,
            "sampling_rate_hz": prepared.fs,
            "preparation": plain,
            "notes": list(prepared.notes) + rows_note + block_notes,
            "metrics": _kept_row_metrics(prepared.tau, result.fitted, row_masks[0]),
        }
        return result
    # Several logs: the fit on all rows together, then each log's own (its errors against its
    # own torques, so a log the model fits worse than the others shows).
    result.training = {
        "source": [run.source for run in runs],
        "format": [run.format for run in runs],
        "samples": total,
        "duration_s": sum(run.duration for run in runs),
        "preparation": plain,
        "notes": block_notes,
        "metrics": _kept_row_metrics(
            np.concatenate([run.tau for run in runs]),
            fitted,
            None
            if row_masks[0] is None
            else np.concatenate([m for m in row_masks if m is not None]),
        ),
        "logs": [
            {
                "source": run.source,
                "format": run.format,
                "samples": run.T,
                "duration_s": run.duration,
                "sampling_rate_hz": run.fs,
                "notes": list(run.notes) + note,
                "metrics": _kept_row_metrics(run.tau, part, rows),
            }
            for run, part, (rows, note) in zip(runs, result.fitted_logs, masks)
        ],
    }
    return result


def _correlation_robust_std(
    result: LogIdentification,
    fit: LeastSquaresResult,
    torques: Sequence[NDArray[np.float64]],
    row_masks: Sequence[NDArray[np.bool_] | None],
    starts: NDArray[np.int64],
    chunks: Sequence[tuple[int, slice, NDArray[np.float64] | None]],
    regressor: Any,
    fitted: NDArray[np.float64],
    added: NDArray[np.float64] | None = None,
) -> list[str]:
    """Replace the least-squares standard deviations in ``result`` by those of the residuals'
    correlation in time (the sandwich A^-1 Omega A^-1 of dynid.identification.
    serial_correlation, Omega by the Bartlett kernel of the width the residuals show) when the
    residuals are correlated (width > 1); the note that says so, or none. ``chunks``: (log,
    samples, its regressor or None to compute it with ``regressor(log, samples)``). ``added``:
    the covariance a block's nonlinear parameters add (dynid.identification.separable: the
    Stribeck velocity scales' uncertainty, from their own fit), kept on top of the sandwich."""
    covariance = fit.covariance
    if covariance is None or not np.all(np.isfinite(covariance)) or fit.rank < result.theta.size:
        return []
    n, p = result.n, result.theta.size
    weights = np.zeros(n)  # the fit's: 1 (OLS) or 1 / sigma_j^2 (WLS, floored as solve_factors)
    variance = np.asarray(fit.noise_variance, dtype=float)
    kept = list(fit.joints)
    if result.method == "wls" and variance.size and np.all(np.isfinite(variance)):
        largest = variance.max()
        floored = (
            np.maximum(variance, VARIANCE_FLOOR * largest)
            if largest > 0
            else np.ones_like(variance)
        )
        weights[kept] = 1.0 / floored
    else:
        weights[kept] = 1.0
    residuals = []
    for r, tau in enumerate(torques):
        part = (tau - fitted[starts[r] : starts[r + 1]]) * np.sqrt(weights)
        rows = row_masks[r]
        residuals.append(part if rows is None else np.where(rows, part, 0.0))
    window = correlation_window(residuals)
    correlation_time = 1.0 + 2.0 * float(autocorrelation(residuals, window)[1:].sum())
    if correlation_time < WHITE_CORRELATION_TIME:  # independent samples: the white covariance
        return []
    width = WIDTH_PER_WINDOW * window

    def weighted(r: int, c: slice, cached: NDArray[np.float64] | None) -> tuple[NDArray, NDArray]:
        # A chunk's rows (the left-out ones zero) and their weighted copy; computed again in the
        # second pass when not cached, so that memory stays one chunk, as in the fit.
        Y = cached if cached is not None else regressor(r, c)
        rows = row_masks[r]
        if rows is not None:
            Y = np.where(rows[c][:, :, None], Y, 0.0)
        return Y, Y * weights[None, :, None]

    A = np.zeros((p, p))
    for r, c, cached in chunks:
        Y, WY = weighted(r, c, cached)
        A += np.einsum("tjp,tjq->pq", WY, Y)
    inverse = scaled_inverse(A)
    accumulator = LongRunAccumulator(p, width)
    current = 0
    for r, c, cached in chunks:
        Y, WY = weighted(r, c, cached)
        if r != current:
            accumulator.end_segment()
            current = r
        residual = torques[r][c] - fitted[starts[r] + c.start : starts[r] + c.start + Y.shape[0]]
        rows = row_masks[r]
        if rows is not None:
            residual = np.where(rows[c], residual, 0.0)
        accumulator.add(np.einsum("tjp,tj->tp", WY, residual) @ inverse.T)
    accumulator.end_segment()
    robust = accumulator.omega if added is None else accumulator.omega + added
    std = np.sqrt(np.maximum(np.diag(robust), 0.0))
    ratio = std / np.where(result.std > 0, result.std, np.inf)
    result.covariance, result.std = robust, std
    result.relative_std = relative_std(result.theta, std)
    return [correlation_note(correlation_time, width, ratio)]


def _estimator_options(method: str, options: Mapping[str, Any] | None) -> dict[str, Any]:
    """``estimator_options`` checked: a mapping of the options the estimator ``method`` takes
    (none for "ols" and "wls")."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise ValueError(
            f"estimator_options: expected a mapping of option names to values, "
            f"got {type(options).__name__}"
        )
    known = () if method in LEAST_SQUARES else estimator(method).options
    unknown = [k for k in options if k not in known]
    if unknown:
        takes = ", ".join(known) if known else "no options"
        raise ValueError(
            f"estimator_options: {', '.join(map(repr, unknown))} not an option of method "
            f"{method!r} (it takes {takes})"
        )
    return dict(options)


def _estimate(
    method: str,
    options: Mapping[str, Any],
    Y: NDArray[np.float64],
    runs: Sequence[Log],
    row_masks: Sequence[NDArray[np.bool_] | None],
    starts: NDArray[np.int64],
    start: LeastSquaresResult,
    result: LogIdentification,
) -> EstimatorFit:
    """The registered estimator ``method`` on the stacked problem (rows left out zeroed)."""
    keep = np.concatenate(
        [
            np.ones(run.tau.shape, dtype=bool) if rows is None else rows
            for run, rows in zip(runs, row_masks)
        ]
    )
    tau = np.where(keep, np.concatenate([run.tau for run in runs]), 0.0)
    problem = Problem(
        Y=np.where(keep[:, :, None], Y, 0.0),
        tau=tau,
        keep=keep,
        excluded=tuple(start.excluded),
        names=list(result.names),
        runs=tuple(runs),
        starts=np.asarray(starts, dtype=np.int64),
        robot=result.robot,
        model=result.identification_model,
        start=start,
        options=options,
    )
    outcome = estimator(method).function(problem)
    if outcome.result.theta.shape != (problem.p,):
        raise RuntimeError(f"estimator {method!r} returned {outcome.result.theta.shape} values")
    return outcome


def _masked(standard: NDArray[np.float64], rows: NDArray[np.bool_] | None) -> NDArray[np.float64]:
    """The rows left out by min_velocity set to zero: a zero row adds nothing to the
    least-squares objective."""
    return standard if rows is None else np.where(rows[:, :, None], standard, 0.0)


def _signals(log: Log) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """q, qd, qdd of a log that has them (after ``_with_derivatives``)."""
    assert log.qd is not None and log.qdd is not None  # _with_derivatives computed them
    return log.q, log.qd, log.qdd


def _training_logs(log: Any) -> list[Log]:
    """``identify_log``'s ``log``: one Log or path, or a non-empty list of them, as Logs (paths
    read by ``dynid.load_log`` with its defaults)."""
    items = list(log) if isinstance(log, (list, tuple)) else [log]
    if not items:
        raise ValueError("log: expected a dynid.Log, a log file or a list of them, got none")
    logs = []
    for k, item in enumerate(items):
        where = "log" if len(items) == 1 and not isinstance(log, (list, tuple)) else f"log[{k}]"
        if isinstance(item, Log):
            logs.append(item)
        elif isinstance(item, (str, Path)):
            logs.append(load_log(item))
        else:
            raise ValueError(
                f"{where}: expected a dynid.Log or the path of a log file, "
                f"got {type(item).__name__}"
            )
    return logs


def _physical(
    result: LogIdentification,
    Y: NDArray[np.float64],
    tau: NDArray[np.float64],
    noise_variance: NDArray[np.float64],
    prior: Robot | None,
    prior_weight: float,
    source: Any,
    row_weights: NDArray[np.float64] | None = None,
) -> None:
    """Replace the least-squares estimate in ``result`` by the physically consistent one; ``Y``
    (T, n, P + e) is the standard regressor of the training logs followed by the blocks'
    columns, ``tau`` (T, n) their torques (the rows left out are zero in both)."""
    robot, n = result.robot, result.n
    model = result.identification_model
    # Each block says which of its coefficients are >= 0 (friction dissipates, as Fv, Fs >= 0).
    nonnegative = model.nonnegative_extra()
    weights = np.ones(n)
    kept = [j for j in range(n) if j not in result.excluded]
    usable = np.all(np.isfinite(noise_variance)) and noise_variance.max() > 0
    if result.method != "ols" and usable:  # as dynid.least_squares: 1 / sigma_j
        floored = np.maximum(noise_variance, VARIANCE_FLOOR * noise_variance.max())
        weights[kept] = 1.0 / np.sqrt(floored)
    weights[list(result.excluded)] = 0.0
    # An estimator's own row weights (e.g. IRLS's robust weights) times the joints' 1/sigma_j:
    # the physically consistent fit of the same method.
    row_weighted = weights if row_weights is None else row_weights * weights
    fit = physical_least_squares(
        robot,
        Y,
        tau,
        rotor=result.rotor,
        friction=result.friction,
        weights=row_weighted,
        prior=prior,
        prior_weight=prior_weight,
        extra_columns=model.extra_size,
        nonnegative_extra=nonnegative,
    )
    result.theta = np.concatenate([fit.base_values, fit.extra])
    result.std = np.full(result.theta.size, np.inf)
    result.relative_std = np.full(result.theta.size, np.inf)
    result.covariance = None
    result.model = model_to_dict(fit.robot)
    result._robot = fit.robot
    result.physical = {
        "status": fit.status,
        "solver": fit.solver,
        "solve_time_s": fit.solve_time if np.isfinite(fit.solve_time) else None,
        "setup_time_s": fit.setup_time,
        "objective": fit.objective,
        "prior": None
        if source is None
        else (str(source) if not isinstance(source, Robot) else f"<Robot {source.name}>"),
        "prior_weight": prior_weight,
        "margin": fit.options["margin"],
        "projected_links": [i + 1 for i in fit.projected],
        "min_pseudo_inertia_eigenvalues": fit.min_eigenvalues.tolist(),
    }


def _prior_model(prior: Any) -> Robot:
    """The prior: a Robot, or what ``dynid.load_model`` reads (a model file, a URDF, a built-in
    name)."""
    if isinstance(prior, Robot):
        return prior
    if not isinstance(prior, (str, Path)):
        raise ValueError(
            f"prior: expected a dynid.Robot or the path of a model file or URDF, "
            f"got {type(prior).__name__}"
        )
    return load_model(prior)


@dataclass(eq=False)
class LogValidation(ValueEquality):
    """An identified model applied to another log: the prepared log, the predicted torques and
    the per-joint errors (:func:`dynid.identification.validation.error_metrics`)."""

    log: Log  #: the validation log after ``preparation``
    predicted: NDArray[np.float64]
    metrics: dict[str, NDArray[np.float64]]
    preparation: dict[str, Any]
    notes: list[str] = field(default_factory=list)  #: differences from the training preparation


def run_validation(
    result: LogIdentification, log: Log, *, preparation: Mapping[str, Any] | None = None
) -> LogValidation:
    """Prepare ``log`` (``prepare_log(log, **preparation)``), predict its torques with ``result``
    and measure the errors (with ``min_velocity``: on the rows of joint j where |qd_j| >=
    min_velocity, as :func:`identify_log` fits); ``notes`` says which rows were left out and
    where the preparation differs from the training log's (a low-pass on one and not the other
    biases the comparison)."""
    options = _options(preparation)
    sample_options = _sample_options(options)
    prepared = prepare_log(log, **sample_options) if sample_options else log
    predicted = result.predict(prepared)
    qd = prepared.qd if prepared.qd is not None else _with_derivatives(prepared, result.n, "").qd
    rows, rows_note = _moving_rows(qd, options.get("min_velocity"))
    notes = list(rows_note)
    trained = result.training.get("preparation", {}).get("cutoff")
    if trained != options.get("cutoff"):
        notes.append(
            f"the training log was {_filtered(trained)}, this one is "
            f"{_filtered(options.get('cutoff'))}"
        )
    return LogValidation(
        prepared, predicted, _kept_row_metrics(prepared.tau, predicted, rows), options, notes
    )


def validate_log(
    result: LogIdentification, log: Log, *, preparation: Mapping[str, Any] | None = None
) -> dict[str, NDArray[np.float64]]:
    """Per-joint errors of ``result`` on another log (``prepare_log(log, **preparation)``
    first): ``rms``, ``relative_rms`` (rms error / rms of the measured torque), ``max_abs``,
    ``r2`` and ``mse`` (see :func:`dynid.identification.validation.error_metrics`)."""
    return run_validation(result, log, preparation=preparation).metrics


def _sample_options(options: dict[str, Any]) -> dict[str, Any]:
    """The prepare_log options without min_velocity: identify and validate leave out rows of
    the stacked system per joint (:func:`_moving_rows`), not whole samples."""
    return {k: v for k, v in options.items() if k != "min_velocity"}


def _moving_rows(
    qd: NDArray[np.float64] | None, min_velocity: Any
) -> tuple[NDArray[np.bool_] | None, list[str]]:
    """(T, n) the rows of joint j kept by ``min_velocity`` (|qd_j| >= v_j), and a note; (None,
    []) without it. Lecture, "further practical hints": data near zero velocity are discarded
    because sign(qd) in Fs sign(qd) is ill-defined there; joint j's friction appears only in
    joint j's rows, so a slow joint 3 says nothing against joint 1's rows of the same sample."""
    if min_velocity is None:
        return None, []
    assert qd is not None  # identify and validate always have qd (given or differentiated)
    keep = sig.moving_mask_min_velocity(qd, min_velocity, per_joint=True)
    left = ", ".join(f"{int((~keep[:, j]).sum())}" for j in range(keep.shape[1]))
    if not keep.any(axis=0).all():
        idle = [j + 1 for j in range(keep.shape[1]) if not keep[:, j].any()]
        raise ValueError(
            f"min_velocity: no row of joint(s) {idle} has |qd| >= "
            f"{np.round(np.asarray(min_velocity), 6)}"
        )
    note = (
        f"left out the rows of joint j where |qd_j| < {np.round(np.asarray(min_velocity), 6)} "
        f"(friction sign ill-defined near zero velocity): {left} of {keep.shape[0]} rows per "
        "joint; the errors are on the rows kept"
    )
    return keep, [note]


def _kept_row_metrics(
    measured: NDArray[np.float64], predicted: NDArray[np.float64], keep: NDArray[np.bool_] | None
) -> dict[str, NDArray[np.float64]]:
    """:func:`error_metrics` per joint on the rows kept (all without ``keep``)."""
    if keep is None:
        return error_metrics(measured, predicted)
    per_joint = [
        error_metrics(measured[keep[:, j], j : j + 1], predicted[keep[:, j], j : j + 1])
        for j in range(measured.shape[1])
    ]
    return {k: np.concatenate([m[k] for m in per_joint]) for k in per_joint[0]}


def _filtered(cutoff: float | None) -> str:
    return "not low-passed" if cutoff is None else f"low-passed at {cutoff:g} Hz"


def _options(preparation: Mapping[str, Any] | None) -> dict[str, Any]:
    """The prepare_log options given (None values left out), checked by name."""
    options = {k: v for k, v in dict(preparation or {}).items() if v is not None}
    unknown = sorted(set(options) - set(PREPARATION))
    if unknown:
        raise ValueError(
            f"preparation: unknown option(s) {unknown}; expected some of "
            f"{', '.join(PREPARATION)} (dynid.prepare_log)"
        )
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
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    if log.n != n:
        raise ValueError(f"log: has {log.n} joints, but the model {name!r} has {n}")
    if log.qd is None or log.qdd is None:
        log = prepare_log(log, differentiate="missing")
    return log
