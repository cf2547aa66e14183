"""The figures of ``report.html`` as inline SVG (matplotlib's SVG backend, no display, no file).

Two things a report's torque plot must not do: join the samples on both sides of a hole (rows
dropped by the preparation, a gap of the time stamps, the rows of a joint left out by
``min_velocity``) with a straight line as if the arm had moved so, and grow with the log. So:

- :func:`with_gaps` puts NaN where rows are left out and between two samples further apart than
  ``DROPPED_STEP`` median steps (:mod:`dynid.logs.timing`'s threshold of a dropped sample): NaN
  breaks a matplotlib line, and the SVG path starts again with a new ``M``.
- :func:`envelope_with_gaps` decimates for drawing only, as :func:`dynid.export.plots.envelope`
  (each bucket's minimum and maximum, so spikes survive) and keeps the breaks: a bucket without
  holes gives its 2 extremes; a bucket with holes the extremes of its part before the first hole
  and after the last one, each side of a break, and those of the part in between as one short
  bar between two breaks (narrower than a bucket, less than a pixel). At most ``max_points`` + 2
  points per line whatever the log's length.

Text is SVG text (``svg.fonttype`` "none": the browser's font, smaller than glyph outlines),
the SVG's ids are salted per figure so that many figures live in one page, and no date is
written (the same run gives the same page).
"""

from __future__ import annotations

import io

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from ..logs.timing import DROPPED_STEP

#: Most points per drawn line (a bucket gives 2 to 8 points: MAX_POINTS // 8 buckets).
MAX_POINTS = 4000
#: Histogram bins: about sqrt(samples), within these bounds.
MIN_BINS, MAX_BINS = 10, 60


def with_gaps(
    t: ArrayLike, y: ArrayLike, keep: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(t, y) with y = NaN where ``keep`` is False, and a NaN point inserted between two samples
    more than ``DROPPED_STEP`` median steps apart (rows dropped or a gap of the log)."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float).copy()
    if keep is not None:
        y[~np.asarray(keep, dtype=bool)] = np.nan
    if t.size < 2:
        return t, y
    step = np.diff(t)
    jumps = np.flatnonzero(step > DROPPED_STEP * np.median(step))
    if jumps.size == 0:
        return t, y
    middle = 0.5 * (t[jumps] + t[jumps + 1])
    return np.insert(t, jumps + 1, middle), np.insert(y, jumps + 1, np.nan)


def envelope_with_gaps(
    t: ArrayLike, y: ArrayLike, max_points: int = MAX_POINTS
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(t, y), NaN marking breaks, reduced to at most ``max_points`` + 2 points for drawing (see
    the module docstring; the first and the last sample are kept); returned unchanged when it is
    no longer."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    if y.size <= max_points:
        return t, y
    buckets = max(1, max_points // 8)
    size = -(-y.size // buckets)  # samples per bucket (ceil)
    finite = np.isfinite(y)
    index: list[int] = []  # the samples drawn; a hole's own sample (NaN) is a break

    def extremes_of(a: int, b: int) -> None:
        kept = a + np.flatnonzero(finite[a:b])
        if kept.size:
            index.extend(_extremes(y, kept))

    # The extremes of the whole buckets at once (those with holes are redone below).
    whole = y.size // size
    body = np.where(finite, y, 0.0)[: whole * size].reshape(whole, size)
    start = np.arange(whole) * size
    lowest, highest = start + body.argmin(axis=1), start + body.argmax(axis=1)
    clean = finite[: whole * size].reshape(whole, size).all(axis=1)
    for k, lo in enumerate(range(0, y.size, size)):
        hi = min(lo + size, y.size)
        if k < whole and clean[k]:
            index.extend(sorted({int(lowest[k]), int(highest[k])}))
            continue
        holes = lo + np.flatnonzero(~finite[lo:hi])
        if holes.size == 0:
            extremes_of(lo, hi)
            continue
        first, last = int(holes[0]), int(holes[-1])
        extremes_of(lo, first)  # joined to the bucket before
        index.append(first)
        extremes_of(first + 1, last)  # the part between the holes: one bar, within the bucket
        if last > first:
            index.append(last)
        extremes_of(last + 1, hi)  # joined to the bucket after
    # The first and the last sample too, so that the line spans the whole time axis; the
    # indices are increasing already (each bucket's in time order), unique drops repeats.
    picked = np.unique(np.asarray([0, *index, y.size - 1], dtype=np.int64))
    hole = ~finite[picked]
    repeated = np.concatenate([[False], hole[1:] & hole[:-1]])  # one break is enough
    picked = picked[~repeated]
    return t[picked], y[picked]


def _extremes(y: NDArray[np.float64], where: NDArray[np.int64]) -> list[int]:
    """The indices (among ``where``) of the minimum and the maximum of y, in time order; one
    index when they are the same sample."""
    values = y[where]
    low, high = int(where[np.argmin(values)]), int(where[np.argmax(values)])
    return [low] if low == high else sorted((low, high))


def svg_of(fig: Figure, salt: str) -> str:
    """The figure as an ``<svg>`` element (no XML header), its ids salted with ``salt``."""
    buffer = io.StringIO()
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": salt}):
        fig.savefig(buffer, format="svg", metadata={"Date": None})
    svg = buffer.getvalue()
    return svg[svg.index("<svg") :]


def torque_figure(
    t: ArrayLike,
    measured: ArrayLike,
    predicted: ArrayLike,
    keep: ArrayLike | None,
    label: str,
    gid: str,
) -> str:
    """Measured (dashed) and predicted (solid) torque of one joint against time, holes as
    breaks; the lines' SVG groups are ``{gid}-measured`` and ``{gid}-predicted``."""
    fig = Figure(figsize=(9.0, 2.4))
    fig.subplots_adjust(left=0.09, right=0.99, top=0.88, bottom=0.2)
    ax = fig.add_subplot()
    t = np.asarray(t, dtype=float)
    for values, style, color, name in (
        (measured, "--", "tab:blue", "measured"),
        (predicted, "-", "tab:green", "predicted"),
    ):
        line_t, line_y = envelope_with_gaps(*with_gaps(t, values, keep))
        (line,) = ax.plot(line_t, line_y, style, color=color, lw=1.0, label=name)
        line.set_gid(f"{gid}-{name}")
    ax.set_title(label, fontsize=10)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("torque [N m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    return svg_of(fig, gid)


def histogram_figure(residual: ArrayLike, label: str, gid: str) -> str:
    """The histogram of one joint's residuals (predicted - measured, the rows kept); its SVG
    group is ``{gid}-bars``."""
    values = np.asarray(residual, dtype=float)
    values = values[np.isfinite(values)]
    fig = Figure(figsize=(4.2, 2.6))
    fig.subplots_adjust(left=0.17, right=0.97, top=0.87, bottom=0.2)
    ax = fig.add_subplot()
    bins = int(np.clip(round(np.sqrt(values.size)), MIN_BINS, MAX_BINS))
    # One filled outline (stairs) instead of a bar per bin: one SVG path, and drawn in a
    # fraction of the time of ``hist``'s bars.
    counts, edges = np.histogram(values, bins=bins)
    bars = ax.stairs(counts, edges, fill=True, color="tab:red", alpha=0.8)
    bars.set_gid(f"{gid}-bars")
    ax.axvline(0.0, color="k", lw=0.6)
    ax.set_title(label, fontsize=10)
    ax.set_xlabel("predicted - measured [N m]")
    ax.set_ylabel("samples")
    ax.grid(alpha=0.3)
    return svg_of(fig, gid)
