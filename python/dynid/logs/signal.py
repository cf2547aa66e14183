"""Signal processing for identification logs: filtering, differentiation, decimation, masks.

The identification of the paper (Gaz, Flacco, De Luca, ICRA 2014) treats its torque validation
experiment (eq. 33) this way: joint positions differentiated twice numerically, then positions,
velocities, accelerations and torques filtered by a 4th-order zero-phase Butterworth filter with
a 1 Hz cutoff. Zero phase matters because the regressor Y(q, qd, qdd) and the measured torque are
compared sample by sample: a causal filter delays each signal by its group delay, and any relative
delay between the regressor's inputs and tau shows up as a model error. The lecture's "further
practical hints" on least-squares identification (Robotics 2, identification, p. 28) add the two
masks here: outliers can be eliminated in advance, and when the friction model is not rich enough,
data collected at joint velocities close to zero are discarded.

Every function works along ``axis`` (default 0, the time axis of a (T, n) trajectory) and raises
``ValueError`` naming the offending argument.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import is_integer, positive, positive_int, real_array
from ._iir import PadType, butterworth_lowpass, default_padding, zero_phase

#: Anti-aliasing cutoff of :func:`decimate` as a fraction of the new Nyquist frequency (the value
#: scipy.signal.decimate uses): the band kept is undistorted, the band folded back is attenuated.
ANTIALIAS_FRACTION = 0.8

#: 1.4826 * MAD estimates the standard deviation of Gaussian data (1 / Phi^-1(3/4)).
MAD_TO_SIGMA = 1.482602218505602

#: :func:`spike_mask` never calls a deviation below this fraction of the signal's robust spread
#: an outlier: data that are already smooth (the KUKA logs went through median and Butterworth
#: filters) leave a residual near round-off, whose MAD would make any wiggle look wild.
SPIKE_FLOOR = 1e-3


# --------------------------------------------------------------------------- checks


def _array(x: ArrayLike, name: str, min_ndim: int = 1) -> NDArray[np.float64]:
    arr = real_array(x, name)
    if arr.ndim < min_ndim:
        raise ValueError(
            f"{name}: expected at least {min_ndim} dimension(s), got shape {arr.shape}"
        )
    return arr


def _axis(x: NDArray, axis: int, name: str = "x") -> int:
    if not is_integer(axis):
        raise ValueError(f"axis: expected an integer, got {axis!r}")
    if not -x.ndim <= axis < x.ndim:
        raise ValueError(f"axis: {axis} is out of range for {name} with shape {x.shape}")
    return int(axis) % x.ndim


def _per_column(value: ArrayLike, name: str, columns: int, what: str) -> NDArray[np.float64]:
    """A non-negative scalar or one value per column, as an array."""
    array = _array(value, name, min_ndim=0)
    if array.ndim > 1 or (array.ndim == 1 and array.size != columns):
        raise ValueError(
            f"{name}: expected a scalar or one value per {what} ({columns},), "
            f"got shape {array.shape}"
        )
    if (array < 0).any():
        raise ValueError(f"{name}: expected values >= 0, got {array}")
    return array


def _sosfiltfilt(
    x: NDArray,
    sos: NDArray,
    axis: int,
    order: int,
    name: str,
    padtype: PadType = "odd",
    padlen: int | None = None,
) -> NDArray:
    """Zero-phase filtering along ``axis`` (scipy.signal.sosfiltfilt's, :mod:`dynid.logs._iir`) with
    a readable error when x is shorter than the filter's edge padding."""
    if padlen is None:
        padlen = default_padding(sos)
    if padtype not in ("odd", "even", "constant"):
        raise ValueError(f"padtype: expected 'odd', 'even' or 'constant', got {padtype!r}")
    if x.shape[axis] <= padlen:
        raise ValueError(
            f"{name}: {x.shape[axis]} samples along axis {axis} are too few for an order-{order} "
            f"zero-phase filter, which extends the signal by {padlen} samples at each end; "
            f"need at least {padlen + 1}"
        )
    columns = np.moveaxis(x, axis, 0)
    shape = columns.shape
    filtered = zero_phase(sos, columns.reshape(shape[0], -1), padtype, padlen)
    return np.moveaxis(filtered.reshape(shape), 0, axis)


# --------------------------------------------------------------------------- filtering


def lowpass(
    x: ArrayLike,
    fs: float,
    cutoff: float,
    order: int = 4,
    axis: int = 0,
    padtype: PadType = "odd",
    settle: bool = False,
) -> NDArray:
    """Zero-phase low-pass Butterworth filter (forward and backward, ``sosfiltfilt``).

    Parameters
    ----------
    x
        Signal, time along ``axis`` (e.g. a (T, n) trajectory). Sampling is taken as uniform.
    fs
        Sampling rate in Hz (see :func:`sampling_rate`).
    cutoff
        Cutoff frequency in Hz, 0 < cutoff < fs / 2.
    order
        Order of the Butterworth design (4 in the paper's eq. 33 experiment).
    padtype
        How the signal is extended at both ends before filtering: ``"odd"`` (scipy's default,
        keeps a linear trend) or ``"even"`` (mirror image: the natural choice for a motion that
        starts and ends at rest).
    settle
        Extend by ~3 time constants of the filter (3 fs / cutoff samples, at most the signal
        length - 1) instead of scipy's few samples, so that the backward pass starts settled; a
        low cutoff otherwise leaves a transient of several per cent at the end.

    Running the filter forwards and backwards cancels its phase, so nothing is delayed (the
    paper's "zero-phase digital Butterworth filter"). It also squares the magnitude response:
    the result attenuates like a Butterworth of order ``2 * order``, with a gain of 1/2 (-6 dB)
    rather than 1/sqrt(2) at ``cutoff``. Second-order sections keep high orders and low cutoffs
    numerically stable. The ends are handled by scipy's odd extension, so the first and last
    ~3 / cutoff seconds are less reliable than the middle.
    """
    arr = _array(x, "x")
    ax = _axis(arr, axis)
    fs = positive(fs, "fs")
    cutoff = positive(cutoff, "cutoff")
    order = positive_int(order, "order")
    if cutoff >= fs / 2:
        raise ValueError(
            f"cutoff: expected 0 < cutoff < fs/2 = {fs / 2:g} Hz (Nyquist), got {cutoff:g} Hz"
        )
    sos = butterworth_lowpass(order, 2.0 * cutoff / fs)
    padlen = min(int(3 * fs / cutoff), arr.shape[ax] - 1) if settle else None
    return _sosfiltfilt(arr, sos, ax, order, "x", padtype=padtype, padlen=padlen)


def sampling_rate(t: ArrayLike) -> float:
    """The median of 1/dt of a strictly increasing time vector, in Hz.

    The median ignores the occasional late or early sample of a real-time log (the KUKA logs have
    dt between 3.3 and 6.8 ms around a 5 ms median).
    """
    t = check_time(t)
    return float(1.0 / np.median(np.diff(t)))


def check_time(t: ArrayLike, name: str = "t") -> NDArray[np.float64]:
    """t as a 1-D float array, checked finite, with at least 2 samples and strictly increasing."""
    t = _array(t, name)
    if t.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D time vector (T,), got shape {t.shape}")
    if t.size < 2:
        raise ValueError(f"{name}: expected at least 2 samples, got {t.size}")
    dt = np.diff(t)
    bad = np.nonzero(dt <= 0)[0]
    if bad.size:
        i = int(bad[0]) + 1
        raise ValueError(
            f"{name}: not strictly increasing at sample {i} "
            f"({name}[{i}] = {float(t[i])!r} <= {name}[{i - 1}] = {float(t[i - 1])!r})"
        )
    return t


# --------------------------------------------------------------------------- differentiation


def differentiate(
    x: ArrayLike, t: ArrayLike | None = None, fs: float | None = None, axis: int = 0
) -> NDArray:
    """Numerical time derivative, second-order accurate, on a uniform or non-uniform grid.

    Give either the sample times ``t`` (T,) or a uniform sampling rate ``fs``. Interior samples
    use central differences, which on a non-uniform grid are the derivative of the parabola
    through three neighbours (``np.gradient`` with the time vector): the error is
    -h1 h2 x'''/6, second order in the step whether or not the grid is uniform. The two end
    samples use one-sided second-order formulas (``edge_order=2``) when there are at least three
    samples. Differentiation amplifies noise in proportion to frequency, so low-pass as the
    paper does for its eq. 33 experiment; filtering the input rather than the result gives the
    same middle and quieter ends (see :func:`dynid.prepare_log`).
    """
    arr = _array(x, "x")
    ax = _axis(arr, axis)
    if (t is None) == (fs is None):
        raise ValueError("t, fs: give exactly one of the time vector t and the sampling rate fs")
    length = arr.shape[ax]
    if length < 2:
        raise ValueError(f"x: expected at least 2 samples along axis {ax}, got {length}")
    edge_order = 2 if length >= 3 else 1
    if fs is not None:
        step = 1.0 / positive(fs, "fs")
        return _finite_result(np.gradient, arr, step, axis=ax, edge_order=edge_order)
    assert t is not None  # exactly one of t and fs (checked above)
    t = check_time(t)
    if t.size != length:
        raise ValueError(f"t: has {t.size} samples but x has {length} along axis {ax}")
    return _finite_result(np.gradient, arr, t, axis=ax, edge_order=edge_order)


def _finite_result(gradient: Any, arr: NDArray, *args: Any, **kwargs: Any) -> NDArray:
    # Differences of huge finite values (or tiny time steps) overflow: a ValueError naming the
    # input, never inf/NaN with only a RuntimeWarning.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        result = gradient(arr, *args, **kwargs)
    if not np.all(np.isfinite(result)):
        raise ValueError("x: the derivative overflows (values too large for their time steps)")
    return result


# --------------------------------------------------------------------------- decimation


def decimate(*data: Any, factor: int | None = None, order: int = 8, antialias: bool = True) -> Any:
    """Keep every ``factor``-th sample (from the first), after an anti-aliasing low-pass.

    Forms::

        decimate(x, factor)                -> array
        decimate(x1, x2, ..., factor)      -> tuple of arrays (time along axis 0)

    (``factor`` may also be given by keyword.) Before subsampling, each signal is low-passed by a
    zero-phase Butterworth of order ``order`` at 0.8 times the new Nyquist frequency
    (``ANTIALIAS_FRACTION``), so content that the new rate cannot represent is removed instead of
    folding back onto low frequencies; the cutoff is relative, so arrays need no sampling rate.
    Pass ``antialias=False`` only for signals already band-limited below that (e.g. a log
    low-passed at a lower cutoff). A time vector must not be filtered: subsample
    ``t[::factor]`` yourself, or decimate a whole log with
    :func:`dynid.logs.preparation.decimate_log`.
    """
    if factor is None and len(data) >= 2 and is_integer(data[-1]):
        data, factor = data[:-1], data[-1]
    if factor is None:
        raise ValueError("factor: missing; call decimate(x, factor)")
    factor = positive_int(factor, "factor")
    order = positive_int(order, "order")
    if not data:
        raise ValueError("data: nothing to decimate")
    wn = ANTIALIAS_FRACTION / factor  # cutoff in units of the old Nyquist frequency

    def one(x: ArrayLike, name: str) -> NDArray:
        arr = _array(x, name)
        if factor == 1:
            return arr.copy()
        if antialias:
            sos = butterworth_lowpass(order, wn)
            arr = _sosfiltfilt(arr, sos, 0, order, name)
        return np.ascontiguousarray(arr[::factor])

    out = tuple(one(x, f"data[{i}]") for i, x in enumerate(data))
    return out[0] if len(out) == 1 else out


# --------------------------------------------------------------------------- masks


def moving_mask_min_velocity(
    qd: ArrayLike, threshold: float | ArrayLike, *, per_joint: bool = False
) -> NDArray[np.bool_]:
    """Samples where the joints move at least ``threshold`` (|qd| >= threshold).

    Lecture, "further practical hints": if the friction model in Y is not rich enough, discard
    the data collected at joint velocities close to zero. Coulomb friction Fs sign(qd) jumps at
    qd = 0 (and stiction is not modelled at all), so near zero velocity the measured friction is
    whatever the sign of a noisy qd makes it.

    Parameters
    ----------
    qd
        Joint velocities (T, n), or (T,) for one joint.
    threshold
        A scalar, or one value per joint (n,), in the units of qd (rad/s, m/s); >= 0.
    per_joint
        False (default): a (T,) mask, True where EVERY joint has |qd_j| >= threshold_j, i.e. a
        sample is dropped when any joint is slow; this is what selecting whole samples (rows
        t_k of a log, as :func:`dynid.prepare_log` does) needs. True: the (T, n) mask of each
        joint separately, for selecting rows of the stacked regressor joint by joint (the
        friction of joint j appears only in joint j's rows), which keeps more data.
    """
    qd = _array(qd, "qd")
    if qd.ndim > 2:
        raise ValueError(f"qd: expected shape (T, n) or (T,), got {qd.shape}")
    columns = qd.reshape(qd.shape[0], -1)
    thr = _per_column(threshold, "threshold", columns.shape[1], "joint")
    mask = np.abs(columns) >= thr
    if per_joint:
        return mask if qd.ndim == 2 else mask[:, 0]
    return np.all(mask, axis=1)


def outlier_mask(
    residual: ArrayLike, k: float = 5.0, *, min_sigma: float | ArrayLike = 0.0
) -> NDArray[np.bool_]:
    """True where a residual is an outlier: |r - median| > k * sigma, column by column.

    sigma is the robust standard deviation 1.4826 * MAD (median absolute deviation), which a
    few wild samples cannot inflate, unlike the ordinary standard deviation that they would
    drag up until they no longer stand out. A column whose MAD is 0 (more than half its values
    equal) falls back to 1.2533 times the mean absolute deviation (also sigma for Gaussian data);
    ``min_sigma`` (scalar or per column) sets a floor, so that numerically tiny deviations of
    almost exact data are not called outliers. Lecture, "further practical hints": outlier data
    can be eliminated in advance, when building Y.

    Parameters
    ----------
    residual
        (T, n) residuals (e.g. measured minus predicted torque), or (T,).
    k
        Threshold in robust standard deviations (5 flags about 6e-7 of Gaussian samples).

    Returns a boolean array of the shape of ``residual``; a sample (row) is rejected with
    ``mask.any(axis=1)``.
    """
    r = _array(residual, "residual")
    if r.ndim > 2:
        raise ValueError(f"residual: expected shape (T, n) or (T,), got {r.shape}")
    k = positive(k, "k")
    columns = r.reshape(r.shape[0], -1)
    floor = _per_column(min_sigma, "min_sigma", columns.shape[1], "column")
    deviation = np.abs(columns - np.median(columns, axis=0))
    sigma = MAD_TO_SIGMA * np.median(deviation, axis=0)
    fallback = np.sqrt(np.pi / 2) * deviation.mean(axis=0)
    sigma = np.maximum(np.where(sigma > 0, sigma, fallback), floor)
    mask = deviation > k * sigma
    return mask if r.ndim == 2 else mask[:, 0]


def spike_mask(
    x: ArrayLike,
    fs: float,
    k: float = 5.0,
    *,
    window: int | None = None,
    iterations: int = 3,
    relative_floor: float = SPIKE_FLOOR,
) -> tuple[NDArray[np.bool_], NDArray]:
    """Outliers of a signal against a robustly smoothed version of itself; (mask, smoothed).

    For when no model prediction is available to compare with. The smoothed signal is a
    5-sample running median (which removes isolated spikes without spreading them) followed by
    a cubic Savitzky-Golay fit over ``window`` samples (default about 0.1 s, odd): local cubic
    fits follow a smooth motion closely, up to the ends of the log (``mode="interp"``), where a
    forward-backward IIR filter would leave an end transient that looks like an outlier. Bursts
    longer than the median can hide still leak into the fit, so the detection is iterated:
    flagged values are replaced by the smoothed ones and the signal smoothed again
    (``iterations`` passes). Column j is flagged by :func:`outlier_mask` (k robust sigmas of the
    residual), with sigma at least ``relative_floor`` times the column's robust spread, so that
    already smooth data (residual near round-off) yield no flags.

    Parameters
    ----------
    x
        (T, n) or (T,) signal, e.g. measured torques, uniformly sampled at ``fs`` Hz.
    """
    arr = _array(x, "x")
    if arr.ndim > 2:
        raise ValueError(f"x: expected shape (T, n) or (T,), got {arr.shape}")
    fs = positive(fs, "fs")
    if window is None:
        window = max(7, 2 * round(fs / 20) + 1)
    window = positive_int(window, "window")
    if window < 5 or window % 2 == 0:
        raise ValueError(f"window: expected an odd number of samples >= 5, got {window}")
    iterations = positive_int(iterations, "iterations")
    # SciPy's signal and ndimage cost ~0.5 s to import: only when spikes are looked for.
    from scipy.ndimage import median_filter
    from scipy.signal import savgol_filter

    columns = arr.reshape(arr.shape[0], -1)
    if columns.shape[0] < window:
        raise ValueError(f"x: {columns.shape[0]} samples are fewer than the window of {window}")
    spread = MAD_TO_SIGMA * np.median(np.abs(columns - np.median(columns, axis=0)), axis=0)
    floor = positive(relative_floor, "relative_floor") * spread
    mask = np.zeros(columns.shape, dtype=bool)
    smoothed = columns
    for _ in range(iterations):
        cleaned = np.where(mask, smoothed, columns)
        despiked = median_filter(cleaned, size=(5, 1), mode="nearest")
        smoothed = savgol_filter(despiked, window, 3, axis=0, mode="interp")
        mask = outlier_mask(columns - smoothed, k, min_sigma=floor)
    if arr.ndim == 1:
        return mask[:, 0], smoothed[:, 0]
    return mask, smoothed
