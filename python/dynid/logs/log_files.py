"""Logs in and out: the checked measurement log, and loading and saving it as NPZ or CSV.

A :class:`Log` holds time, joint positions and joint torques, with velocities and accelerations
when the recording has them. Files are NPZ or CSV, laid out as in ``docs/data.md``; the
FloBaRoID key names of the real KUKA LWR4+ recordings (``times``, ``positions``, ...) are read as
they are. Preparing a log for identification (filtering, differentiation, decimation, dropping
samples) is :mod:`dynid.logs.preparation`.
"""

from __future__ import annotations

import csv
import re
import warnings
import zipfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import count, is_integer, real_array
from .._equality import ValueEquality
from . import signal as sig
from .columns import check_columns, matching, time_scale
from .messages import name_list, quote

#: A time step larger than this many median steps is a gap: filters and decimation assume a
#: uniform grid, which a log with samples removed no longer is.
GAP_FACTOR = 2.5

#: NPZ keys: the dynid name first, then the FloBaRoID name (measurements_*.npz of kjyv/FloBaRoID).
NPZ_KEYS = {
    "t": ("t", "times"),
    "q": ("q", "positions"),
    "qd": ("qd", "velocities"),
    "qdd": ("qdd", "accelerations"),
    "tau": ("tau", "torques"),
}
SIGNALS = ("q", "tau", "qd", "qdd")  # the (T, n) arrays of a Log

PathLike = Union[str, Path]


@dataclass(eq=False, repr=False)
class Log(ValueEquality):
    """A measurement log: t (T,), q and tau (T, n), optional qd and qdd (T, n).

    ``t`` is kept as recorded (it may start anywhere, e.g. at a Unix time). ``notes`` lists, in
    order and in words, what was done to the data since it was loaded. The arrays are checked on
    construction: shapes, finite values, t strictly increasing, at least 2 samples. Arrays are
    converted to float64 but not copied when they already are, so a Log derived by ``replace``
    shares the arrays it did not change: treat them as read-only.
    """

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    tau: NDArray[np.float64]
    qd: NDArray[np.float64] | None = None
    qdd: NDArray[np.float64] | None = None
    source: str = ""
    notes: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.t = _float_array(self.t, "t")
        if self.t.ndim != 1:
            raise ValueError(f"t: expected a 1-D time vector (T,), got shape {self.t.shape}")
        for name in SIGNALS:
            value = getattr(self, name)
            if value is None:
                if name in ("q", "tau"):
                    raise ValueError(f"{name}: missing (a log needs t, q and tau)")
                continue
            arr = _float_array(value, name)
            if arr.ndim != 2:
                raise ValueError(f"{name}: expected shape (T, n), got {arr.shape}")
            setattr(self, name, arr)
        lengths = {
            name: len(getattr(self, name))
            for name in ("t", *SIGNALS)
            if getattr(self, name) is not None
        }
        if len(set(lengths.values())) > 1:
            listed = ", ".join(f"{k} has {v}" for k, v in lengths.items())
            raise ValueError(f"length mismatch: every array needs one row per sample; {listed}")
        n = self.q.shape[1]
        for name in SIGNALS[1:]:
            value = getattr(self, name)
            if value is not None and value.shape[1] != n:
                raise ValueError(f"{name}: has {value.shape[1]} joints (columns) but q has {n}")
        if n < 1:
            raise ValueError("q: has no joints (0 columns)")
        for name in ("t", *SIGNALS):
            value = getattr(self, name)
            if value is not None:
                _check_finite(value, name)
        sig.check_time(self.t)
        self.notes = list(self.notes)

    # ------------------------------------------------------------------ shape and rate

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.q.shape[1])

    @property
    def T(self) -> int:
        """Number of samples."""
        return int(self.t.shape[0])

    @property
    def duration(self) -> float:
        """t[-1] - t[0], seconds."""
        return float(self.t[-1] - self.t[0])

    @property
    def fs(self) -> float:
        """Sampling rate, Hz: the median of 1/dt (robust to the odd late sample)."""
        return sig.sampling_rate(self.t)

    def __repr__(self) -> str:
        extra = "".join(f", {k}" for k in ("qd", "qdd") if getattr(self, k) is not None)
        return (
            f"Log(T={self.T}, n={self.n}, duration={self.duration:.4g} s, fs={self.fs:.4g} Hz, "
            f"q, tau{extra}, source={self.source!r}, {len(self.notes)} notes)"
        )

    # ------------------------------------------------------------------ new logs from this one

    def replace(self, *, note: str | None = None, **arrays: Any) -> Log:
        """A new, checked Log with some arrays replaced and ``note`` appended to the notes."""
        unknown = set(arrays) - {"t", *SIGNALS}
        if unknown:
            raise ValueError(
                f"arrays: unknown names {sorted(unknown)}; expected t, q, tau, qd, qdd"
            )
        values = {name: getattr(self, name) for name in ("t", *SIGNALS)}
        values.update(arrays)
        notes = self.notes + ([note] if note else [])
        return Log(**values, source=self.source, notes=notes)

    def select(self, mask: ArrayLike, *, note: str | None = None) -> Log:
        """The samples where the boolean ``mask`` (T,) is True (or at the given sorted indices).

        The time grid keeps its gaps: filter and differentiate before selecting samples.
        """
        mask = np.asarray(mask)
        if mask.dtype == bool:
            if mask.shape != (self.T,):
                raise ValueError(
                    f"mask: expected a boolean array of shape ({self.T},), got {mask.shape}"
                )
            kept = int(mask.sum())
        elif np.issubdtype(mask.dtype, np.integer) and mask.ndim == 1:
            if mask.size and (mask.min() < 0 or mask.max() >= self.T):
                raise ValueError(
                    f"mask: sample indices must lie in [0, {self.T}), got "
                    f"{mask.min()}..{mask.max()}"
                )
            kept = mask.size
        else:
            raise ValueError(
                f"mask: expected a boolean (T,) mask or 1-D integer indices, got {mask.dtype} "
                f"{mask.shape}"
            )
        if note is None:
            note = f"selected {kept} of {self.T} samples"
        arrays = {
            name: getattr(self, name)[mask]
            for name in ("t", *SIGNALS)
            if getattr(self, name) is not None
        }
        return self.replace(note=note, **arrays)

    def slice(
        self, start: int | None = None, stop: int | None = None, *, note: str | None = None
    ) -> Log:
        """Samples start:stop (Python slice semantics, negative indices allowed)."""
        for name, value in (("start", start), ("stop", stop)):
            if value is not None and not is_integer(value):
                raise ValueError(f"{name}: expected an integer or None, got {value!r}")
        lo, hi, _ = slice(start, stop).indices(self.T)
        if note is None:
            note = f"kept samples {lo}:{hi} of {self.T}"
        return self.select(np.arange(lo, max(lo, hi)), note=note)

    def check_uniform(self, what: str) -> None:
        """Raise if the grid has a gap (dt > GAP_FACTOR median dt), which ``what`` cannot handle."""
        dt = np.diff(self.t)
        gaps = np.nonzero(dt > GAP_FACTOR * np.median(dt))[0]
        if gaps.size:
            i = int(gaps[0])
            raise ValueError(
                f"t: {what} needs a uniformly sampled log, but there is a gap of {dt[i]:.4g} s "
                f"(median step {np.median(dt):.4g} s) after sample {i}; filter, differentiate and "
                "decimate before removing samples"
            )


def _float_array(value: Any, name: str) -> NDArray[np.float64]:
    # Non-finite values are reported by _check_finite, with the row (and CSV line) they are on.
    return np.ascontiguousarray(real_array(value, name, finite=False))


def _check_finite(arr: NDArray, name: str, rows: NDArray | None = None) -> None:
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.nonzero(bad.reshape(len(arr), -1).any(axis=1))[0][0])
        cols: NDArray[np.intp] | list[int] = (
            np.nonzero(bad[i].ravel())[0] + 1 if arr.ndim == 2 else []
        )
        joint = f", joint(s) {', '.join(str(c) for c in cols)}" if len(cols) else ""
        where = f"row {i}" if rows is None else f"line {rows[i]} (data row {i})"
        raise ValueError(f"{name}: non-finite value at {where}{joint}")


# --------------------------------------------------------------------------- loading


def load_log(
    path: PathLike,
    *,
    skip: int = 0,
    columns: Mapping[str, str] | None = None,
    time_unit: str | None = None,
    skip_end: int = 0,
) -> Log:
    """Load a log from an ``.npz`` or ``.csv`` file (formats in ``docs/data.md``).

    ``skip`` drops the first samples (e.g. a start-up transient; FloBaRoID's configuration for
    the LWR4+ logs skips 500); ``skip_end`` drops the last samples (e.g. a final rest; the
    filters' edge transients are trimmed by :func:`dynid.prepare_log` itself). ``columns`` maps
    signals of a foreign log to its columns or keys
    (``{"t": "stamp", "q": "pos_*", "tau": "effort_*"}``, :mod:`dynid.logs.columns`) and
    ``time_unit`` ("s", "ms", "us", "ns") says what the time stamps count; None reads seconds.
    Errors name the file and what is missing or malformed. A sampling rate no robot log has
    (outside PLAUSIBLE_RATE: nanosecond stamps read as seconds give 2e-7 Hz and a meaningless
    fit) is an error, unless ``time_unit`` was given (then a warning: the caller said what the
    stamps count); a position range no robot has is a warning.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"path: no such file: {path}")
    suffix = path.suffix.lower()
    if suffix not in (".npz", ".csv"):
        raise ValueError(
            f"path: unknown extension {path.suffix!r} of {path}; expected .npz or .csv"
        )
    skip = count(skip, "skip", 0)
    skip_end = count(skip_end, "skip_end", 0)
    mapping = check_columns(columns) if columns is not None else None
    seconds = time_scale("s" if time_unit is None else time_unit)
    try:
        log = _load_npz(path, mapping) if suffix == ".npz" else _load_csv(path, mapping)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
    if seconds != 1.0:
        log = log.replace(t=log.t * seconds, note=f"time stamps in {time_unit}, converted to s")
    if skip:
        if skip > log.T - 2:
            raise ValueError(f"skip: {skip} leaves fewer than 2 of the {log.T} samples of {path}")
        log = log.slice(skip, None, note=f"skipped the first {skip} samples")
    if skip_end:
        if skip_end > log.T - 2:
            raise ValueError(
                f"skip_end: {skip_end} leaves fewer than 2 of the {log.T} samples of {path}"
            )
        log = log.slice(0, log.T - skip_end, note=f"skipped the last {skip_end} samples")
    check_plausible(log, path.name, unit_given=time_unit is not None)
    return log


#: Sampling rates outside this band [Hz] are not a robot log read in the right time unit.
PLAUSIBLE_RATE = (1.0, 100e3)
#: |q| beyond this many radians (or metres) suggests degrees or encoder counts.
PLAUSIBLE_POSITION = 100.0


def check_plausible(log: Log, what: str, *, unit_given: bool) -> None:
    """Refuse a sampling rate outside PLAUSIBLE_RATE (a warning when the caller gave the time
    unit), and warn of positions beyond PLAUSIBLE_POSITION."""
    fs = log.fs
    if not PLAUSIBLE_RATE[0] <= fs <= PLAUSIBLE_RATE[1]:
        guess = "ns" if fs < 1e-3 else ("ms" if fs < 1.0 else "s")
        message = (
            f"{what}: t: the median sampling rate is {fs:.3g} Hz, implausible for a robot log "
            f"({PLAUSIBLE_RATE[0]:g} Hz to {PLAUSIBLE_RATE[1]:g} Hz)"
        )
        if not unit_given:
            raise ValueError(
                f"{message}: the time stamps are probably not in seconds (e.g. {guess!r}); "
                "give their unit with time_unit / --time-unit (s, ms, us, ns)"
            )
        warnings.warn(
            f"{message} with time stamps in the unit given; check time_unit / --time-unit",
            UserWarning,
            stacklevel=3,
        )
    largest = float(np.max(np.abs(log.q)))
    if largest > PLAUSIBLE_POSITION:
        warnings.warn(
            f"{what}: q: positions up to {largest:.4g}; dynid expects radians (or metres): "
            "degrees or encoder counts?",
            UserWarning,
            stacklevel=3,
        )


def _mapped_arrays(
    names: Sequence[str], get: Callable[[str], NDArray], mapping: Mapping[str, str]
) -> dict[str, NDArray]:
    """The signals named by ``mapping`` (columns/keys or glob patterns, :mod:`.columns`): one
    2-D array, or several 1-D ones stacked as joints in natural order; ``t`` is one 1-D array."""
    for required in ("q", "tau"):
        if required not in mapping:
            raise ValueError(f"columns: {required!r} missing from the mapping {dict(mapping)}")
    spec = {"t": "t" if "t" in names else "times", **mapping}
    arrays: dict[str, NDArray] = {}
    for signal, pattern in spec.items():
        found = matching(pattern, names, signal)
        parts = [np.asarray(get(name)) for name in found]
        if len(parts) == 1 and (signal == "t" or parts[0].ndim == 2):
            arrays[signal] = parts[0]
        elif signal != "t" and all(part.ndim == 1 for part in parts):
            arrays[signal] = np.column_stack(parts)
        else:
            expected = (
                "one time vector"
                if signal == "t"
                else "one (T, n) array or 1-D columns, one per joint"
            )
            raise ValueError(
                f"columns: {pattern!r} for {signal} matches {name_list(found)}; expected {expected}"
            )
    return arrays


def _load_npz(path: Path, mapping: Mapping[str, str] | None = None) -> Log:
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:  # all: "not an npz"
        raise ValueError(f"not a readable NPZ file ({type(exc).__name__}: {exc})") from None
    with data:
        found = list(data.files)
        _check_npz_members(path)
        arrays: dict[str, Any]
        if mapping is not None:
            arrays = _mapped_arrays(found, data.__getitem__, mapping)
            note = f"loaded from {path.name} (NPZ, columns {dict(mapping)})"
            return Log(**arrays, source=str(path), notes=[note])
        arrays = {}
        flobaroid = False
        for name, aliases in NPZ_KEYS.items():
            present = [key for key in aliases if key in found]
            if len(present) > 1:
                raise ValueError(f"both keys {present[0]!r} and {present[1]!r} given for {name}")
            if present:
                try:
                    arrays[name] = data[present[0]]
                except ValueError as exc:  # object arrays need pickle, refused on purpose
                    raise ValueError(f"key {present[0]!r}: unreadable ({exc})") from None
                flobaroid |= present[0] != name
        notes = [str(s) for s in data["notes"]] if "notes" in found else []
    for name in ("t", "q", "tau"):
        if name not in arrays:
            alias = NPZ_KEYS[name][1]
            raise ValueError(
                f"missing key {name!r} (or FloBaRoID {alias!r}); found keys: {name_list(found)}"
            )
    for name, arr in arrays.items():
        if arr.dtype.kind not in "iuf":
            raise ValueError(f"key for {name}: expected numbers, got dtype {arr.dtype}")
    how = "FloBaRoID key names" if flobaroid else "dynid key names"
    note = f"loaded from {path.name} (NPZ, {how}; {', '.join(arrays)})"
    return Log(**arrays, source=str(path), notes=[*notes, note])


def _check_npz_members(path: Path) -> None:
    """Refuse a member whose .npy header asks for more bytes than the member holds (a corrupt or
    hostile header would otherwise make NumPy try to allocate it) or that is not .npy at all."""
    with zipfile.ZipFile(path) as archive:
        for info in archive.infolist():
            if not info.filename.endswith(".npy"):
                raise ValueError(f"member {info.filename!r} is not a .npy array")
            with archive.open(info) as member:
                try:
                    version = np.lib.format.read_magic(member)
                    read = (
                        np.lib.format.read_array_header_1_0
                        if version == (1, 0)
                        else np.lib.format.read_array_header_2_0
                    )
                    shape, _, dtype = read(member)
                except (ValueError, OSError, EOFError) as exc:
                    raise ValueError(
                        f"member {info.filename!r}: unreadable header ({exc})"
                    ) from None
            needed = dtype.itemsize * int(np.prod(shape, dtype=object))
            if needed > info.file_size:
                raise ValueError(
                    f"member {info.filename!r}: its header asks for shape {shape} "
                    f"({needed} bytes) but the member holds {info.file_size} bytes"
                )


_CSV_COLUMN = re.compile(r"^(q|qd|qdd|tau)(\d+)$")


def _check_comma_separated(header: list[str], line: int) -> None:
    """Refuse a header that is one column of names separated by blanks (a UR RTDE recording,
    a MATLAB or spreadsheet export with another delimiter): dynid's CSV logs are comma-separated
    (docs/data.md)."""
    if len(header) != 1:
        return
    names = header[0].split()
    if len(names) > 1:
        raise ValueError(
            f"line {line}: the header is one column of {len(names)} names separated by blanks "
            f"({name_list(names)}); CSV logs are comma-separated (docs/data.md)"
        )


def _read_csv_table(path: Path) -> tuple[list[str], NDArray, list[int], list[str]]:
    """(header, values, line number of each data row, notes) of a CSV log."""
    header: list[str] | None = None
    header_line = 0
    notes: list[str] = []
    data: list[str] = []
    lines: list[int] = []
    with path.open(newline="") as handle:
        for number, line in enumerate(handle, start=1):
            text = line.strip()
            if text.startswith("# note:"):
                notes.append(text[len("# note:") :].strip())
            if not text or text.startswith("#"):
                continue
            if header is None:
                header = [f.strip() for f in next(csv.reader([text]))]
                header_line = number
                _check_comma_separated(header, header_line)
            else:
                data.append(text)
                lines.append(number)
    if header is None:
        raise ValueError("no header row (expected columns t, q1..qn, tau1..taun)")
    duplicates = sorted({c for c in header if header.count(c) > 1})
    if duplicates:
        raise ValueError(f"duplicate columns in the header: {', '.join(duplicates)}")
    try:  # fast path (C parser); on failure the loop below finds and names the bad line
        values = np.loadtxt(data, delimiter=",", ndmin=2, dtype=float) if data else None
        if values is not None and values.shape == (len(data), len(header)):
            return header, values, lines, notes
    except ValueError:
        pass
    values = np.empty((len(data), len(header)))
    for r, text in enumerate(data):
        fields = [f.strip() for f in next(csv.reader([text]))]
        if len(fields) != len(header):
            raise ValueError(
                f"line {lines[r]}: {len(fields)} fields, but the header (line {header_line}) "
                f"has {len(header)} columns"
            )
        for c, field_text in enumerate(fields):
            try:
                values[r, c] = float(field_text)
            except ValueError:
                raise ValueError(
                    f"line {lines[r]}, column {quote(header[c])}: "
                    f"cannot read {quote(field_text)} as a number"
                ) from None
    return header, values, lines, notes


def _load_csv(path: Path, mapping: Mapping[str, str] | None = None) -> Log:
    header, values, lines, notes = _read_csv_table(path)
    index = {name: c for c, name in enumerate(header)}
    arrays: dict[str, Any]
    if mapping is not None:
        arrays = _mapped_arrays(header, lambda name: values[:, index[name]], mapping)
        note = f"loaded from {path.name} (CSV, columns {dict(mapping)})"
        return Log(**arrays, source=str(path), notes=[*notes, note])
    if "t" not in index:
        raise ValueError(f"missing column 't'; found columns: {name_list(header)}")
    groups: dict[str, dict[int, int]] = {"q": {}, "qd": {}, "qdd": {}, "tau": {}}
    for name, c in index.items():
        match = _CSV_COLUMN.match(name)
        if match:
            groups[match.group(1)][int(match.group(2))] = c
    if not groups["q"]:
        raise ValueError(f"missing columns q1..qn; found columns: {name_list(header)}")
    n = max(groups["q"])
    arrays = {"t": values[:, index["t"]]}
    for name, columns in groups.items():
        if not columns:
            if name == "tau":
                raise ValueError(
                    f"missing columns tau1..tau{n}; found columns: {name_list(header)}"
                )
            continue
        wanted = range(1, n + 1)
        missing = [f"{name}{j}" for j in wanted if j not in columns]
        extra = [f"{name}{j}" for j in sorted(columns) if j not in wanted]
        if missing or extra:
            problem = f"missing {', '.join(missing)}" if missing else f"extra {', '.join(extra)}"
            raise ValueError(
                f"inconsistent joint columns: expected {name}1..{name}{n} (n = {n} from column "
                f"q{n}), {problem}; found columns: {name_list(header)}"
            )
        arrays[name] = values[:, [columns[j] for j in wanted]]
    line_numbers = np.asarray(lines)
    for name, arr in arrays.items():
        _check_finite(arr, name, rows=line_numbers)
    if len(lines) < 2:
        raise ValueError(f"expected at least 2 data rows, got {len(lines)}")
    backwards = np.nonzero(np.diff(arrays["t"]) <= 0)[0]
    if backwards.size:
        i = int(backwards[0]) + 1
        raise ValueError(
            f"t: not strictly increasing at line {lines[i]} (data row {i}): "
            f"t = {float(arrays['t'][i])!r} after {float(arrays['t'][i - 1])!r} on line "
            f"{lines[i - 1]}"
        )
    ignored = [c for c in header if c != "t" and not _CSV_COLUMN.match(c)]
    note = f"loaded from {path.name} (CSV, {', '.join(arrays)})"
    if ignored:
        note += f"; ignored columns {', '.join(ignored)}"
    return Log(**arrays, source=str(path), notes=[*notes, note])


# --------------------------------------------------------------------------- saving


def save_log(log: Log, path: PathLike) -> None:
    """Write a log as ``.npz`` (keys t, q, tau[, qd, qdd], notes) or ``.csv`` (docs/data.md).

    Values are written exactly (NPZ binary, CSV with 17 significant digits), so loading the
    file gives back the same arrays. The notes go into the file (a string array in NPZ,
    ``# note:`` lines in CSV) and come back on loading.
    """
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    path = Path(path)
    suffix = path.suffix.lower()
    present = [name for name in SIGNALS if getattr(log, name) is not None]
    if suffix == ".npz":
        arrays = {name: getattr(log, name) for name in ("t", *present)}
        with path.open("wb") as handle:  # a handle: np.savez would append ".npz" to "x.NPZ"
            np.savez(handle, **arrays, notes=np.asarray(log.notes, dtype=str))
    elif suffix == ".csv":
        order = [name for name in ("q", "qd", "qdd", "tau") if name in present]
        header = ["t"] + [f"{name}{j}" for name in order for j in range(1, log.n + 1)]
        table = np.column_stack([log.t] + [getattr(log, name) for name in order])
        comments = ["# dynid log: t in s, q in rad or m, tau in N*m or N (docs/data.md)"]
        comments += [f"# note: {note}" for note in log.notes]
        with path.open("w", newline="") as handle:
            handle.write("\n".join(comments) + "\n" + ",".join(header) + "\n")
            np.savetxt(handle, table, delimiter=",", fmt="%.17g")
    else:
        raise ValueError(f"path: unknown extension {path.suffix!r}; expected .npz or .csv")
