"""PNG plots of identification results (matplotlib, Agg backend: no display needed).

Long signals are drawn through :func:`envelope`: a 100k-sample log becomes at most
``MAX_POINTS`` + 2 points per line, keeping each bucket's minimum and maximum, so peaks and
spikes stay visible while drawing costs the same for a 10 s and a 10 min log. Margins are fixed
per figure (``subplots_adjust``) instead of ``tight_layout``, which draws every figure twice.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

#: Most points drawn per line: about two per horizontal pixel of a panel at the saved size.
MAX_POINTS = 2000
DPI = 110


def envelope(
    t: ArrayLike, y: ArrayLike, max_points: int = MAX_POINTS
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(t, y) reduced to at most ``max_points`` + 2 points for drawing: the samples are cut into
    ``max_points // 2`` consecutive buckets and each bucket keeps its minimum and its maximum, in
    time order (the min/max decimation of oscilloscopes), plus the first and the last sample.
    Short signals are returned unchanged."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    if len(y) <= max_points:
        return t, y
    size = -(-len(y) // max(1, max_points // 2))  # samples per bucket (ceil)
    buckets = -(-len(y) // size)
    # The last bucket is filled up with copies of the last sample: they change neither its
    # minimum nor its maximum, and their indices are clipped back to the last sample.
    padded = np.pad(y, (0, size * buckets - len(y)), mode="edge").reshape(buckets, size)
    lowest, highest = padded.argmin(axis=1), padded.argmax(axis=1)
    start = np.arange(buckets) * size
    first = start + np.minimum(lowest, highest)
    second = start + np.maximum(lowest, highest)
    index = np.minimum(np.stack([first, second], axis=1).ravel(), len(y) - 1)
    index = np.unique(np.concatenate([[0], index, [len(y) - 1]]))  # the line spans the whole t
    return t[index], y[index]


def _grid(n: int, title: str, sharex: bool = True) -> tuple[Figure, list[Axes]]:
    rows = (n + 1) // 2
    height = 2.1 * rows + 0.6
    fig, axes = plt.subplots(rows, 2, figsize=(11, height), sharex=sharex, squeeze=False)
    fig.suptitle(title)
    _margins(fig, height, hspace=0.25, wspace=0.22)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    return fig, list(axes.ravel()[:n])


def _margins(fig: Figure, height: float, hspace: float = 0.2, wspace: float = 0.2) -> None:
    """Room for the title (0.45 in), the x labels (0.5 in) and the y labels (0.75 in)."""
    width = fig.get_size_inches()[0]
    fig.subplots_adjust(
        left=0.75 / width,
        right=1 - 0.2 / width,
        top=1 - 0.45 / height,
        bottom=0.5 / height,
        hspace=hspace,
        wspace=wspace,
    )


def _save(fig: Figure, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def plot_joint_signals(
    t: ArrayLike,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    path: str | Path,
    title: str = "Joint motion",
) -> Path:
    """Positions, velocities and accelerations of all joints (as the paper's Fig. 3)."""
    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    fig.suptitle(title)
    _margins(fig, 8, hspace=0.12)
    for ax, signal, label in zip(axes, (q, qd, qdd), ("q [rad]", "qd [rad/s]", "qdd [rad/s²]")):
        data = np.asarray(signal)
        for j in range(data.shape[1]):
            ax.plot(*envelope(t, data[:, j]), lw=1, label=f"J{j + 1}")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(ncol=data.shape[1], fontsize=7, loc="upper right")
    axes[-1].set_xlabel("t [s]")
    return _save(fig, path)


def plot_torques(
    t: ArrayLike,
    measured: ArrayLike,
    predicted: ArrayLike,
    path: str | Path,
    title: str = "Measured and predicted joint torques",
) -> Path:
    """Measured (dashed) against predicted (solid) torque per joint (as the paper's Fig. 4)."""
    measured, predicted = np.asarray(measured), np.asarray(predicted)
    fig, axes = _grid(measured.shape[1], title)
    for j, ax in enumerate(axes):
        ax.plot(*envelope(t, measured[:, j]), "--", color="tab:blue", lw=1.2, label="measured")
        ax.plot(*envelope(t, predicted[:, j]), color="tab:green", lw=1, label="predicted")
        ax.set_ylabel(f"J{j + 1} [N m]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    for ax in axes[-2:]:
        ax.set_xlabel("t [s]")
    return _save(fig, path)


def plot_residuals(
    t: ArrayLike,
    residual: ArrayLike,
    path: str | Path,
    title: str = "Torque residuals (predicted - measured)",
) -> Path:
    """The prediction error per joint."""
    residual = np.asarray(residual)
    fig, axes = _grid(residual.shape[1], title)
    for j, ax in enumerate(axes):
        ax.plot(*envelope(t, residual[:, j]), color="tab:red", lw=0.8)
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_ylabel(f"J{j + 1} [N m]")
        ax.grid(alpha=0.3)
    for ax in axes[-2:]:
        ax.set_xlabel("t [s]")
    return _save(fig, path)


def plot_element_comparison(
    series: dict[str, tuple[ArrayLike, ArrayLike]],
    path: str | Path,
    title: str = "Retrieved and estimated model elements",
) -> Path:
    """Controller values against the identified model's, sample by sample, one panel per
    element, e.g. {"g_2(q)": (retrieved, estimated), "M_11(q)": (...)} (as the paper's Fig. 6)."""
    fig, axes = plt.subplots(1, len(series), figsize=(5.5 * len(series), 3.6), squeeze=False)
    fig.suptitle(title)
    _margins(fig, 3.6, wspace=0.3)
    for ax, (label, (retrieved, estimated)) in zip(axes.ravel(), series.items()):
        k = np.arange(len(np.asarray(retrieved)))
        ax.plot(*envelope(k, retrieved), color="tab:blue", lw=1.6, label="retrieved")
        ax.plot(*envelope(k, estimated), "--", color="tab:green", lw=1.2, label="estimated")
        ax.set_xlabel("sample")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return _save(fig, path)
