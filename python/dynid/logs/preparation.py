"""Preparing a log for identification: the signal processing of :func:`prepare_log`.

:func:`prepare_log` applies the steps of :mod:`dynid.logs.signal` that the identification needs to a
:class:`dynid.Log` (spike removal, zero-phase low-pass, differentiation, decimation, outlier
and near-zero-velocity removal), each step only when asked and each recorded in ``Log.notes``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import positive, positive_int, real_array
from . import signal as sig
from .log_files import SIGNALS, Log


def prepare_log(
    log: Log,
    *,
    cutoff: float | None = None,
    order: int = 4,
    differentiate: str = "missing",
    decimate: int = 1,
    min_velocity: float | ArrayLike | None = None,
    outlier_k: float | None = None,
    reference_tau: ArrayLike | Callable[[Log], ArrayLike] | None = None,
) -> Log:
    """Signal processing for identification; each step only when asked, each noted in ``notes``.

    In this order:

    1. **Spikes** (``outlier_k`` without ``reference_tau``): torque samples deviating from a
       robustly smoothed torque (:func:`dynid.logs.signal.spike_mask`) by more than ``outlier_k``
       robust sigmas are found on the torque as given, where a spike is still sharp; they are
       replaced by the smoothed value so that filtering does not spread them, and the samples
       are dropped in step 5.
    2. **Low-pass** (``cutoff`` in Hz, ``order``): zero-phase Butterworth on q, tau and the
       given qd, qdd, the same filter for all, so that none is delayed relative to another.
    3. **Differentiation** (``differentiate``): ``"missing"`` computes qd from q and qdd from qd
       when absent, ``"always"`` recomputes both from q, ``"never"`` leaves them (possibly
       None); second-order differences on the log's time vector
       (:func:`dynid.logs.signal.differentiate`). The paper's eq. 33 experiment differentiates the
       positions twice and then filters (4th order, zero phase, 1 Hz); both operations are
       linear and time invariant, so the order does not matter in the middle of the log. It
       does at the ends: the filter extends the signal from its end value, and the end value
       of a twice-differentiated noisy position carries the noise amplified by 1/dt^2. With
       1e-4 rad of noise at 200 Hz, filtering first leaves a 20 times smaller qdd error 2 s
       from the ends, so q is filtered first and qd, qdd are derivatives of the filtered q.
    4. **Decimation** (``decimate`` = k): every k-th sample, after an anti-alias low-pass at 0.8 x
       the new Nyquist (:func:`dynid.logs.signal.decimate`), skipped when step 2 already low-passed
       below that.
    5. **Outliers** with ``reference_tau``: samples where tau minus the reference deviates by more
       than ``outlier_k`` robust sigmas (median/MAD per joint) on any joint are dropped (lecture,
       "further practical hints": outliers eliminated in advance). ``reference_tau`` is either an
       array with one row per sample of the INPUT log (e.g. a first model's prediction on it) or
       a callable taking the log after steps 2-4 and returning its predicted (T, n) torque. The
       comparison is made on the processed torque, so the neighbours of an outlier that the
       filters smeared are dropped as well.
    6. **Near-zero velocity** (``min_velocity``, scalar or per joint): a sample is dropped when
       ANY joint has |qd| < min_velocity (lecture, "further practical hints": with friction in
       the model, discard data near zero velocity, where sign(qd) in Fs sign(qd) is ill-defined).
       :func:`dynid.logs.signal.moving_mask_min_velocity` with ``per_joint=True`` gives the
       per-joint masks for selecting rows of a stacked regressor instead.

    Sample removals come last because filters, derivatives and decimation need the uniform grid.
    """
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    if differentiate not in ("missing", "always", "never"):
        raise ValueError(
            f"differentiate: expected 'missing', 'always' or 'never', got {differentiate!r}"
        )
    factor = positive_int(decimate, "decimate")
    order = positive_int(order, "order")
    if outlier_k is not None:
        outlier_k = positive(outlier_k, "outlier_k")
    elif reference_tau is not None:
        raise ValueError("reference_tau: given without outlier_k (the threshold in robust sigmas)")
    if cutoff is not None:
        cutoff = positive(cutoff, "cutoff")
        if cutoff >= log.fs / 2:
            raise ValueError(
                f"cutoff: expected 0 < cutoff < fs/2 = {log.fs / 2:g} Hz, got {cutoff:g} Hz"
            )
    if cutoff is not None or factor > 1 or (outlier_k is not None and reference_tau is None):
        log.check_uniform("prepare_log (filtering, decimation, spike detection)")
    if min_velocity is not None and log.qd is None and differentiate == "never":
        raise ValueError("min_velocity: needs qd, but the log has none and differentiate='never'")
    reference = None
    if reference_tau is not None and not callable(reference_tau):
        reference = real_array(reference_tau, "reference_tau")
        if reference.shape != log.tau.shape:
            raise ValueError(
                f"reference_tau: expected one row per sample of the input log, shape "
                f"{log.tau.shape}, got {reference.shape}"
            )
    index = np.arange(log.T)  # original sample numbers of the rows still present
    fs = log.fs
    spikes: NDArray[np.bool_] = np.zeros(log.T, dtype=bool)
    removals: list[tuple[NDArray[np.bool_], str]] = []  # (rows to drop, why), on the final grid

    # 1. spikes on the raw torque
    if outlier_k is not None and reference_tau is None:
        flags, smoothed = sig.spike_mask(log.tau, fs, outlier_k)
        spikes = np.any(flags, axis=1)
        if spikes.any():
            log = log.replace(tau=np.where(flags, smoothed, log.tau))

    # 2. zero-phase low-pass, the same for every signal
    replaced = []
    if differentiate == "always":
        replaced = [k for k in ("qd", "qdd") if getattr(log, k) is not None]
        log = log.replace(qd=None, qdd=None)
    if cutoff is not None:
        names = [k for k in SIGNALS if getattr(log, k) is not None]
        filtered = {k: sig.lowpass(getattr(log, k), fs, cutoff, order) for k in names}
        log = log.replace(
            **filtered,
            note=f"low-pass zero-phase order-{order} Butterworth {cutoff:g} Hz "
            f"(sosfiltfilt, fs {fs:.4g} Hz) on {', '.join(names)}",
        )

    # 3. differentiation, of the filtered signals (see the docstring for why in this order)
    new: dict[str, NDArray] = {}
    if differentiate != "never" and log.qd is None:
        new["qd"] = sig.differentiate(log.q, log.t)
    if differentiate != "never" and log.qdd is None:
        qd = new.get("qd", log.qd)
        assert qd is not None  # measured, or differentiated just above
        new["qdd"] = sig.differentiate(qd, log.t)
    if new:
        source = ("low-passed " if cutoff is not None else "") + ("q" if "qd" in new else "qd")
        note = (
            f"{' and '.join(new)} computed by second-order central differences on t from "
            f"{source}" + (" (twice)" if len(new) == 2 else "")
        )
        if replaced:
            note += f", replacing the given {', '.join(replaced)}"
        log = log.replace(**new, note=note)

    # 4. decimation
    if factor > 1:
        band_limited = cutoff is not None and cutoff <= sig.ANTIALIAS_FRACTION * fs / (2 * factor)
        log = decimate_log(log, factor, antialias=not band_limited)
        if band_limited:
            log.notes[-1] += f" (already band-limited by the {cutoff:g} Hz low-pass)"
        index = index[::factor]
        spikes = spikes[::factor]
    if outlier_k is not None and reference_tau is None:
        why = (
            f"whose torque as given deviated by more than {outlier_k:g} robust sigmas "
            "(median/MAD per joint) from the torque smoothed by a running median and a cubic "
            "Savitzky-Golay fit over ~0.1 s (replaced by the smoothed value before filtering)"
        )
        removals.append((spikes, why))

    # 5. outliers against a reference torque
    if reference_tau is not None and outlier_k is not None:
        if reference is not None:
            predicted = reference[index]
            what = "reference_tau (given)"
        else:
            assert callable(reference_tau)  # not an array, so the function (checked above)
            predicted = real_array(reference_tau(log), "reference_tau(log)")
            what = "reference_tau(log)"
            if predicted.shape != log.tau.shape:
                raise ValueError(
                    f"reference_tau(log): expected shape {log.tau.shape}, got {predicted.shape}"
                )
        spread = sig.MAD_TO_SIGMA * np.median(np.abs(log.tau - np.median(log.tau, axis=0)), axis=0)
        outliers = sig.outlier_mask(
            log.tau - predicted, outlier_k, min_sigma=sig.SPIKE_FLOOR * spread
        )
        flags = np.any(outliers, axis=1)
        why = (
            f"whose torque deviates from {what} by more than {outlier_k:g} robust sigmas "
            "(median/MAD per joint)"
        )
        removals.append((flags, why))

    # 6. near-zero velocity
    if min_velocity is not None and log.qd is not None:
        moving = sig.moving_mask_min_velocity(log.qd, min_velocity)
        why = (
            f"with |qd| < {np.round(np.asarray(min_velocity), 6)} on some joint (friction sign "
            "ill-defined near zero velocity)"
        )
        removals.append((~moving, why))

    if removals:
        dropped = np.logical_or.reduce([rows for rows, _ in removals])
        reasons = "; ".join(f"{int(rows.sum())} samples {why}" for rows, why in removals)
        if log.T - int(dropped.sum()) < 2:
            raise ValueError(f"prepare_log: fewer than 2 samples would remain; {reasons}")
        log = log.select(
            ~dropped, note=f"dropped {int(dropped.sum())} of {log.T} samples: {reasons}"
        )
    return log


def decimate_log(log: Log, factor: int, *, order: int = 8, antialias: bool = True) -> Log:
    """Every ``factor``-th sample of ``log`` (from the first), q, tau, qd and qdd low-passed first
    as :func:`dynid.logs.signal.decimate` does (the time vector is subsampled, never filtered); the
    step is recorded in ``notes``."""
    factor = positive_int(factor, "factor")
    order = positive_int(order, "order")
    if factor == 1:
        return log.slice(0, log.T, note="decimation by 1 (no change)")
    fs = log.fs
    if antialias:
        log.check_uniform("decimate")
    new = {
        name: (
            sig.decimate(getattr(log, name), factor, order=order, antialias=antialias)
            if getattr(log, name) is not None
            else None
        )
        for name in SIGNALS
    }
    names = ", ".join(k for k, v in new.items() if v is not None)
    cutoff = sig.ANTIALIAS_FRACTION / factor * fs / 2
    how = (
        f"after a zero-phase order-{order} Butterworth at {cutoff:.4g} Hz "
        f"({sig.ANTIALIAS_FRACTION} x the new Nyquist {fs / (2 * factor):.4g} Hz) on {names}"
        if antialias
        else "without anti-alias filter"
    )
    note = (
        f"decimated by {factor}: one sample in {factor} kept {how}; "
        f"{log.T} -> {len(log.t[::factor])} samples, fs {fs:.4g} -> {fs / factor:.4g} Hz"
    )
    return log.replace(t=log.t[::factor], **new, note=note)
