"""From the columns a reader found to the checked Log, the same way for every format: the
signals' columns (a format's own mapping, overridden by the caller's), non-finite rows dropped
(counted) or refused (naming the option), time order, the time unit."""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..columns import index_names, matching, readable, time_scale
from ..formats import ReadOptions
from ..log import Log, check_finite
from ..messages import name_list
from ._table import Table, numbers

#: Each signal's columns: a pattern (dynid.logs.columns) or a format's regular expression.
Spec = Mapping[str, "str | re.Pattern[str]"]

#: What the error for a non-finite value adds: the way out.
DROP_HINT = "; drop_nonfinite=True (--drop-nonfinite) drops such rows"


def table_log(
    path: Path,
    table: Table,
    options: ReadOptions,
    spec: Spec,
    *,
    fmt: str,
    unit: str = "s",
    time_from: tuple[Sequence[str], Callable[..., NDArray[np.float64]]] | None = None,
) -> Log:
    """The Log of ``table``: ``spec`` maps signals to columns, ``options.columns`` overrides it
    per signal (mapping ``q`` drops the format's ``qd`` and ``qdd``, which go with its ``q``);
    without a ``t`` in either, ``time_from`` = (column names, function of those columns) gives
    the time in seconds. ``unit`` is the time stamps' unit unless ``options.time_unit`` says."""
    if not table.has_header and not options.columns:
        raise ValueError(
            f"no header row (line {table.lines[0]} holds numbers): name the columns by "
            "0-based index, e.g. columns={'t': '0', 'q': '1:8', 'tau': '15:22'} "
            "(--columns t=0,q=1:8,tau=15:22)"
        )
    mapping: dict[str, str | re.Pattern[str]] = dict(spec)
    if options.columns:
        if "q" in options.columns:  # other joints: the format's velocities no longer belong
            mapping = {s: p for s, p in mapping.items() if s not in ("qd", "qdd")}
        mapping.update(options.columns)
    for required in ("q", "tau"):
        if required not in mapping:
            raise ValueError(f"columns: {required!r} missing from the mapping {_shown(mapping)}")
    found = _find(table, mapping, options, time_from is None and options.sample_time is None)
    used = sorted({c for names in found.values() for c in names})
    extra: list[int] = []
    if "t" not in found and time_from is not None and options.sample_time is None:
        if options.time_unit not in (None, "s"):
            raise ValueError(
                f"time_unit: {fmt}'s time is {' + '.join(time_from[0])} in seconds; map t to a "
                "column (columns / --columns) to read another unit"
            )
        extra = [table.column(name) for name in _require(table, time_from[0])]
    values = numbers(table, used + extra)
    position = {c: k for k, c in enumerate(used + extra)}

    def column(c: int) -> NDArray[np.float64]:
        return values[:, position[c]]

    arrays: dict[str, NDArray[np.float64]] = {}
    if "t" in found:
        arrays["t"] = column(found["t"][0])
    elif time_from is not None:
        arrays["t"] = time_from[1](*(column(c) for c in extra))
        unit = "s"
    for signal in ("q", "qd", "qdd", "tau"):
        if signal in found:
            arrays[signal] = np.column_stack([column(c) for c in found[signal]])
    shown = {s: _span([table.names[c] for c in cols]) for s, cols in found.items()}
    note = f"loaded from {path.name} ({fmt}, columns {shown})"
    return finish(
        arrays,
        path,
        options,
        fmt=table.format or fmt,
        note=note,
        notes=table.notes,
        lines=np.asarray(table.lines),
        unit=unit,
    )


def _find(
    table: Table, mapping: Mapping[str, str | re.Pattern[str]], options: ReadOptions, need_t: bool
) -> dict[str, list[int]]:
    """Each signal's column indices; ``t`` exactly one column."""
    if not table.has_header:
        assert options.columns
        if "t" not in options.columns and options.sample_time is None:
            raise ValueError(
                "columns: the file has no header; give the time's column too (t=0), or the "
                "sample time (sample_time / --sample-time)"
            )
        width = len(table.names)
        names = {s: index_names(str(p), width, s) for s, p in options.columns.items()}
    else:
        if need_t and "t" not in mapping:
            mapping = {"t": "t" if "t" in table.names else "times", **mapping}
        names = {s: matching(p, table.names, s) for s, p in mapping.items()}
    if "t" in names and len(names["t"]) != 1:
        pattern = mapping.get("t", "")
        shown = readable(pattern) if isinstance(pattern, re.Pattern) else pattern
        raise ValueError(
            f"columns: {shown!r} for t matches {name_list(names['t'])}; expected one time column"
        )
    return {s: [table.column(n) for n in found] for s, found in names.items()}


def _require(table: Table, names: Sequence[str]) -> list[str]:
    missing = [name for name in names if name not in table.names]
    if missing:
        raise ValueError(
            f"missing column(s) {', '.join(missing)}; found columns: {name_list(table.names)}"
        )
    return list(names)


def _span(names: list[str]) -> str:
    return names[0] if len(names) == 1 else f"{names[0]}..{names[-1]}"


def _shown(mapping: Mapping[str, str | re.Pattern[str]]) -> dict[str, str]:
    return {s: readable(p) if isinstance(p, re.Pattern) else p for s, p in mapping.items()}


def finish(
    arrays: dict[str, NDArray],
    path: Path,
    options: ReadOptions,
    *,
    fmt: str,
    note: str,
    notes: Sequence[str] = (),
    lines: NDArray | None = None,
    unit: str = "s",
) -> Log:
    """The checked Log of ``arrays`` (t, q, tau[, qd, qdd]) read from ``path`` in format
    ``fmt``. ``lines`` (text formats) are the data rows' line numbers, for the messages. Rows
    with a NaN or inf are dropped with ``options.drop_nonfinite`` (a note counts them), else
    refused naming the first one and the option."""
    added: list[str] = []
    if "t" in arrays and options.sample_time is not None:
        raise ValueError("sample_time: given, but the log has a time vector; give one of them")
    if "t" not in arrays:  # a recording of samples at a fixed rate (the Staubli TX40's)
        if options.sample_time is None:
            raise ValueError(
                "no time vector (key or column 't' or 'times'): give the sample time with "
                "sample_time / --sample-time, or an NPZ key 'sample_time'"
            )
        samples = len(np.asarray(arrays["q"]))
        arrays = {"t": np.arange(samples, dtype=float) * options.sample_time, **arrays}
        unit = "s"
        timeless = "no time vector: t = 0, dt, 2 dt, ... from the sample time"
    else:
        timeless = ""
    lengths = {len(a) for a in arrays.values()}
    if len(lengths) == 1 and all(np.ndim(a) in (1, 2) for a in arrays.values()):
        T = lengths.pop()
        bad: NDArray[np.bool_] = np.zeros(T, dtype=bool)
        for a in arrays.values():
            if np.asarray(a).dtype.kind in "fc":
                bad |= ~np.isfinite(np.asarray(a)).reshape(T, -1).all(axis=1)
        if bad.any():
            if not options.drop_nonfinite:
                for name, a in arrays.items():
                    try:
                        check_finite(np.asarray(a), name, rows=lines)
                    except ValueError as exc:
                        raise ValueError(f"{exc}{DROP_HINT}") from None
            first = int(np.nonzero(bad)[0][0])
            where = f"line {lines[first]}" if lines is not None else f"row {first}"
            arrays = {name: np.asarray(a)[~bad] for name, a in arrays.items()}
            lines = lines[~bad] if lines is not None else None
            added.append(
                f"dropped {int(bad.sum())} of {T} rows with non-finite values (the first at "
                f"{where}; drop_nonfinite)"
            )
    t = np.asarray(arrays["t"], dtype=float)
    repeated = np.nonzero(np.diff(t) == 0)[0]  # sample k+1 has the stamp of sample k
    if repeated.size:
        # A recorder that wrote a sample twice, or a clock that did not advance: the earlier of
        # two samples with one stamp is dropped (the later holds the newer values), and the
        # grid is then measured as any other (prepare_log resamples a non-uniform one).
        keep: NDArray[np.bool_] = np.ones(len(t), dtype=bool)
        keep[repeated] = False
        first = int(repeated[0])
        where = f"line {lines[first + 1]}" if lines is not None else f"row {first + 1}"
        arrays = {name: np.asarray(a)[keep] for name, a in arrays.items()}
        lines = lines[keep] if lines is not None else None
        added.append(
            f"dropped {repeated.size} of {len(t)} samples whose time stamp the next sample "
            f"repeats (the first at {where}; the later sample of each pair kept)"
        )
    if lines is not None:
        _check_rows(arrays["t"], lines)
    unit = options.time_unit or unit
    seconds = time_scale(unit)
    if seconds != 1.0:
        arrays = dict(arrays, t=np.asarray(arrays["t"], dtype=float) * seconds)
        added.append(f"time stamps in {unit}, converted to s")
    if timeless:
        added.append(timeless)
    return Log(**arrays, source=str(path), format=fmt, notes=[*notes, note, *added])


def _check_rows(t: NDArray, lines: NDArray) -> None:
    """At least 2 rows, the time strictly increasing: errors naming the line."""
    if len(lines) < 2:
        raise ValueError(f"expected at least 2 data rows, got {len(lines)}")
    backwards = np.nonzero(np.diff(t) <= 0)[0]
    if backwards.size:
        i = int(backwards[0]) + 1
        raise ValueError(
            f"t: not strictly increasing at line {lines[i]} (data row {i}): "
            f"t = {float(t[i])!r} after {float(t[i - 1])!r} on line {lines[i - 1]}"
        )
