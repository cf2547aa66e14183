"""Checking an identified model: per-joint error metrics and the paper's table layout."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import real_array


def root_mean_square(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """sqrt(mean(x**2, axis=0)) without overflow or underflow of the squares: computed on x
    scaled by the power of two (exact) that brings its largest |value| into [0.5, 1)."""
    largest = float(np.abs(x).max()) if x.size else 0.0
    exponent = int(np.frexp(largest)[1]) if 0.0 < largest < np.inf else 0
    return np.ldexp(np.sqrt(np.mean(np.ldexp(x, -exponent) ** 2, axis=0)), exponent)


def error_metrics(measured: ArrayLike, predicted: ArrayLike) -> dict[str, NDArray[np.float64]]:
    """Per-column (joint) errors of ``predicted`` against ``measured``, both (T, n).

    Returns ``mse`` (mean square error, paper Table II), ``max_abs`` (maximum absolute error,
    Table III), ``rms``, ``relative_rms`` (rms error / rms of the measurement) and ``r2``
    (coefficient of determination, 1 - SSE / SST about the mean; NaN-free: 1.0 for a constant
    signal predicted exactly, -inf if it is not).
    """
    measured = np.atleast_2d(real_array(measured, "measured"))
    predicted = np.atleast_2d(real_array(predicted, "predicted"))
    if measured.size == 0:
        raise ValueError(
            f"measured: expected at least one sample (T, n) with T, n >= 1, got shape "
            f"{measured.shape}"
        )
    if measured.shape != predicted.shape:
        raise ValueError(
            f"predicted: expected the shape of measured {measured.shape}, got {predicted.shape}"
        )
    # Computed in units where the largest value is in [0.5, 1) (an exact power-of-two scaling),
    # so that the squares of values beyond ~1e154 do not overflow; scaled back at the end.
    largest = max(float(np.abs(measured).max()), float(np.abs(predicted).max()))
    exponent = int(np.frexp(largest)[1]) if largest > 0 else 0
    y: NDArray[np.float64] = np.ldexp(measured, -exponent)  # measured, scaled
    error: NDArray[np.float64] = np.ldexp(predicted, -exponent) - y
    sse = np.sum(error**2, axis=0)
    sst = np.sum((y - y.mean(axis=0)) ** 2, axis=0)
    rms_measured = root_mean_square(y)
    with np.errstate(divide="ignore", invalid="ignore"):
        r2 = np.where(sst > 0.0, 1.0 - sse / sst, np.where(sse == 0.0, 1.0, -np.inf))
        relative = np.where(
            rms_measured > 0.0,
            root_mean_square(error) / rms_measured,
            np.where(sse == 0.0, 0.0, np.inf),
        )
    with np.errstate(over="ignore"):
        mse = np.ldexp(np.mean(error**2, axis=0), 2 * exponent)
    if not np.all(np.isfinite(mse)):
        raise ValueError(
            f"measured, predicted: the mean square error overflows float64 (values up to "
            f"{largest:.3g}); express them in other units"
        )
    return {
        "mse": mse,
        "max_abs": np.ldexp(np.max(np.abs(error), axis=0), exponent),
        "rms": np.ldexp(root_mean_square(error), exponent),
        "relative_rms": relative,
        "r2": r2,
    }


def paper_table(
    title: str,
    columns: Mapping[str, ArrayLike],
    excluded: Sequence[int] = (),
    fmt: str = "{:.2e}",
) -> str:
    """A table in the layout of the paper's Tables II and III: one row per joint (J1, J2, ...),
    one column per data set (e.g. TS, VS, TVE); excluded joints show a dash."""
    names = list(columns)
    values = [np.asarray(columns[name], dtype=float) for name in names]
    n = len(values[0])
    width = max(10, *(len(name) + 2 for name in names))
    lines = [title, "      " + "".join(f"{name:>{width}}" for name in names)]
    for j in range(n):
        cells = ["–" if j in excluded else fmt.format(v[j]) for v in values]
        lines.append(f"  J{j + 1:<3}" + "".join(f"{c:>{width}}" for c in cells))
    return "\n".join(lines)


def validation_table(
    metrics: Mapping[str, NDArray[np.float64]],
    unit: str = "N m",
    training_relative_rms: Sequence[float] | None = None,
) -> str:
    """Per-joint RMS, relative RMS, maximum error and R^2 as an aligned text table; with
    ``training_relative_rms`` a last column compares with the fit on the training log."""
    n = len(metrics["rms"])
    head = f"  joint   rms [{unit}]   rel. rms   max [{unit}]        R2"
    lines = [head + ("   rel. rms on training log" if training_relative_rms is not None else "")]
    for j in range(n):
        trained = (
            f"{100 * training_relative_rms[j]:>26.2f}%" if training_relative_rms is not None else ""
        )
        lines.append(
            f"  J{j + 1:<5}{metrics['rms'][j]:>11.4g}{100 * metrics['relative_rms'][j]:>10.2f}%"
            f"{metrics['max_abs'][j]:>12.4g}{metrics['r2'][j]:>10.4f}{trained}"
        )
    return "\n".join(lines)
