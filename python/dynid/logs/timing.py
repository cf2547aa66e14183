"""The time base of a log: how uniform it is, where it breaks, and a uniform grid when it is not.

The zero-phase filter, the decimation and the spike detection of :func:`dynid.prepare_log` treat
sample k as taken at t_0 + k dt. A log stepping 10 ms or 12 ms at random (UR10e controllers) is
then warped in time by up to 20 %, which a low-pass turns into errors in qd, qdd that no warning
reveals (issue 20: 8.7 % -> 34 % training error on joint 1). This module measures the time base
(:func:`measure_timing`), splits it at gaps (:func:`segments`) and puts a segment onto a uniform
grid (:func:`resample_uniform`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: A step is irregular when it differs from the median step by more than this fraction.
JITTER_TOLERANCE = 0.05
#: The grid counts as non-uniform when more than this fraction of its steps are irregular (or a
#: sample is dropped). The KUKA LWR4+ logs have 0.3 % of their steps more than 5 % off (the odd
#: late sample, at most 31 %): they stay as recorded; a UR10e log stepping 10 ms / 12 ms at
#: random has about half.
JITTER_FRACTION = 0.01
#: A step of at least this many median steps has dropped samples (round(dt / median) - 1).
DROPPED_STEP = 1.5
#: A step longer than this many median steps is a gap: the log is split there and each side is
#: prepared on its own (no filter across it). Shorter holes (up to 4 missing samples) are
#: bridged by the interpolation of :func:`resample_uniform`.
GAP_STEPS = 5.0


@dataclass(frozen=True)
class Timing:
    """What :func:`measure_timing` finds in a time vector (steps relative to the median step)."""

    median_step: float  #: s
    max_jitter: float  #: max |dt - median| / median over the steps that are neither drops nor gaps
    p99_jitter: float  #: its 99th percentile
    irregular_fraction: float  #: fraction of those steps off by more than JITTER_TOLERANCE
    dropped: int  #: samples missing in steps of DROPPED_STEP to GAP_STEPS median steps
    gaps: tuple[int, ...]  #: step indices i (between samples i and i + 1) longer than GAP_STEPS

    @property
    def uniform(self) -> bool:
        """True when the grid may be filtered as uniform: no dropped samples and at most
        JITTER_FRACTION of the steps off by more than JITTER_TOLERANCE (gaps aside: those
        split the log)."""
        return self.dropped == 0 and self.irregular_fraction <= JITTER_FRACTION

    def describe(self) -> str:
        """One line for the log's notes and the command line's output."""
        text = (
            f"time stamps: median step {self.median_step:.4g} s, jitter max "
            f"{100 * self.max_jitter:.3g} % (99th percentile {100 * self.p99_jitter:.3g} %), "
            f"{100 * self.irregular_fraction:.3g} % of the steps more than "
            f"{100 * JITTER_TOLERANCE:g} % off, {self.dropped} dropped samples"
        )
        if self.gaps:
            text += f", {len(self.gaps)} gaps longer than {GAP_STEPS:g} steps"
        return text


def measure_timing(t: NDArray[np.float64]) -> Timing:
    """The jitter, dropped samples and gaps of a strictly increasing time vector (T >= 2)."""
    dt = np.diff(np.asarray(t, dtype=float))
    median = float(np.median(dt))
    ratio = dt / median
    gaps = np.nonzero(ratio > GAP_STEPS)[0]
    dropping = (ratio >= DROPPED_STEP) & (ratio <= GAP_STEPS)
    dropped = int(np.sum(np.round(ratio[dropping]) - 1))
    ordinary = np.abs(ratio[ratio < DROPPED_STEP] - 1.0)
    if ordinary.size == 0:  # every step a drop or a gap: nothing to call jitter
        ordinary = np.zeros(1)
    return Timing(
        median_step=median,
        max_jitter=float(ordinary.max()),
        p99_jitter=float(np.percentile(ordinary, 99)),
        irregular_fraction=float(np.mean(ordinary > JITTER_TOLERANCE)),
        dropped=dropped,
        gaps=tuple(int(i) for i in gaps),
    )


def segments(t: NDArray[np.float64], gaps: tuple[int, ...]) -> list[slice]:
    """The sample ranges between the gaps (step i is between samples i and i + 1)."""
    bounds = [0, *(i + 1 for i in gaps), len(t)]
    return [slice(lo, hi) for lo, hi in zip(bounds[:-1], bounds[1:])]


def uniform_grid(t: NDArray[np.float64], step: float) -> NDArray[np.float64]:
    """t[0], t[0] + step, ... up to t[-1] (within a millionth of a step, so that a grid that
    is already uniform keeps its last sample)."""
    count = int(np.floor((t[-1] - t[0]) / step + 1e-6)) + 1
    return t[0] + step * np.arange(count)


def resample_uniform(
    t: NDArray[np.float64],
    grid: NDArray[np.float64],
    smooth: dict[str, NDArray[np.float64]],
    measured: dict[str, NDArray[np.float64]],
) -> dict[str, NDArray[np.float64]]:
    """The (T, n) signals at the times ``grid`` (inside [t[0], t[-1]]).

    ``smooth`` (q, and qd, qdd when the log has them) by a not-a-knot cubic spline: a motion is
    smooth, the spline's error is O(h^4 q'''') and it has continuous first and second
    derivatives, so that qd and qdd differentiated afterwards carry no kinks at the original
    stamps (a linear interpolation of q would put a jump in qd, a spike in qdd, at every one).
    ``measured`` (tau, a reference torque) linearly: a torque holds noise and, before the spike
    detection, spikes, which a cubic spline would spread as ringing over the neighbours; linear
    interpolation keeps a spike within two samples, and its error h^2 tau'' / 8 is far below
    what the low-pass that follows removes.
    """
    from scipy.interpolate import CubicSpline  # ~0.2 s to import: only for irregular logs

    out = {k: CubicSpline(t, v, axis=0)(grid) for k, v in smooth.items()}
    for k, v in measured.items():
        out[k] = np.column_stack([np.interp(grid, t, v[:, j]) for j in range(v.shape[1])])
    return out
