"""Drive gains from motor currents: identify k and the base parameters together (Gautier & Briot).

Many controllers log the motor currents i, not joint torques: tau_j = k_j i_j, with k_j the drive
gain of joint j (motor torque constant times gear ratio, N m/A). The model Y theta = diag(i) k is
then homogeneous: (s theta, s k) fits the data as well as (theta, k) for every s, so a run of the
arm alone cannot fix the scale. Something of known mass can (Gautier & Briot, "Global
identification of joint drive gains and dynamic parameters of robots", ASME J. Dyn. Syst. Meas.
Control 136(5), 2014; FIGAROH's ``build_total_regressor``): a run with a payload of known inertial
parameters pi_L on the last link, whose torques are those of the arm plus Y_n pi_L (the rule of
change, notes p. 33, :mod:`dynid.identification.payload`: Y_n the last link's 10 standard regressor
columns):

    unloaded runs:  Y_u theta - diag(i_u) k = 0
    loaded runs:    Y_l theta - diag(i_l) k = -Y_l,n pi_L

with theta the base parameters (``dynid.model.base_parameters``, rotor/friction columns and torque
offsets as in :func:`dynid.identify_log`). With the payload's mass m_L only, its other nine
parameters are unknowns of the loaded rows (those the structure can tell apart; notes p. 33) and
-Y_l,n[:, m] m_L is the right-hand side.

Three solvers, all on the triangular factors of the stacked [A | b] (chunk by chunk,
``dynid.identification._qr``: memory bounded whatever the logs' length):

- ``"nls"`` (default): nonlinear least squares on the currents. Joint j's equation divided by
  k_j reads i_j = (Y_j theta - d_j) / k_j: the measured current is the output, so white current
  noise is the residual and the weighted fit (weights 1/s_j, the current noise of joint j from
  the residuals) is maximum likelihood, consistent, with the Gauss-Newton covariance as its
  standard deviations. Started from the WLS solution (then from TLS's if that fails); each
  joint's term ||A_j x - b_j||^2 / (s_j k_j)^2 = ||R_j [x; -1]||^2 / (s_j k_j)^2 needs only R_j.
- ``"tls"``: total least squares as in Gautier & Briot and FIGAROH: x = -v[:-1] / v[-1], v the
  right singular vector of the smallest singular value of [A | b] (rows unweighted as in FIGAROH,
  columns scaled to unit norm so that the units do not matter). It copes with the noise in the
  gain columns -diag(i) far better than least squares, but assumes equal noise in every column
  where only the current columns have any, so it keeps a bias of about one standard deviation
  at 2 % current noise and breaks down at 5 % (gains of the wrong sign; docs/drive_gains.md);
  the standard deviations are first order (those of an unweighted fit with each joint's noise).
- ``"wls"`` / ``"ols"``: least squares on the inhomogeneous system (``dynid.least_squares``,
  its rank check and standard deviations). The current noise sits in the gain columns, and
  shrinking the common scale of (theta, k) shrinks that noise's share of the residual, which
  only the payload's rows resist: with 2 % current noise on the LWR the gains come out several
  standard deviations low. For comparison, and exact on noise-free data.

The rank of A is checked by least squares first (:class:`dynid.RankDeficientError` naming the
unexcited unknowns), whatever the method.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._equality import ValueEquality
from ..logs.log_files import Log
from ..logs.preparation import prepare_log
from ..model.base_parameters import base_parameters
from ..model.robot import Robot
from ._qr import GroupedTriangularFactors
from .blocks.base import Context
from .blocks.drive_gains import DriveGains
from .blocks.model import kept
from .blocks.registry import build_blocks, friction_model
from .drive_gain_system import (
    PAYLOAD,
    TORQUE,
    CurrentModel,
    current_least_squares,
    payload_vector,
    total_least_squares,
    visible_payload,
)
from .gain_consistency import BLOCKS, block_edges, jackknife_std, overconfidence
from .identify import RankDeficientError, relative_std, solve_factors
from .log_identification import (
    STREAM_CHUNK,
    LogIdentification,
    _options,
    _plain,
    _with_derivatives,
    unfitted,
)
from .payload import PAYLOAD_NAMES
from .validation import error_metrics

METHODS = ("nls", "tls", "wls", "ols")
#: Rank tolerance of the stacked system (that of dynid.least_squares).
RANK_TOLERANCE = 1e-10

#: A run: a Log whose ``tau`` holds the motor currents, or a tuple (q, qd, qdd, current) of
#: (T, n) arrays.
Run = Union[Log, Sequence[ArrayLike]]


@dataclass(eq=False)
class DriveGainIdentification(ValueEquality):
    """Drive gains and base parameters identified from motor currents: see
    :func:`identify_drive_gains`.

    ``result`` is the identified torque model (a :class:`dynid.LogIdentification`: base
    parameters in torque units, offsets, their standard deviations and covariance; its
    ``drive_gains`` report holds the gains, so it is saved, loaded and validated as
    ``dynid identify`` results are). ``payload`` is the payload's 10 standard parameters in the
    last DH frame, given or (with a known mass only) estimated, ``payload_std`` their standard
    deviations (0 where given, inf where the structure cannot see them). ``unknowns``,
    ``estimate`` and ``covariance`` cover the whole vector solved for: the base parameters and
    offsets, the gains, then the payload's estimated parameters. ``residual_rms`` is (runs, n):
    the RMS of Y theta + Y_n pi_L - k i per run and joint, in N m (unloaded runs first).
    """

    gains: NDArray[np.float64]  #: (n,) k_j, torque per unit of the logged current
    gains_std: NDArray[np.float64]
    result: LogIdentification
    payload: NDArray[np.float64]  #: (10,) pi_L in frame n (m, mx, my, mz, Ixx..Izz about O_n)
    payload_std: NDArray[np.float64]
    method: str
    unknowns: list[str]
    estimate: NDArray[np.float64]
    covariance: NDArray[np.float64]
    residual_rms: NDArray[np.float64]
    runs: list[dict[str, Any]] = field(default_factory=list)  #: source, loaded, samples

    @property
    def relative_std(self) -> NDArray[np.float64]:
        """100 gains_std / |gains| (percent)."""
        return relative_std(self.gains, self.gains_std)

    def torques(self, log: Log) -> Log:
        """``log`` (currents in ``tau``) with the torques k_j i_j in ``tau``."""
        return torques_from_currents(self.result, log)

    def predict_currents(self, log: Log) -> NDArray[np.float64]:
        """(T, n) currents the model predicts on ``log``: (Y theta) / k."""
        return self.result.predict(log) / self.gains

    def summary(self) -> str:
        """The gains with their standard deviations, the payload, then the torque model's
        summary (:meth:`dynid.LogIdentification.summary`)."""
        lines = [
            f"drive gains ({self.method.upper()}, scale from the "
            f"{'payload' if np.all(self.payload_std == 0) else 'payload mass'}):",
            f"  {'joint':<6}{'k':>12}  {'std':>10}  {'rel.std':>8}",
        ]
        for j, (k, s, r) in enumerate(zip(self.gains, self.gains_std, self.relative_std)):
            lines.append(f"  {j + 1:<6}{k:>12.6g}  {s:>10.3g}  {r:>7.3g}%")
        payload = ", ".join(
            f"{name}={value:.4g}" + (f"+-{std:.2g}" if std > 0 else "")
            for name, value, std in zip(PAYLOAD_NAMES, self.payload, self.payload_std)
        )
        lines.append(f"payload (frame n): {payload}")
        return "\n".join(lines) + "\n" + self.result.summary()


def identify_drive_gains(
    robot: Robot,
    unloaded: Run | Sequence[Run],
    loaded: Run | Sequence[Run],
    *,
    payload: ArrayLike | Mapping[str, Any] | None = None,
    payload_mass: float | None = None,
    rotor: bool = False,
    friction: bool | str = False,
    offset: bool = False,
    position_torque: bool = False,
    method: str = "nls",
    preparation: Mapping[str, Any] | None = None,
) -> DriveGainIdentification:
    """Identify the drive gains k (tau_j = k_j i_j) and the base parameters of ``robot`` from
    runs whose logs hold motor currents, the scale fixed by a payload of known parameters.

    ``unloaded`` and ``loaded`` are runs (or lists of runs) of the arm without and with the
    payload on its last link, along any trajectories: :class:`dynid.Log` objects whose ``tau``
    column holds the currents (qd, qdd computed from q when absent; ``preparation`` as in
    :func:`dynid.identify_log`, applied to every run), or tuples (q, qd, qdd, current) of
    (T, n) arrays (no ``preparation`` then). Give exactly one of ``payload`` (its 10 standard
    parameters in the last DH frame n about the frame's origin, or a mapping with ``mass``,
    ``com`` (3,) in frame n and optional ``inertia`` (3, 3) about the centre of mass) and
    ``payload_mass`` (the mass alone: the payload's other parameters are estimated with the
    rest). ``rotor``, ``friction`` (True, False or a friction model's name), ``offset`` and
    ``position_torque`` are those of :func:`dynid.identify_log`: the same column blocks;
    ``method`` is "nls" (default), "tls", "wls" or "ols" (module docstring). Every joint's rows
    are used (each is the only one that sees its gain).

    Raises ValueError naming the argument: no loaded or no unloaded run (the scale is then
    undetermined), a payload of zero mass, a mass the structure cannot tell from the payload's
    other parameters; :class:`dynid.RankDeficientError` (a ValueError) when the runs do not
    excite every unknown -- in particular when the payload's torques are too small to fix the
    scale, with the unexcited unknowns named.
    """
    checks.robot(robot)
    if not isinstance(robot, Robot):
        raise ValueError(f"robot: expected a dynid.Robot, got {type(robot).__name__}")
    if robot.coupled:
        raise ValueError(
            "robot: its drives are coupled (robot.transmission); drive gains from currents "
            "assume one motor per joint (tau_j = k_j i_j)"
        )
    rotor, offset, position_torque = (
        checks.flag(v, k)
        for v, k in ((rotor, "rotor"), (offset, "offset"), (position_torque, "position_torque"))
    )
    kind = friction_model(friction)
    symmetric = kind == "symmetric"  # in the rigid-body columns; the others are column blocks
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"method: expected one of {METHODS}, got {method!r}")
    n = robot.n
    options = _options(preparation)
    runs = [(False, log) for log in _runs(unloaded, "unloaded", n, options)]
    runs += [(True, log) for log in _runs(loaded, "loaded", n, options)]
    known, estimated = payload_vector(payload, payload_mass)
    base = base_parameters(robot, "torque", rotor=rotor, friction=symmetric)
    if estimated:
        estimated = visible_payload(base.beta[:, 10 * (n - 1) : 10 * n])
    # The torque model: the base parameters, then the column blocks these options ask for
    # (dynid.identification.blocks), as in identify_log.
    built = build_blocks(Context(robot, rotor, kind, offset, position_torque))
    if any(block.nonlinear() is not None for block in built):  # e.g. Stribeck's velocity scales
        raise ValueError(
            f"friction: the {kind!r} model has nonlinear parameters, which identify_log "
            "estimates (separable least squares) and identify_drive_gains does not"
        )
    column_blocks = kept(built)
    result = unfitted(robot, base, column_blocks, rotor=rotor, method=method)
    names = result.names
    system = CurrentModel(result.identification_model, DriveGains(n), known, tuple(estimated))
    unknowns = system.names(names)
    coefficients, gain, estimates = (
        system.slice(TORQUE),
        system.slice(system.gains.key),
        system.slice(PAYLOAD),
    )

    def rows(log: Log, loaded: bool, c: slice) -> tuple[NDArray, NDArray]:
        """The rows of samples c of a run."""
        assert log.qd is not None and log.qdd is not None
        return system.rows(log.q[c], log.qd[c], log.qdd[c], log.tau[c], loaded)

    # Factors per contiguous block of each run (for the jackknife check below), then merged.
    blocks = []
    for loaded_run, log in runs:
        for lo, hi in block_edges(log.T, max(2, -(-BLOCKS // len(runs)))):
            block = GroupedTriangularFactors(n, len(unknowns), tuple(range(n)))
            for start in range(lo, hi, STREAM_CHUNK):
                block.add(*rows(log, loaded_run, slice(start, min(start + STREAM_CHUNK, hi))))
            blocks.append(block)
    factors = GroupedTriangularFactors.merged(blocks)
    try:
        fit = solve_factors(
            factors,
            method="ols" if method == "ols" else "wls",  # WLS: a start for "nls"
            names=unknowns,
            on_rank_deficient="raise",
            rank_tolerance=RANK_TOLERANCE,
            excluded=(),
        )
    except RankDeficientError as exc:
        raise RankDeficientError(
            f"{exc} With currents, the scale of (theta, k) comes from the payload alone: the "
            "loaded runs must move it enough for its torques Y_n pi_L to stand out (a heavier "
            "payload, a longer or richer loaded trajectory)."
        ) from None
    if method in ("tls", "nls"):  # the LS fit above checked the rank
        x, covariance = total_least_squares(factors)
        if method == "nls":
            x, covariance = current_least_squares(factors, [fit.theta, x], gain)
    else:
        x, covariance = fit.theta, fit.covariance
    std = np.sqrt(np.maximum(np.diag(covariance), 0.0))

    def refit(part: GroupedTriangularFactors) -> NDArray[np.float64]:
        """The gains from part of the rows, by the same method, started from the whole fit."""
        if method == "nls":
            return current_least_squares(part, [x], gain)[0][gain]
        if method == "tls":
            return total_least_squares(part)[0][gain]
        solved = solve_factors(
            part, method=method, names=unknowns, on_rank_deficient="raise",
            rank_tolerance=RANK_TOLERANCE, excluded=(),
        )  # fmt: skip
        return solved.theta[gain]

    gains_spread = jackknife_std(blocks, refit)
    warning = overconfidence(unknowns[gain], x[gain], std[gain], gains_spread, method)
    if warning is not None:
        warnings.warn(warning, UserWarning, stacklevel=2)

    # Per-run residuals and the torque model's fit on the unloaded runs (k i as the measurement).
    gains = x[gain]
    residual = np.zeros((len(runs), n))
    measured, predicted = [], []
    for r, (loaded_run, log) in enumerate(runs):
        squares = np.zeros(n)
        for start in range(0, log.T, STREAM_CHUNK):
            A, b = rows(log, loaded_run, slice(start, start + STREAM_CHUNK))
            squares += np.sum((A @ x - b) ** 2, axis=0)
            if not loaded_run:
                measured.append(system.gains.torque(log.tau[start : start + STREAM_CHUNK], gains))
                predicted.append(A[:, :, coefficients] @ x[coefficients])
        residual[r] = np.sqrt(squares / log.T)
    payload_values = known.copy()
    payload_std = np.zeros(10)
    if estimated:
        payload_values[estimated] = x[estimates]
        payload_std[estimated] = std[estimates]
        unseen = [c for c in range(1, 10) if c not in estimated]
        payload_std[unseen] = np.inf  # not separable on this structure: left at 0
    result.theta, result.std = x[coefficients].copy(), std[coefficients].copy()
    result.relative_std = relative_std(result.theta, result.std)
    result.covariance = covariance[coefficients, coefficients].copy()
    # The whole system has full rank (solve_factors raised otherwise): theta's part too.
    result.condition_number, result.rank = fit.condition_number, len(names)
    first = next(log for loaded_run, log in runs if not loaded_run)
    conversion = system.gains.note(gains)
    result.log = replace(
        first, tau=system.gains.torque(first.tau, gains), notes=[*first.notes, conversion]
    )
    sources = [
        {"source": log.source, "loaded": loaded_run, "samples": log.T} for loaded_run, log in runs
    ]
    result.training = {
        "source": first.source,
        "format": first.format,
        "samples": sum(log.T for loaded_run, log in runs if not loaded_run),
        "duration_s": first.duration,
        "sampling_rate_hz": first.fs,
        "preparation": {k: _plain(v) for k, v in options.items()},
        "notes": [*first.notes, *(note for b in built for note in b.notes()), conversion],
        "metrics": error_metrics(np.concatenate(measured), np.concatenate(predicted)),
    }
    result.drive_gains = {
        "gains": gains.tolist(),
        "gains_std": std[gain].tolist(),
        # the block jackknife's (gain_consistency): None when leaving a block out fixes nothing
        "gains_std_blocks": None if gains_spread is None else gains_spread.tolist(),
        "method": method,
        "payload": dict(zip(PAYLOAD_NAMES, payload_values.tolist())),
        "payload_std": dict(zip(PAYLOAD_NAMES, [_finite(s) for s in payload_std])),
        "payload_known": "all" if not estimated else "mass",
        "runs": [dict(s, residual_rms=row.tolist()) for s, row in zip(sources, residual)],
    }
    return DriveGainIdentification(
        gains=gains.copy(),
        gains_std=std[gain].copy(),
        result=result,
        payload=payload_values,
        payload_std=payload_std,
        method=method,
        unknowns=unknowns,
        estimate=x,
        covariance=covariance,
        residual_rms=residual,
        runs=sources,
    )


def torques_from_currents(result: LogIdentification, log: Log) -> Log:
    """``log`` with its currents (``tau``) converted to torques k_j i_j by the gains of
    ``result`` (an :func:`identify_drive_gains` result, or one loaded from its folder)."""
    report = getattr(result, "drive_gains", None)
    if report is None:
        raise ValueError(
            "result: holds no drive gains (identified from torques, not with --current); "
            "its logs must hold torques"
        )
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    gains = np.asarray(report["gains"], dtype=float)
    if log.n != gains.size:
        raise ValueError(f"log: has {log.n} joints, the result's gains {gains.size}")
    block = DriveGains(log.n)
    return replace(log, tau=block.torque(log.tau, gains), notes=[*log.notes, block.note(gains)])


# --------------------------------------------------------------------------- helpers


def _runs(value: Any, name: str, n: int, options: Mapping[str, Any]) -> list[Log]:
    """The runs of one kind as prepared Logs with qd and qdd."""
    if isinstance(value, Log) or (isinstance(value, tuple) and len(value) == 4 and _arrays(value)):
        items = [value]
    elif isinstance(value, Sequence) and not isinstance(value, (str, bytes)):
        items = list(value)
    else:
        raise ValueError(
            f"{name}: expected a dynid.Log (currents in tau), a (q, qd, qdd, current) tuple or a "
            f"list of them, got {type(value).__name__}"
        )
    if not items:
        raise ValueError(
            f"{name}: no run given; the currents fix the parameters only up to a common scale, "
            "which one run without and one with the payload determine together"
        )
    logs = []
    for k, item in enumerate(items):
        where = f"{name}[{k}]"
        if isinstance(item, Log):
            log = prepare_log(item, **options) if options else item
        elif isinstance(item, (tuple, list)) and len(item) == 4:
            if options:
                raise ValueError(
                    f"preparation: needs time stamps; {where} is arrays: pass a dynid.Log"
                )
            q, qd, qdd, current = (np.asarray(a, dtype=float) for a in item)
            if q.ndim != 2:
                raise ValueError(f"{where}: expected (T, {n}) arrays, got q of shape {q.shape}")
            try:
                log = Log(t=np.arange(q.shape[0], dtype=float), q=q, tau=current, qd=qd, qdd=qdd)
            except ValueError as exc:
                raise ValueError(f"{where}: {exc}") from None
            log.source = f"<{where}>"
        else:
            raise ValueError(
                f"{where}: expected a dynid.Log or a (q, qd, qdd, current) tuple, got "
                f"{type(item).__name__}"
            )
        try:
            logs.append(_with_derivatives(log, n, "robot"))
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None
    return logs


def _arrays(value: tuple) -> bool:
    return all(np.ndim(a) == 2 for a in value)


def _finite(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None
