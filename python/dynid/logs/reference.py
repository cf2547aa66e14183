"""A controller's reference trajectory, read from a file and sampled at any instant.

The closed-loop estimators (IDIM-IV, DIDIM: docs/identification.md, "Estimators") simulate the
robot under the user's controller along the reference it tracked. The reference is a table on
the log's own clock (the same time stamps, the same unit):

- NPZ: keys ``t`` (T,) and ``q_d`` (T, n), optionally ``qd_d`` and ``qdd_d`` (T, n);
- CSV: a header row ``t,q_d1,...,q_dn[,qd_d1,...,qd_dn[,qdd_d1,...,qdd_dn]]`` then one row per
  instant (comment lines starting with ``#`` skipped).

Between its instants the reference is the cubic spline through q_d (not-a-knot ends); the
velocity and acceleration are the given ``qd_d``, ``qdd_d`` interpolated the same way, or the
spline's first and second derivatives when the file has none.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import real_array

SIGNALS = ("q_d", "qd_d", "qdd_d")


@dataclass(frozen=True, eq=False)
class SampledReference:
    """q_d (and optionally qd_d, qdd_d) at the instants ``t``, strictly increasing."""

    t: NDArray[np.float64]
    q_d: NDArray[np.float64]
    qd_d: NDArray[np.float64] | None = None
    qdd_d: NDArray[np.float64] | None = None
    source: str = ""

    def __post_init__(self) -> None:
        where = f" ({self.source})" if self.source else ""
        t = real_array(self.t, "reference t")
        if t.ndim != 1 or t.size < 4:
            raise ValueError(f"reference{where}: expected t of shape (T,), T >= 4, got {t.shape}")
        if np.any(np.diff(t) <= 0.0):
            raise ValueError(f"reference{where}: t must be strictly increasing")
        object.__setattr__(self, "t", t)
        for name in SIGNALS:
            value = getattr(self, name)
            if value is None:
                continue
            array = real_array(value, f"reference {name}")
            if array.ndim == 1:
                array = array[:, None]
            if array.shape[0] != t.size or array.ndim != 2:
                raise ValueError(
                    f"reference{where}: {name} needs one row per instant, shape ({t.size}, n), "
                    f"got {array.shape}"
                )
            if not np.all(np.isfinite(array)):
                raise ValueError(f"reference{where}: {name} holds NaN or inf")
            object.__setattr__(self, name, array)
        widths = {self.q_d.shape[1]} | {
            getattr(self, s).shape[1] for s in SIGNALS[1:] if getattr(self, s) is not None
        }
        if len(widths) != 1:
            raise ValueError(f"reference{where}: q_d, qd_d, qdd_d have different joint counts")

    @property
    def n(self) -> int:
        return int(self.q_d.shape[1])

    def __call__(self, t: ArrayLike) -> tuple[NDArray[np.float64], ...]:
        """(q_d, qd_d, qdd_d) at the instants ``t`` (K,), each (K, n); ValueError outside the
        table's time span (no extrapolation)."""
        from scipy.interpolate import CubicSpline

        times = np.asarray(t, dtype=float)
        span = (self.t[0], self.t[-1])
        slack = 1e-9 * max(1.0, abs(span[0]), abs(span[1]))
        if times.min() < span[0] - slack or times.max() > span[1] + slack:
            raise ValueError(
                f"reference: covers t in [{span[0]:.9g}, {span[1]:.9g}], the log needs "
                f"[{times.min():.9g}, {times.max():.9g}] (the reference must be on the log's clock)"
            )
        times = np.clip(times, *span)
        spline = CubicSpline(self.t, self.q_d, axis=0)
        q_d = spline(times)
        qd_d = spline(times, 1) if self.qd_d is None else CubicSpline(self.t, self.qd_d)(times)
        if self.qdd_d is not None:
            qdd_d = CubicSpline(self.t, self.qdd_d)(times)
        elif self.qd_d is not None:
            qdd_d = CubicSpline(self.t, self.qd_d)(times, 1)
        else:
            qdd_d = spline(times, 2)
        return q_d, qd_d, qdd_d


def load_reference(path: str | Path) -> SampledReference:
    """Read a reference trajectory file (NPZ or CSV, this module's docstring)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"reference: no such file {str(path)!r}")
    if path.suffix.lower() == ".npz":
        arrays = _npz(path)
    elif path.suffix.lower() == ".csv":
        arrays = _csv(path)
    else:
        raise ValueError(f"reference: {path.name}: expected an .npz or .csv file")
    if "t" not in arrays or "q_d" not in arrays:
        raise ValueError(f"reference: {path.name}: needs t and q_d, found {sorted(arrays)}")
    return SampledReference(
        arrays["t"],
        arrays["q_d"],
        arrays.get("qd_d"),
        arrays.get("qdd_d"),
        source=path.name,
    )


def _npz(path: Path) -> dict[str, NDArray[np.float64]]:
    try:
        with np.load(path, allow_pickle=False) as data:
            return {k: np.asarray(data[k], dtype=float) for k in ("t", *SIGNALS) if k in data}
    except (OSError, ValueError, TypeError) as exc:
        raise ValueError(f"reference: {path.name}: not a readable NPZ file ({exc})") from None


def _csv(path: Path) -> dict[str, NDArray[np.float64]]:
    lines = [
        line
        for line in path.read_text(encoding="utf-8").splitlines()
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if len(lines) < 2:
        raise ValueError(f"reference: {path.name}: expected a header row and data rows")
    header = [h.strip() for h in lines[0].split(",")]
    try:
        table = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    except ValueError as exc:
        raise ValueError(f"reference: {path.name}: a value is not a number ({exc})") from None
    if table.ndim != 2 or table.shape[1] != len(header):
        raise ValueError(f"reference: {path.name}: every row needs {len(header)} values")
    arrays: dict[str, NDArray[np.float64]] = {}
    if "t" in header:
        arrays["t"] = table[:, header.index("t")]
    for signal in SIGNALS:
        pattern = re.compile(rf"{signal}(\d+)\Z")
        joints = sorted(
            (int(m.group(1)), k) for k, h in enumerate(header) if (m := pattern.match(h))
        )
        if joints:
            if [j for j, _ in joints] != list(range(1, len(joints) + 1)):
                raise ValueError(
                    f"reference: {path.name}: columns {signal}1..{signal}n expected, got "
                    f"{[f'{signal}{j}' for j, _ in joints]}"
                )
            arrays[signal] = table[:, [k for _, k in joints]]
    return arrays
