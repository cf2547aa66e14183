"""The measurement log: :class:`Log` (time, joint positions and torques, velocities and
accelerations when recorded), checked on construction. Reading it from files is
:mod:`dynid.logs.log_files` (through the readers of :mod:`dynid.logs.readers`), preparing it for
identification :mod:`dynid.logs.preparation`; this module imports neither, so every reader can
build a Log without an import circle.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import is_integer, real_array
from .._equality import ValueEquality
from . import signal as sig

#: A time step larger than this many median steps is a gap: filters and decimation assume a
#: uniform grid, which a log with samples removed no longer is.
GAP_FACTOR = 2.5

SIGNALS = ("q", "tau", "qd", "qdd")  # the (T, n) arrays of a Log


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
