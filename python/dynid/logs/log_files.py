"""Logs in and out: the checked measurement log, loading it in any registered format, and
saving it as NPZ or CSV.

A :class:`Log` holds time, joint positions and joint torques, with velocities and accelerations
when the recording has them. ``load_log`` finds the file's format in the registry
(:mod:`dynid.logs.formats`; the readers, one per format, are in :mod:`dynid.logs.readers`) and
adds what every format shares: ``skip`` and the plausibility of the time base. ``save_log``
writes dynid's NPZ and CSV (``docs/data.md``). Preparing a log for identification (filtering,
differentiation, decimation, dropping samples) is :mod:`dynid.logs.preparation`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import count, is_integer, positive, real_array
from .._equality import ValueEquality
from . import signal as sig
from .columns import check_columns, time_scale

#: A time step larger than this many median steps is a gap: filters and decimation assume a
#: uniform grid, which a log with samples removed no longer is.
GAP_FACTOR = 2.5

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
    format: str = ""  #: the recorded format's name (dynid.logs.formats), e.g. "UR RTDE CSV"

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
                check_finite(value, name)
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
        return Log(**values, source=self.source, notes=notes, format=self.format)

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
    # Non-finite values are reported by check_finite, with the row (and CSV line) they are on.
    return np.ascontiguousarray(real_array(value, name, finite=False))


def check_finite(arr: NDArray, name: str, rows: NDArray | None = None) -> None:
    """Raise naming the first row (with ``rows``: its line in the file) and joint(s) holding a NaN
    or inf."""
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
    current: bool = False,
    drop_nonfinite: bool = False,
    topic: str | None = None,
    joint_names: Sequence[str] | None = None,
    sample_time: float | None = None,
    skip_end: int = 0,
) -> Log:
    """Load a log in any registered format (``dynid.logs.formats``; docs/data.md): dynid's NPZ
    and CSV, UR RTDE, libfranka, pyfri/FRI, any CSV, MATLAB. The format is chosen by the suffix
    and the file's header and named in ``Log.format``.

    ``skip`` drops the first samples (e.g. a start-up transient; FloBaRoID's configuration for
    the LWR4+ logs skips 500); ``skip_end`` drops the last samples (e.g. a final rest; the
    filters' edge transients are trimmed by :func:`dynid.prepare_log` itself). ``columns`` maps
    signals of a foreign log to its columns or keys
    (``{"t": "stamp", "q": "pos_*", "tau": "effort_*"}``, :mod:`dynid.logs.columns`; a CSV
    without a header by column index, ``{"t": "0", "q": "1:8", "tau": "15:22"}``) and
    ``time_unit`` ("s", "ms", "us", "ns") says what the time stamps count; None reads the
    format's own unit (seconds, libfranka milliseconds). ``current`` reads motor currents as tau
    where the format records them (UR RTDE ``actual_current_i``). ``drop_nonfinite`` drops rows
    holding a NaN or inf (counted in the notes) instead of refusing the file. ``topic`` and
    ``joint_names`` are for ROS bags (the topic, and the model's joint names the message's joints
    are matched to). A log without a time vector (a motor-side recording such as the Staubli
    TX40's) needs ``sample_time`` [s], or an NPZ key ``sample_time``: t = 0, dt, 2 dt, ...
    Errors name the file and what is missing or malformed. A sampling rate no
    robot log has (outside PLAUSIBLE_RATE: nanosecond stamps read as seconds give 2e-7 Hz and a
    meaningless fit) is an error, unless ``time_unit`` was given (then a warning: the caller
    said what the stamps count); a position range no robot has is a warning.
    """
    from .formats import ReadOptions, detect

    path = Path(path)
    if not path.exists():  # a folder is a log too where a format reads one (ROS 2 bags)
        raise FileNotFoundError(f"path: no such file: {path}")
    skip = count(skip, "skip", 0)
    skip_end = count(skip_end, "skip_end", 0)
    if time_unit is not None:
        time_scale(time_unit)  # checked before the file is read
    if topic is not None and (not isinstance(topic, str) or not topic):
        raise ValueError(f"topic: expected a topic name, got {topic!r}")
    if joint_names is not None:
        if isinstance(joint_names, str) or not all(
            isinstance(name, str) and name for name in joint_names
        ):
            raise ValueError(f"joint_names: expected a sequence of names, got {joint_names!r}")
        joint_names = tuple(joint_names)
    if sample_time is not None:
        sample_time = positive(sample_time, "sample_time")  # seconds
    options = ReadOptions(
        sample_time=sample_time,
        columns=check_columns(columns) if columns is not None else None,
        time_unit=time_unit,
        current=bool(current),
        topic=topic,
        joint_names=joint_names,
        drop_nonfinite=bool(drop_nonfinite),
    )
    fmt = detect(path)
    if topic is not None and not fmt.topics:
        raise ValueError(f"topic: only for ROS bags, not {path.name} ({fmt.name})")
    try:
        log = fmt.read(path, options)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
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


# --------------------------------------------------------------------------- saving


def save_log(log: Log, path: PathLike) -> None:
    """Write a log as ``.npz`` (keys t, q, tau[, qd, qdd], notes) or ``.csv`` (docs/data.md).

    Values are written exactly (NPZ binary, CSV with 17 significant digits), so loading the
    file gives back the same arrays. The notes and the format go into the file (string arrays
    in NPZ, ``# note:`` and ``# format:`` lines in CSV) and come back on loading.
    """
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    path = Path(path)
    suffix = path.suffix.lower()
    present = [name for name in SIGNALS if getattr(log, name) is not None]
    if suffix == ".npz":
        arrays = {name: getattr(log, name) for name in ("t", *present)}
        with path.open("wb") as handle:  # a handle: np.savez would append ".npz" to "x.NPZ"
            if log.format:
                arrays["format"] = np.asarray(log.format)
            np.savez(handle, **arrays, notes=np.asarray(log.notes, dtype=str))
    elif suffix == ".csv":
        order = [name for name in ("q", "qd", "qdd", "tau") if name in present]
        header = ["t"] + [f"{name}{j}" for name in order for j in range(1, log.n + 1)]
        table = np.column_stack([log.t] + [getattr(log, name) for name in order])
        comments = ["# dynid log: t in s, q in rad or m, tau in N*m or N (docs/data.md)"]
        comments += [f"# format: {log.format}"] if log.format else []
        comments += [f"# note: {note}" for note in log.notes]
        with path.open("w", newline="") as handle:
            handle.write("\n".join(comments) + "\n" + ",".join(header) + "\n")
            np.savetxt(handle, table, delimiter=",", fmt="%.17g")
    else:
        raise ValueError(f"path: unknown extension {path.suffix!r}; expected .npz or .csv")
