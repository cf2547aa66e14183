"""The sections of ``report.html`` for ``dynid identify`` and ``dynid validate``
(:mod:`dynid.export.report`): summary, measured and predicted torque per joint, residual
histograms, the coefficients, the per-joint errors, the notes and warnings.

The numbers are those of result.json and validation.json (the same values, printed to a stated
precision, their exact value in ``data-value``). Holes in the torque plots: the rows a
preparation dropped and the gaps of the time stamps (:func:`~.report_figures.with_gaps`), and
with ``min_velocity`` the rows of joint j where |qd_j| < min_velocity, which the fit and the
errors leave out (recomputed here with the same function, ``dynid.logs.signal``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..identification.log_identification import LogIdentification, LogValidation
from ..logs import signal as sig
from ..logs.log_files import Log
from ..logs.preparation import prepare_log
from ..logs.timing import DROPPED_STEP
from .report_figures import histogram_figure, torque_figure
from .report_html import Num, Section, bullet_list, facts, figure, table

#: The per-joint errors (dynid.identification.validation.error_metrics) and their headings.
METRICS = {
    "rms": "rms error [N m]",
    "relative_rms": "relative rms error",
    "max_abs": "max |error| [N m]",
    "r2": "R²",
    "mse": "mse [N² m²]",
}

Run = tuple[Log, NDArray[np.float64], "NDArray[np.bool_] | None"]


def identification_sections(
    result: LogIdentification, *, log: Log | None = None, warnings: Sequence[str] = ()
) -> list[Section]:
    """The sections of an identification's report (see the module docstring)."""
    training = result.training
    runs = _identification_runs(result, log)
    names = _joint_names(result)
    sections = [
        Section("summary", "Summary", facts(_identification_facts(result), "summary-facts")),
        _torque_section(runs, names, "training log", result.excluded),
        _histogram_section(runs, names),
        _parameter_section(result),
    ]
    metrics: list[tuple[str, Mapping[str, Any]]] = [
        ("fit on the training log" + ("s" if training.get("logs") else ""), training)
    ]
    metrics += [(f"fit on log {k}, {run.get('source')}", run) for k, run in _logs(training)]
    sections.append(_metrics_section(metrics, names))
    notes = list(training.get("notes", []))
    for k, run in _logs(training):
        notes += [f"log {k}: {note}" for note in run.get("notes", [])]
    sections.append(_notes_section(warnings, notes))
    return sections


def validation_sections(
    validation: LogValidation,
    *,
    result: LogIdentification | None,
    warnings: Sequence[str],
    sources: Mapping[str, Any],
) -> list[Section]:
    """The sections of a validation's report; with ``result`` its coefficients too."""
    log = validation.log
    keep = _kept_rows(log, validation.preparation.get("min_velocity"))
    runs: list[Run] = [(log, np.asarray(validation.predicted, dtype=float), keep)]
    names = _joint_names(result) if result is not None else [f"J{j + 1}" for j in range(log.n)]
    items: list[tuple[str, Any]] = [
        ("result", sources.get("result") or "-"),
        ("arm", _arm(result) if result is not None else "-"),
        ("log", sources.get("log") or log.source),
        ("format", log.format or "-"),
        ("samples", log.T),
        ("duration [s]", Num(log.duration, 6)),
        ("preparation", _options_text(validation.preparation)),
    ]
    sections = [
        Section("summary", "Summary", facts(items, "summary-facts")),
        _torque_section(runs, names, "validation log", ()),
        _histogram_section(runs, names),
    ]
    training = result.training.get("metrics", {}) if result is not None else {}
    sections.append(
        _metrics_section(
            [("errors on the validation log", {"metrics": validation.metrics})],
            names,
            training_relative_rms=training.get("relative_rms"),
        )
    )
    if result is not None:
        sections.append(_parameter_section(result, "Coefficients of the result applied"))
    notes = list(log.notes) + list(validation.notes)
    sections.append(_notes_section(warnings, notes))
    return sections


# --------------------------------------------------------------------------- the data


def _identification_runs(result: LogIdentification, log: Log | None) -> list[Run]:
    """(prepared log, predicted torque, rows kept) of each training log shown."""
    min_velocity = result.training.get("preparation", {}).get("min_velocity")
    if log is not None:
        pairs = [(log, result.predict(log))]
    elif result.logs and len(result.fitted_logs) == len(result.logs):
        pairs = list(zip(result.logs, result.fitted_logs))
    elif result.log is not None:
        fitted = result.fitted if result.fitted is not None else result.predict(result.log)
        pairs = [(result.log, fitted)]
    else:
        pairs = []  # a result loaded from its file: no log kept
    return [
        (run, np.asarray(predicted, dtype=float), _kept_rows(run, min_velocity))
        for run, predicted in pairs
    ]


def _kept_rows(log: Log, min_velocity: Any) -> NDArray[np.bool_] | None:
    """(T, n) the rows min_velocity keeps (those identify and validate fit and measure), as
    ``identify_log`` computes them; None without min_velocity."""
    if min_velocity is None:
        return None
    qd = log.qd if log.qd is not None else prepare_log(log, differentiate="missing").qd
    assert qd is not None  # differentiated from q
    return np.asarray(sig.moving_mask_min_velocity(qd, min_velocity, per_joint=True), dtype=bool)


def _logs(training: Mapping[str, Any]) -> list[tuple[int, Mapping[str, Any]]]:
    return list(enumerate(training.get("logs") or [], start=1))


def _joint_names(result: LogIdentification) -> list[str]:
    names = list(getattr(result.robot, "joint_names", []) or [])
    return [
        f"J{j + 1}" + (f" ({names[j]})" if j < len(names) and names[j] else "")
        for j in range(result.n)
    ]


def _arm(result: LogIdentification) -> str:
    model = result.model
    return (
        f"{model.get('name') or '?'}: {result.n} joints ({model.get('joint_types', '')}), "
        f"{model.get('convention', '?')} DH"
    )


def _options_text(options: Mapping[str, Any]) -> str:
    if not options:
        return "none (the log as given)"
    return ", ".join(f"{k} = {v}" for k, v in options.items())


def _listed(value: Any) -> str:
    return ", ".join(map(str, value)) if isinstance(value, list) else str(value)


def _identification_facts(result: LogIdentification) -> list[tuple[str, Any]]:
    training = result.training
    columns = ["rigid body"] + [k for k in ("rotor", "friction") if getattr(result, k)]
    columns += [block.key.replace("_", " ") for block in result.blocks]
    items: list[tuple[str, Any]] = [
        ("arm", _arm(result)),
        ("log" + ("s" if training.get("logs") else ""), _listed(training.get("source", "-"))),
        ("format", _listed(training.get("format") or "-")),
        ("samples", training.get("samples", "-")),
        ("duration [s]", Num(training.get("duration_s"), 6)),
    ]
    if "sampling_rate_hz" in training:
        items.append(("sampling rate [Hz]", Num(training["sampling_rate_hz"], 6)))
    items += [
        ("preparation", _options_text(training.get("preparation", {}))),
        ("method", result.method.upper()),
        ("columns", ", ".join(columns) + f"; friction model: {result.friction_model}"),
        ("coefficients", f"{result.theta.size} ({result.count} base parameters)"),
        ("rank", f"{result.rank} of {result.theta.size}"),
        ("condition number", Num(result.condition_number, 6)),
    ]
    if result.excluded:
        items.append(
            ("joints left out of the fit", ", ".join(f"J{j + 1}" for j in result.excluded))
        )
    if result.physical is not None:
        report = result.physical
        items.append(
            (
                "physically consistent fit",
                f"SDP, {report.get('solver')} status {report.get('status')}, prior "
                f"{report.get('prior') or 'none'}; the values are the identified robot's base "
                "parameters (no standard deviations)",
            )
        )
    if result.drive_gains is not None:
        gains = ", ".join(f"{k:.6g}" for k in result.drive_gains.get("gains", []))
        items.append(("drive gains k (tau = k * current)", gains))
    return items


# --------------------------------------------------------------------------- sections


def _torque_section(
    runs: Sequence[Run], names: Sequence[str], what: str, excluded: Sequence[int]
) -> Section:
    if not runs:
        return Section("torques", "Measured and predicted torque", "<p>No log kept.</p>")
    parts = []
    for k, (log, predicted, keep) in enumerate(runs, start=1):
        t = log.t - log.t[0]
        label = f"{what} {k}" if len(runs) > 1 else what
        step = np.diff(log.t)
        jumps = int(np.sum(step > DROPPED_STEP * np.median(step))) if log.T > 1 else 0
        for j, name in enumerate(names):
            rows = None if keep is None else keep[:, j]
            left_out = 0 if rows is None else int((~rows).sum())
            title = f"{name}: {label}, {log.source}" + (
                " (left out of the fit)" if j in excluded else ""
            )
            svg = torque_figure(
                t, log.tau[:, j], predicted[:, j], rows, title, f"torque-log{k}-j{j + 1}"
            )
            caption = (
                f"{name}: measured (dashed) and predicted (solid) torque, {log.T} samples; "
                f"breaks: {jumps} steps of dropped samples or gaps"
                + (f", {left_out} rows left out by min_velocity" if keep is not None else "")
            )
            parts.append(figure(svg, f"torque-log{k}-j{j + 1}", caption))
    return Section("torques", "Measured and predicted torque", "\n".join(parts))


def _histogram_section(runs: Sequence[Run], names: Sequence[str]) -> Section:
    if not runs:
        return Section("residuals", "Residuals", "<p>No log kept.</p>")
    parts = []
    for j, name in enumerate(names):
        residual = np.concatenate(
            [
                (predicted[:, j] - log.tau[:, j])[slice(None) if keep is None else keep[:, j]]
                for log, predicted, keep in runs
            ]
        )
        svg = histogram_figure(residual, name, f"histogram-j{j + 1}")
        caption = (
            f"{name}: predicted - measured on {residual.size} rows; mean {residual.mean():.4g} "
            f"N m, standard deviation {residual.std():.4g} N m"
        )
        parts.append(figure(svg, f"histogram-j{j + 1}", caption))
    body = '<div class="histograms">' + "\n".join(parts) + "</div>"
    return Section("residuals", "Residuals (predicted − measured)", body)


def _parameter_section(result: LogIdentification, title: str = "Coefficients") -> Section:
    rows = [
        [name, Num(value, 6), Num(std, 3), Num(rel, 3, " %"), expression]
        for name, value, std, rel, expression in zip(
            result.names, result.theta, result.std, result.relative_std, result.expressions
        )
    ]
    headers = ["coefficient", "value", "± std", "relative std", "expression"]
    body = table(headers, rows, "parameter-table") + (
        "<p>Values in SI units as their expressions over the standard parameters (result.json, "
        "<code>units</code>); a dash: no standard deviation (a physically consistent fit) or "
        "a relative one of a zero value.</p>"
    )
    return Section("parameters", title, body)


def _metrics_section(
    groups: Sequence[tuple[str, Mapping[str, Any]]],
    names: Sequence[str],
    training_relative_rms: Any = None,
) -> Section:
    tables = []
    for k, (caption, holder) in enumerate(groups):
        metrics = {m: np.asarray(v, dtype=float) for m, v in holder.get("metrics", {}).items()}
        keys = [m for m in METRICS if m in metrics]
        headers = ["joint"] + [METRICS[m] for m in keys]
        extra = training_relative_rms is not None and k == 0
        if extra:
            headers.append("relative rms error (training)")
        rows = []
        for j, name in enumerate(names):
            row: list[Any] = [name] + [Num(metrics[m][j], 6) for m in keys]
            if extra:
                row.append(Num(np.asarray(training_relative_rms, dtype=float)[j], 6))
            rows.append(row)
        tables.append(
            table(headers, rows, "metrics-table" if k == 0 else f"metrics-table-log{k}", caption)
        )
    return Section("metrics", "Errors per joint", "\n".join(tables))


def _notes_section(warnings: Sequence[str], notes: Sequence[str]) -> Section:
    body = (
        "<h3>Warnings</h3>"
        + bullet_list(warnings, "warning-list")
        + "<h3>Notes (reading and preparing the log, the fit)</h3>"
        + bullet_list(notes, "note-list")
    )
    return Section("notes", "Warnings and notes", body)
