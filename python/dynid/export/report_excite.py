"""``report.html`` of ``dynid excite``: the designed trajectory against its limits.

Sections: what was designed (the model, the series, the condition number), one figure per joint
with q, qd, qdd and the predicted torque over the whole duration and their limits drawn as
lines, and a table of each joint's extremes against its limits (the share of each limit used).
The values are the trajectory's own (``ExperimentTrajectory.evaluate``, the function the other
files are sampled from) on a grid of ``REPORT_SAMPLES`` instants, the torque predicted by the
model written to trajectory.csv; the limits are those recorded in trajectory.json.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from ..excitation.trajectory_files import ExperimentTrajectory
from ..model.robot import Robot
from .report_figures import svg_of
from .report_html import Num, Section, facts, figure, table

#: Instants drawn and tabulated over the whole duration.
REPORT_SAMPLES = 2000

_QUANTITIES = (
    ("q", "q [rad]"),
    ("qd", "qd [rad/s]"),
    ("qdd", "qdd [rad/s^2]"),
    ("tau", "tau [N m]"),
)


def excite_sections(plan: ExperimentTrajectory, model: Robot) -> list[Section]:
    """The sections of the page (module docstring); ``model`` predicts the torque."""
    t = np.linspace(0.0, plan.duration, REPORT_SAMPLES)
    q, qd, qdd = plan.evaluate(t)
    values = {"q": q, "qd": qd, "qdd": qdd, "tau": model.rnea(q, qd, qdd)}
    bounds = _bounds(plan.limits, plan.trajectory.n)
    names = list(plan.joint_names)
    return [
        _summary(plan, model),
        _limits_section(values, bounds, names),
        _figures_section(t, values, bounds, names),
    ]


def _bounds(limits: dict[str, Any], n: int) -> dict[str, tuple[NDArray, NDArray] | None]:
    """(lower, upper) per joint of each quantity, None where trajectory.json records none."""

    def vector(key: str) -> NDArray[np.float64] | None:
        value = limits.get(key)
        return None if value is None else np.broadcast_to(np.asarray(value, float), (n,))

    out: dict[str, tuple[NDArray, NDArray] | None] = {}
    low, high = vector("q_min"), vector("q_max")
    out["q"] = None if low is None or high is None else (low, high)
    for quantity, key in (("qd", "qd_max"), ("qdd", "qdd_max"), ("tau", "tau_max")):
        top = vector(key)
        out[quantity] = None if top is None else (-top, top)
    return out


def _summary(plan: ExperimentTrajectory, model: Robot) -> Section:
    traj = plan.trajectory
    items = [
        ("model", plan.model or model.name),
        ("joints", ", ".join(plan.joint_names)),
        ("harmonics", traj.harmonics),
        ("period [s]", Num(traj.period)),
        ("periods", plan.periods),
        ("duration [s]", Num(plan.duration)),
        ("start and stop", plan.ramp.replace("_", " ")),
        ("condition number", Num(plan.condition_number)),
        ("torque predicted by", plan.limits.get("torque_model") or model.name),
    ]
    return Section("summary", "Summary", facts(items, "summary-facts"))


def _limits_section(
    values: dict[str, NDArray[np.float64]],
    bounds: dict[str, tuple[NDArray, NDArray] | None],
    names: list[str],
) -> Section:
    rows: list[list[Any]] = []
    for j, name in enumerate(names):
        row: list[Any] = [name]
        for quantity, _ in _QUANTITIES:
            series = values[quantity][:, j]
            row += [Num(series.min()), Num(series.max())]
            limit = bounds[quantity]
            if limit is None:
                row.append("no limit")
                continue
            low, high = limit[0][j], limit[1][j]
            # The share of the limit used: of the half range about its centre for q, of the
            # bound itself for the symmetric ones.
            centre, half = 0.5 * (low + high), 0.5 * (high - low)
            used = np.abs(series - centre).max() / half if half > 0 else np.inf
            row.append(Num(100.0 * used, 4, " %"))
        rows.append(row)
    headers = ["joint"]
    for quantity, _ in _QUANTITIES:
        headers += [f"{quantity} min", f"{quantity} max", f"{quantity} limit used"]
    body = table(headers, rows, "limits-table", "Each joint's extremes against its limits")
    return Section("limits", "Limits", body)


def _figures_section(
    t: NDArray[np.float64],
    values: dict[str, NDArray[np.float64]],
    bounds: dict[str, tuple[NDArray, NDArray] | None],
    names: list[str],
) -> Section:
    parts = []
    for j, name in enumerate(names):
        gid = f"joint-{j + 1}"
        fig = Figure(figsize=(9.0, 5.2))
        fig.subplots_adjust(left=0.09, right=0.99, top=0.94, bottom=0.09, hspace=0.35)
        for k, (quantity, label) in enumerate(_QUANTITIES):
            ax = fig.add_subplot(4, 1, k + 1)
            (line,) = ax.plot(t, values[quantity][:, j], color="tab:blue", lw=1.0)
            line.set_gid(f"{gid}-{quantity}")
            limit = bounds[quantity]
            if limit is not None:
                for bound in (limit[0][j], limit[1][j]):
                    ax.axhline(bound, color="tab:red", lw=0.8, ls="--")
            ax.set_ylabel(label, fontsize=8)
            ax.grid(alpha=0.3)
            if k == 0:
                ax.set_title(name, fontsize=10)
        fig.axes[-1].set_xlabel("t [s]")
        caption = f"{name}: q, qd, qdd and the predicted torque; dashed: the limits"
        parts.append(figure(svg_of(fig, gid), f"figure-{gid}", caption))
    return Section("trajectory", "Trajectory per joint", "\n".join(parts))
