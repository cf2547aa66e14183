"""Collision residual over a log: the generalized-momentum observer (De Luca & Mattone 2005;
docs/uses.md, "Collision residual"; the paper's conclusion) run on recorded (q, qd, tau), and its
plot.

:class:`dynid.MomentumObserver` (C++) does the work; this module feeds it a :class:`dynid.Log`
and a model, either a :class:`dynid.Robot` or an identified :class:`dynid.LogIdentification`
(its base parameters turned into an equivalent robot: :func:`robot_from_identification`), and
summarises the residual per joint. Without contact the residual is the model error seen through
the observer's first-order filter; a collision shows as a jump towards J^T F_ext.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .. import _core
from .._checks import real_array
from ..logs.log_files import Log
from ..logs.preparation import prepare_log
from .log_identification import LogIdentification
from .validation import root_mean_square

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

    from ..model.robot import Robot

Array: TypeAlias = NDArray[np.float64]


@dataclass
class Residual:
    """The observer's output over a log: ``r`` (T, n) at the times ``t`` (T,), with the gain
    (n,) and the sample period used, and per-joint ``rms`` and ``max_abs`` of ``r``."""

    t: Array
    r: Array
    gain: Array
    dt: float
    rms: Array
    max_abs: Array


def robot_from_identification(result: LogIdentification) -> tuple[Robot, Array]:
    """A robot whose dynamics equal the identified model, and the identified torque offsets (n,)
    (zeros without offset columns).

    The identified coefficients are base parameters, tau = Y[:, independent] theta; a standard
    parameter vector holding theta at the independent columns and zero elsewhere gives the same
    Y pi for every (q, qd, qdd), hence the same M(q), c, g and friction (drive terms not
    identified are zero). Its parameters are not physically meaningful one by one. The other
    columns of the result (asymmetric friction, position torque: ``result.extra_torque``) are
    not part of the robot.
    """
    if not isinstance(result, LogIdentification):
        raise ValueError(
            "model: expected a dynid.Robot or a dynid.LogIdentification, got "
            f"{type(result).__name__}"
        )
    robot = result.robot.copy()
    n = robot.n
    pi = np.zeros(len(result.parameter_names))
    pi[result.independent] = result.theta[: result.identification_model.rigid.size]
    robot.params = pi[: 10 * n]
    column = 10 * n
    robot.Ia = pi[column : column + n] if result.rotor else np.zeros(n)
    column += n if result.rotor else 0
    robot.Fv = pi[column : column + n] if result.friction else np.zeros(n)
    robot.Fs = pi[column + n : column + 2 * n] if result.friction else np.zeros(n)
    return robot, result.offsets.copy()


def residual_from_log(model: Robot | LogIdentification, log: Log, gain: float | Array) -> Residual:
    """Run :class:`dynid.MomentumObserver` over ``log`` (uniformly sampled; qd computed from q
    when absent) with ``gain`` (1/s, a number or one per joint) at the log's median sample
    period. With an identified model, the torques of its columns that are not the robot's
    (offsets, asymmetric friction, position torque: ``extra_torque(q, qd)``) are taken off the
    measured torques."""
    from ..model.robot import Robot

    if isinstance(model, Robot):
        robot = model
    else:
        robot, _ = robot_from_identification(model)
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    if log.n != robot.n:
        raise ValueError(f"log: has {log.n} joints, the model {robot.n}")
    log.check_uniform("the momentum observer")
    if log.qd is None:
        log = prepare_log(log, differentiate="missing")
    dt = float(np.median(np.diff(log.t)))
    observer = _core.MomentumObserver(robot, gain, dt)
    assert log.qd is not None  # measured, or differentiated just above
    extra = 0.0 if isinstance(model, Robot) else model.extra_torque(log.q, log.qd)
    r = observer.run(log.q, log.qd, log.tau - extra)
    return Residual(
        t=log.t.copy(),
        r=r,
        gain=observer.gain,
        dt=dt,
        rms=root_mean_square(r),
        max_abs=np.abs(r).max(axis=0),
    )


def plot_residual(
    residual: Residual, path: str | Path, threshold: float | Array | None = None
) -> Path:
    """One panel per joint of r(t) (N m or N), with +-``threshold`` lines when given; saved as
    an image at ``path`` (the format from its suffix, e.g. .png)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = residual.r.shape[1]
    fig, axes = plt.subplots(n, 1, sharex=True, figsize=(8, 1.6 * n + 1), squeeze=False)
    limits = (
        None if threshold is None else np.broadcast_to(real_array(threshold, "threshold"), (n,))
    )
    for j, ax in enumerate(axes[:, 0]):
        ax.plot(residual.t - residual.t[0], residual.r[:, j], lw=0.8)
        if limits is not None:
            for sign in (-1, 1):
                ax.axhline(sign * limits[j], color="tab:red", lw=0.6, ls="--")
        ax.set_ylabel(f"r{j + 1}")
        ax.text(
            0.99,
            0.9,
            f"RMS {residual.rms[j]:.3g}",
            transform=ax.transAxes,
            ha="right",
            va="top",
            fontsize=8,
        )
    fig.axes[-1].set_xlabel("t - t0 [s]")  # the bottom panel, axes[-1, 0] (typed as an Axes)
    gains = ", ".join(f"{g:g}" for g in np.unique(residual.gain))
    fig.suptitle(f"momentum-observer residual [N m] (gain {gains} 1/s, dt {residual.dt:.4g} s)")
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def save_residual(residual: Residual, path: str | Path) -> Path:
    """The residual as an .npz file: t, r, gain, dt, rms, max_abs."""
    out = Path(path)
    np.savez(
        out,
        t=residual.t,
        r=residual.r,
        gain=residual.gain,
        dt=residual.dt,
        rms=residual.rms,
        max_abs=residual.max_abs,
    )
    return out
