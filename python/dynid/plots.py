"""PNG plots of identification results (matplotlib, Agg backend: no display needed)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import ArrayLike


def _grid(n: int, title: str, sharex: bool = True) -> tuple[Figure, list[Axes]]:
    rows = (n + 1) // 2
    fig, axes = plt.subplots(rows, 2, figsize=(11, 2.1 * rows + 0.6), sharex=sharex, squeeze=False)
    fig.suptitle(title)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    return fig, list(axes.ravel()[:n])


def _save(fig: Figure, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
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
    for ax, signal, label in zip(axes, (q, qd, qdd), ("q [rad]", "qd [rad/s]", "qdd [rad/s²]")):
        data = np.asarray(signal)
        for j in range(data.shape[1]):
            ax.plot(t, data[:, j], lw=1, label=f"J{j + 1}")
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
        ax.plot(t, measured[:, j], "--", color="tab:blue", lw=1.2, label="measured")
        ax.plot(t, predicted[:, j], color="tab:green", lw=1, label="predicted")
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
        ax.plot(t, residual[:, j], color="tab:red", lw=0.8)
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
    for ax, (label, (retrieved, estimated)) in zip(axes.ravel(), series.items()):
        k = np.arange(len(np.asarray(retrieved)))
        ax.plot(k, retrieved, color="tab:blue", lw=1.6, label="retrieved")
        ax.plot(k, estimated, "--", color="tab:green", lw=1.2, label="estimated")
        ax.set_xlabel("sample")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return _save(fig, path)
