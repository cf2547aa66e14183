"""A payload from two logs of the arm, without and with it (the Python side of ``dynid payload``).

The rule of change (notes p. 33; :mod:`dynid.identification.payload`): the loaded arm's torque is
the unloaded arm's plus the last link's 10 regressor columns times the payload's standard
parameters, tau_loaded = Y_b theta + Y_n pi_L, with Y_b theta the unloaded arm's torque model (base
parameters and, as identified, rotor, friction, offsets, ...). Both logs are fitted together,

    [tau_unloaded]   [Y_b(unloaded)   0          ] [theta]
    [tau_loaded  ] = [Y_b(loaded)     Y_n(loaded)] [pi_L ],

so that the unloaded model's own estimation error is in the payload's covariance. Taking theta
from an earlier identification instead and treating its prediction as exact (``estimate_payload(
..., tau_unloaded=result.predict(log))``) leaves that error out: on a simulated UR5 the z-scores
of the payload had an RMS of 1.5-2 instead of 1 even on unfiltered data (docs/payload.md).

The standard deviations then follow the residuals' correlation in time
(:mod:`dynid.identification.serial_correlation`): both logs are usually low-passed, and rows of a
filtered log are not independent draws.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from .. import _checks as checks
from ..logs.log_files import Log
from ..logs.preparation import prepare_log
from ..model.base_parameters import base_parameters
from ..model.robot import Robot
from .blocks.base import Context
from .blocks.model import kept
from .blocks.registry import build_blocks, friction_model
from .identify import VARIANCE_FLOOR, RankDeficientError
from .log_identification import (
    STREAM_CHUNK,
    LogIdentification,
    _moving_rows,
    _options,
    _sample_options,
    _training_logs,
    _with_derivatives,
    unfitted,
)
from .payload import FRAMES, PAYLOAD_NAMES, PayloadEstimate, _physical
from .serial_correlation import bartlett_width, long_run_covariance
from .streaming import LeastSquaresAccumulator

PathLike = Union[str, Path]


def estimate_payload_from_logs(
    unloaded: Log | PathLike | Sequence[Log | PathLike],
    loaded: Log | PathLike | Sequence[Log | PathLike],
    model: Robot | LogIdentification,
    *,
    rotor: bool = False,
    friction: bool | str = False,
    offset: bool = False,
    preparation: Mapping[str, Any] | None = None,
    method: str = "wls",
    exclude_joints: Sequence[int] = (),
    frame: str = "flange",
) -> PayloadEstimate:
    """Estimate the payload on the last link from logs of the arm without and with it.

    Parameters
    ----------
    unloaded, loaded
        Logs (a :class:`dynid.Log`, a log file, or a list of them) of the arm without and with
        the payload; any exciting motions, not necessarily the same.
    model
        The unloaded arm: a result of :func:`dynid.identify_log` (its structure and torque
        model: base parameters, rotor, friction model, offsets, position torque) or a robot
        (its kinematics; the torque model then has the base parameters and the columns
        ``rotor``, ``friction``, ``offset`` ask for, as in :func:`dynid.identify_log`). The
        torque model's coefficients are estimated again, on both logs with the payload (module
        docstring): the model gives the structure, the logs the values.
    preparation
        Options of :func:`dynid.prepare_log` applied to every log (``min_velocity`` leaves out
        rows per joint, as in :func:`dynid.identify_log`).
    method
        "wls" (per-joint noise levels, the default) or "ols".
    exclude_joints, frame
        As in :func:`dynid.estimate_payload`.

    Returns
    -------
    A :class:`PayloadEstimate` whose standard deviations include the unloaded model's
    uncertainty and the residuals' correlation in time (``bartlett_width``, the kernel width in
    samples; 1 when the residuals are white). ``fit`` is the joint least-squares fit of (theta,
    pi_L) with the white-noise covariance.

    Raises
    ------
    RankDeficientError (a ValueError) when the logs do not determine theta and pi_L together
    (the unloaded log must excite the torque model, the loaded log the payload); ValueError for
    bad arguments.
    """
    if not isinstance(frame, str) or frame not in FRAMES:
        raise ValueError(f"frame: expected one of {FRAMES}, got {frame!r}")
    if method not in ("ols", "wls"):
        raise ValueError(f"method: expected 'ols' or 'wls', got {method!r}")
    torque_model = _torque_model(model, rotor, friction, offset, method)
    robot = torque_model.robot
    exclude_joints = checks.indices(exclude_joints, "exclude_joints", robot.n)
    options = _options(preparation)
    runs = []
    for name, logs in (("unloaded", unloaded), ("loaded", loaded)):
        try:
            items = _training_logs(logs)
        except ValueError as exc:
            raise ValueError(f"{name}: {exc}") from None
        for log in items:
            prepared = prepare_log(log, **_sample_options(options))
            prepared = _with_derivatives(prepared, robot.n, robot.name)
            rows, _ = _moving_rows(prepared.qd, options.get("min_velocity"))
            runs.append((name == "loaded", prepared, rows))
    columns = torque_model.identification_model.size
    last = slice(10 * (robot.n - 1), 10 * robot.n)
    names = list(torque_model.names) + list(PAYLOAD_NAMES)

    def chunks() -> Any:
        """(run index, Y (T_c, n, columns + 10), tau, rows kept) chunk by chunk."""
        for r, (is_loaded, log, rows) in enumerate(runs):
            for k in range(0, log.T, STREAM_CHUNK):
                c = slice(k, k + STREAM_CHUNK)
                q, qd, qdd = log.q[c], log.qd[c], log.qdd[c]  # type: ignore[index]
                Y = np.zeros((q.shape[0], robot.n, columns + 10))
                Y[..., :columns] = torque_model.regressor(q, qd, qdd)
                if is_loaded:
                    Y[..., columns:] = robot.regressor(q, qd, qdd)[..., last]
                yield r, Y, log.tau[c], None if rows is None else rows[c]

    accumulator = LeastSquaresAccumulator(robot.n, columns + 10, exclude_joints=exclude_joints)
    for _, Y, tau, rows in chunks():
        accumulator.add(Y, tau, rows)
    try:
        fit = accumulator.solve(method=method, names=names)
    except RankDeficientError as exc:
        raise RankDeficientError(
            f"the logs do not determine the unloaded torque model and the payload together: "
            f"{exc} (the unloaded log must excite the model, the loaded log the payload)"
        ) from None
    weights = _row_weights(fit.noise_variance, fit.joints, robot.n, method)
    # Second pass: the sandwich A^-1 Omega A^-1 (serial_correlation), A accumulated here with
    # the fit's weights, Omega from each sample's weighted residual on its rows.
    A = np.zeros((columns + 10, columns + 10))
    gradients: list[list[NDArray[np.float64]]] = [[] for _ in runs]
    residuals: list[list[NDArray[np.float64]]] = [[] for _ in runs]
    for r, Y, tau, rows in chunks():
        w = np.broadcast_to(weights, tau.shape)
        if rows is not None:
            w = np.where(rows, w, 0.0)
        e = tau - Y @ fit.theta
        A += np.tensordot(Y * w[..., None], Y, axes=([0, 1], [0, 1]))  # sum_t Y_t^T W Y_t
        gradients[r].append(np.matmul((w * e)[:, None, :], Y)[:, 0, :])  # g_t = Y_t^T W e_t
        residuals[r].append(e * np.sqrt(w))
    segments = [np.concatenate(parts) for parts in residuals]
    width = bartlett_width(segments)
    inverse = _inverse_rows(A, slice(columns, columns + 10))  # rows of A^-1 for pi_L
    influence = [np.concatenate(parts) @ inverse.T for parts in gradients]
    covariance = long_run_covariance(influence, width)
    estimate = _physical(fit.theta[columns:], covariance, robot, frame, fit)
    return dataclasses.replace(estimate, bartlett_width=width)


def _torque_model(
    model: Any, rotor: bool, friction: bool | str, offset: bool, method: str
) -> LogIdentification:
    """The unloaded arm's torque model: a result as it is, or a robot's base parameters with
    the columns asked for (an unfitted result: the structure of :func:`dynid.identify_log`)."""
    if isinstance(model, LogIdentification):
        if rotor or friction or offset:
            raise ValueError(
                "rotor, friction, offset: a result brings its own torque model; give them with "
                "a robot model only"
            )
        return model
    if not isinstance(model, Robot):
        raise ValueError(
            f"model: expected a dynid.Robot or a result of dynid.identify_log, got "
            f"{type(model).__name__}"
        )
    rotor = checks.flag(rotor, "rotor")
    offset = checks.flag(offset, "offset")
    kind = friction_model(friction)
    blocks = kept(build_blocks(Context(model, rotor, kind, offset, False)))
    base = base_parameters(model, "torque", rotor=rotor, friction=kind == "symmetric")
    return unfitted(model, base, blocks, rotor=rotor, method=method)


def _row_weights(
    noise_variance: NDArray[np.float64], joints: tuple[int, ...], n: int, method: str
) -> NDArray[np.float64]:
    """(n,) the fit's row weights: 1 / sigma_j^2 (floored as :func:`dynid.least_squares` does)
    for WLS, 1 for OLS; 0 for excluded joints."""
    weights = np.zeros(n)
    if method == "ols":
        weights[list(joints)] = 1.0
        return weights
    variance = np.asarray(noise_variance, dtype=float)
    if not np.any(variance > 0):
        weights[list(joints)] = 1.0
        return weights
    weights[list(joints)] = 1.0 / np.maximum(variance, VARIANCE_FLOOR * variance.max())
    return weights


def _inverse_rows(A: NDArray[np.float64], rows: slice) -> NDArray[np.float64]:
    """The ``rows`` of A^-1 for a symmetric positive definite A, solved with the columns
    scaled to unit diagonal (the parameters' units differ by orders of magnitude)."""
    d = np.sqrt(np.diag(A))
    d[d == 0] = 1.0
    scaled = A / np.outer(d, d)
    unit = np.zeros((A.shape[0], rows.stop - rows.start))
    unit[rows, :] = np.eye(rows.stop - rows.start) / d[rows, None]
    # A^-1 = D^-1 S^-1 D^-1 with S the scaled matrix: its columns for ``rows``.
    return (np.linalg.solve(scaled, unit) / d[:, None]).T
