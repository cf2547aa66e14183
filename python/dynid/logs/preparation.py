"""Preparing a log for identification: the signal processing of :func:`prepare_log`.

:func:`prepare_log` applies the steps of :mod:`dynid.logs.signal` that the identification needs to a
:class:`dynid.Log` (spike removal, zero-phase low-pass, differentiation, decimation, outlier
and near-zero-velocity removal), each step only when asked and each recorded in ``Log.notes``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import positive, positive_int, real_array
from . import rest
from . import signal as sig
from ._iir import butterworth_lowpass, default_padding
from .edges import EDGE_FRACTION, edge_trim
from .log import SIGNALS, Log
from .timing import GAP_STEPS, measure_timing, resample_uniform, segments, uniform_grid


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
    nonuniform: str = "resample",
    trim_edges: bool = True,
    rest_velocity: float | str | ArrayLike | None = None,
) -> Log:
    """Signal processing for identification; each step only when asked, each noted in ``notes``.

    In this order:

    0. **Time base** (:mod:`dynid.logs.timing`): the jitter, dropped samples and gaps of ``t``
       are measured and noted whenever a step below is asked for or the grid is irregular.
       Steps 1, 2 and 4 treat the samples as equally spaced. When one of them runs, a gap (a
       step longer than ``GAP_STEPS`` median steps) splits the log into segments that go
       through steps 1-4 and 7 each on its own (no filter across a gap); the prepared log is
       their concatenation. A
       segment too short for the filter and its edge trim is dropped (noted). When steps 1, 2
       or 4 are asked for and the grid is not uniform (dropped samples, or more than
       ``JITTER_FRACTION`` of the steps off by more than ``JITTER_TOLERANCE``),
       ``nonuniform`` says what happens: ``"resample"`` (default) interpolates each segment
       onto a uniform grid of the median step first (q, qd, qdd by cubic spline, tau
       linearly: :func:`dynid.logs.timing.resample_uniform` says why); ``"refuse"`` raises a
       ValueError saying how to proceed; ``"ignore"`` filters as if uniform (the behaviour
       before dynid 0.3, for comparison; a gap is then an error). Differentiation alone needs
       no resampling: it uses the time stamps as they are.
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
    7. **Edge trim** (``trim_edges``, after step 4 of each segment, numbered by when it was
       added): the samples at both ends of every segment that the zero-phase filters' edge
       transients spoil are dropped, as many as :func:`dynid.logs.edges.edge_trim` derives from
       the filters' own impulse responses (the low-pass's and the anti-alias filter's, added).
       Only when a filter ran.
    5. **Outliers** with ``reference_tau``: samples where tau minus the reference deviates by more
       than ``outlier_k`` robust sigmas (median/MAD per joint) on any joint are dropped (lecture,
       "further practical hints": outliers eliminated in advance). ``reference_tau`` is either an
       array with one row per sample of the INPUT log (e.g. a first model's prediction on it;
       resampled, subsampled and trimmed with the log) or a callable taking the log after steps
       2-4 and 7 and returning its predicted (T, n) torque. The comparison is made on the
       processed torque, so the neighbours of an outlier that the filters smeared are dropped
       as well.
    6. **Near-zero velocity** (``min_velocity``, scalar or per joint): a sample is dropped when
       ANY joint has |qd| < min_velocity (lecture, "further practical hints": with friction in
       the model, discard data near zero velocity, where sign(qd) in Fs sign(qd) is ill-defined).
       :func:`dynid.logs.signal.moving_mask_min_velocity` with ``per_joint=True`` gives the
       per-joint masks for selecting rows of a stacked regressor instead (as
       :func:`dynid.identify_log` does).

    Between them and the removals, **joints at rest** (``rest_velocity``: a velocity, one per
    joint, or "auto"): qd_j = 0 where |qd_j| is below it, so that the Coulomb term is 0 while a
    joint stands still instead of +-Fs at random (:mod:`dynid.logs.rest`).

    Sample removals come last because filters, derivatives and decimation need the uniform grid.
    """
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    if differentiate not in ("missing", "always", "never"):
        raise ValueError(
            f"differentiate: expected 'missing', 'always' or 'never', got {differentiate!r}"
        )
    if nonuniform not in NONUNIFORM:
        raise ValueError(
            f"nonuniform: expected one of {', '.join(map(repr, NONUNIFORM))}, got {nonuniform!r}"
        )
    positions, fs_read = log.q, log.fs  # as read: the quantum of rest_velocity="auto"
    # "auto" estimates the noise of a velocity differentiated from the quantized angle; a log's
    # own velocities (a robot's estimate, e.g. libfranka's dq) are left as they are.
    differentiated = differentiate == "always" or (log.qd is None and differentiate != "never")
    if rest_velocity is not None and log.qd is None and differentiate == "never":
        raise ValueError("rest_velocity: needs qd, but the log has none and differentiate='never'")
    if not isinstance(trim_edges, (bool, np.bool_)):
        raise ValueError(f"trim_edges: expected True or False, got {trim_edges!r}")
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
    spikes_wanted = outlier_k is not None and reference_tau is None
    grid_steps = cutoff is not None or factor > 1 or spikes_wanted
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

    # 0. the time base: segments between gaps, resampled when irregular
    timing = measure_timing(log.t)
    step = timing.median_step
    if nonuniform == "ignore":
        parts = [slice(0, log.T)]
        resample = False
        if grid_steps:
            log.check_uniform("prepare_log (filtering, decimation, spike detection)")
    else:
        # Differentiation alone works on the stamps as they are (np.gradient: the parabola
        # through three neighbours, gaps included), so the log stays whole then, as before.
        parts = segments(log.t, timing.gaps) if grid_steps else [slice(0, log.T)]
        resample = grid_steps and not timing.uniform
        if resample and nonuniform == "refuse":
            raise ValueError(
                f"t: {timing.describe()}: the low-pass, decimation and spike detection need a "
                "uniform grid; resample it with nonuniform='resample' (--nonuniform resample), "
                "or filter it as if uniform with nonuniform='ignore' (--nonuniform ignore)"
            )
    opening: list[str] = []
    if grid_steps or not timing.uniform or timing.gaps:
        if resample:
            decision = (
                f"not uniform: resampled onto a uniform grid of {step:.4g} s (q, qd, qdd by "
                "cubic spline, tau linearly) before filtering"
            )
        elif not timing.uniform and grid_steps:
            decision = "not uniform, filtered as if uniform (nonuniform='ignore')"
        elif not timing.uniform:
            decision = "not uniform; differentiated on the time stamps as they are, not split"
        else:
            decision = "uniform"
        opening.append(f"{timing.describe()}: {decision}")
        if len(parts) > 1:
            lengths = ", ".join(str(p.stop - p.start) for p in parts)
            opening.append(
                f"split at {len(parts) - 1} gaps (steps longer than {GAP_STEPS:g} median steps) "
                f"into {len(parts)} segments of {lengths} samples, each prepared on its own"
            )

    # 1-4 and 7 per segment
    options = _SegmentOptions(
        cutoff,
        order,
        differentiate,
        factor,
        spikes_wanted,
        outlier_k,
        resample,
        step,
        bool(trim_edges),
        log.fs,
    )
    done: list[_Segment] = []
    for number, part in enumerate(parts, start=1):
        piece = log.slice(part.start, part.stop, note="")
        piece.notes = []
        ref = reference[part] if reference is not None else None
        prepared = _prepare_segment(piece, ref, options)
        if isinstance(prepared, str):
            opening.append(f"segment {number} ({piece.T} samples) dropped: {prepared}")
            continue
        done.append(prepared)
    if not done:
        raise ValueError(f"log: no segment long enough to prepare; {'; '.join(opening)}")
    longest = max(done, key=lambda s: s.log.T)
    steps_notes = longest.log.notes
    if len(parts) > 1:
        steps_notes = [
            f"each segment (as the longest, {longest.log.T} samples): {n}" for n in steps_notes
        ]
    whole = done[0].log if len(done) == 1 else _concatenate([s.log for s in done])
    # the prepared arrays, with the input's source, format and notes
    log = dataclasses.replace(
        whole, source=log.source, format=log.format, notes=log.notes + opening + steps_notes
    )
    spikes = np.concatenate([s.spikes for s in done])
    if reference is not None:
        reference = np.concatenate([s.reference for s in done if s.reference is not None])

    # Joints at rest: qd_j = 0 where |qd_j| is below the rest velocity (dynid.logs.rest).
    auto = isinstance(rest_velocity, str) and rest_velocity == "auto"
    if rest_velocity is not None and log.qd is not None and (differentiated or not auto):
        # the low-pass the velocities went through: the cutoff, or decimation's anti-alias one
        low_pass = (
            cutoff if cutoff is not None else (0.4 * fs_read / factor if factor > 1 else None)
        )
        velocity = rest.rest_velocity(rest_velocity, positions, fs_read, low_pass)
        still = rest.at_rest(log.qd, velocity)
        if still.any():
            counts = ", ".join(str(int(c)) for c in still.sum(axis=0))
            log = log.replace(
                qd=np.where(still, 0.0, log.qd),
                note=f"joints at rest: qd_j = 0 where |qd_j| < {np.round(velocity, 8).tolist()} "
                f"rad/s ({'estimated, ' if isinstance(rest_velocity, str) else ''}"
                f"rest_velocity); samples per joint: {counts}",
            )

    removals: list[tuple[NDArray[np.bool_], str]] = []  # (rows to drop, why), on the final grid
    if spikes_wanted:
        why = (
            f"whose torque as given deviated by more than {outlier_k:g} robust sigmas "
            "(median/MAD per joint) from the torque smoothed by a running median and a cubic "
            "Savitzky-Golay fit over ~0.1 s (replaced by the smoothed value before filtering)"
        )
        removals.append((spikes, why))

    # 5. outliers against a reference torque
    if reference_tau is not None and outlier_k is not None:
        if reference is not None:
            predicted = reference
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


#: What prepare_log does with a non-uniform grid before filtering (its ``nonuniform``).
NONUNIFORM = ("resample", "refuse", "ignore")


@dataclass(frozen=True)
class _SegmentOptions:
    cutoff: float | None
    order: int
    differentiate: str
    factor: int
    spikes: bool
    outlier_k: float | None
    resample: bool
    step: float  # the whole log's median step: every segment's grid
    trim: bool
    fs: float


@dataclass
class _Segment:
    log: Log
    reference: NDArray[np.float64] | None
    spikes: NDArray[np.bool_]


def _prepare_segment(
    log: Log, reference: NDArray[np.float64] | None, o: _SegmentOptions
) -> _Segment | str:
    """Steps 0-4 and 7 of prepare_log on one segment without gaps; a reason (str) when it is too
    short for them."""
    if o.resample:
        grid = uniform_grid(log.t, o.step)
        smooth = {k: getattr(log, k) for k in ("q", "qd", "qdd") if getattr(log, k) is not None}
        measured = {"tau": log.tau, **({"ref": reference} if reference is not None else {})}
        if grid.size < 4:
            return f"fewer than 4 samples on the uniform grid of {o.step:.4g} s"
        resampled: dict[str, Any] = resample_uniform(log.t, grid, smooth, measured)
        reference = resampled.pop("ref", None)
        log = log.replace(t=grid, **resampled)
    fs = 1.0 / o.step if o.resample else log.fs
    trims = []  # (filter, samples at the original rate)
    if o.cutoff is not None:
        trims.append(("low-pass", edge_trim(butterworth_lowpass(o.order, 2 * o.cutoff / fs))))
    band_limited = o.cutoff is not None and o.cutoff <= sig.ANTIALIAS_FRACTION * fs / (2 * o.factor)
    if o.factor > 1 and not band_limited:
        trims.append(
            ("anti-alias", edge_trim(butterworth_lowpass(8, sig.ANTIALIAS_FRACTION / o.factor)))
        )
    trim = -(-sum(k for _, k in trims) // o.factor) if o.trim else 0  # after decimation
    # sosfiltfilt's extension must be shorter than the signal; the trim must leave 2 samples
    padding = [default_padding(butterworth_lowpass(o.order, 0.5))] if o.cutoff is not None else []
    padding += [default_padding(butterworth_lowpass(8, 0.5))] if o.factor > 1 else []
    needed = max([p + 1 for p in padding] + [o.factor * (2 * trim + 2)])
    if needed > log.T:
        return f"shorter than the {needed} samples its filters and edge trim need"
    spikes: NDArray[np.bool_] = np.zeros(log.T, dtype=bool)

    # 1. spikes on the raw torque
    if o.spikes:
        assert o.outlier_k is not None
        flags, smoothed = sig.spike_mask(log.tau, fs, o.outlier_k)
        spikes = np.any(flags, axis=1)
        if spikes.any():
            log = log.replace(tau=np.where(flags, smoothed, log.tau))

    # 2. zero-phase low-pass, the same for every signal
    replaced = []
    if o.differentiate == "always":
        replaced = [k for k in ("qd", "qdd") if getattr(log, k) is not None]
        log = log.replace(qd=None, qdd=None)
    if o.cutoff is not None:
        names = [k for k in SIGNALS if getattr(log, k) is not None]
        filtered = {k: sig.lowpass(getattr(log, k), fs, o.cutoff, o.order) for k in names}
        log = log.replace(
            **filtered,
            note=f"low-pass zero-phase order-{o.order} Butterworth {o.cutoff:g} Hz "
            f"(sosfiltfilt, fs {fs:.4g} Hz) on {', '.join(names)}",
        )

    # 3. differentiation, of the filtered signals (prepare_log's docstring says why in this order)
    new: dict[str, NDArray] = {}
    if o.differentiate != "never" and log.qd is None:
        new["qd"] = sig.differentiate(log.q, log.t)
    if o.differentiate != "never" and log.qdd is None:
        qd = new.get("qd", log.qd)
        assert qd is not None  # measured, or differentiated just above
        new["qdd"] = sig.differentiate(qd, log.t)
    if new:
        source = ("low-passed " if o.cutoff is not None else "") + ("q" if "qd" in new else "qd")
        note = (
            f"{' and '.join(new)} computed by second-order central differences on t from "
            f"{source}" + (" (twice)" if len(new) == 2 else "")
        )
        if replaced:
            note += f", replacing the given {', '.join(replaced)}"
        log = log.replace(**new, note=note)

    # 4. decimation
    if o.factor > 1:
        log = decimate_log(log, o.factor, antialias=not band_limited)
        if band_limited:
            log.notes[-1] += f" (already band-limited by the {o.cutoff:g} Hz low-pass)"
        spikes = spikes[:: o.factor]
        if reference is not None:
            reference = reference[:: o.factor]

    # 7. the filters' edge transients
    if trim:
        how = " + ".join(f"{k} ({what})" for what, k in trims)
        log = log.slice(
            trim,
            log.T - trim,
            note=f"trimmed {trim} samples ({trim / log.fs:.4g} s) at both ends: the filters' edge "
            f"transients, where their zero-phase impulse responses ({how} samples at "
            f"{fs:.4g} Hz) stay above {EDGE_FRACTION:g} of their peak",
        )
        spikes = spikes[trim:-trim]
        if reference is not None:
            reference = reference[trim:-trim]
    return _Segment(log, reference, spikes)


def _concatenate(logs: list[Log]) -> Log:
    arrays: dict[str, Any] = {
        k: np.concatenate([getattr(s, k) for s in logs])
        for k in ("t", *SIGNALS)
        if getattr(logs[0], k) is not None
    }
    return Log(**arrays)


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
