"""The period of a periodic log: given, or found by the autocorrelation of its positions.

The periodic estimator (:mod:`.periodic`) needs the samples of whole periods. A log whose
positions repeat after ``L`` samples has ``q(t + L) = q(t)``: the normalised correlation of
``q - mean(q)`` with itself shifted by ``L`` samples (every joint summed, over the samples both
copies cover) is 1 there, and 1 - O(noise / motion) on a measured log. The period is the
first lag after the correlation has fallen below zero at which it climbs back above
:data:`MIN_CORRELATION`, moved to the nearest local maximum. Lags are searched while the two
copies overlap by at least :data:`MIN_OVERLAP` of the log (a few samples correlate trivially),
so a log of 1.5-2 periods has its period found, and the estimator then says that it holds fewer
than two; a log with no such lag is not periodic.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: The autocorrelation of q at a period: 1 for an exactly periodic motion; the LWR4+ logs give
#: 0.9999 at their 12.57 s period, a random walk or a chirp nowhere more than ~0.5.
MIN_CORRELATION = 0.98


#: The shortest overlap of the log with its shifted copy at which a lag is considered, as a
#: fraction of the log's length.
MIN_OVERLAP = 1 / 3


def autocorrelation(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """(T,) the normalised autocorrelation of ``q`` (T, n) at lags 0..T-1, every joint summed:
    sum_t <x(t), x(t+L)> / sqrt(sum_t |x(t)|^2 sum_t |x(t+L)|^2) over t < T - L, x = q - mean q.
    """
    x = q - q.mean(axis=0)
    T = x.shape[0]
    size = 1 << int(2 * T - 1).bit_length()  # zero padding: the linear, not circular, sums
    spectrum = np.fft.rfft(x, size, axis=0)
    cross = np.fft.irfft(np.abs(spectrum) ** 2, size, axis=0)[:T].sum(axis=1)
    power = np.einsum("ij,ij->i", x, x)
    cumulative = np.concatenate([[0.0], np.cumsum(power)])
    head = cumulative[T - np.arange(T)]  # samples 0 .. T-L-1
    tail = cumulative[T] - cumulative[np.arange(T)]  # samples L .. T-1
    with np.errstate(divide="ignore", invalid="ignore"):
        r = cross / np.sqrt(head * tail)
    return np.where(np.isfinite(r), r, 0.0)


def detect_period(q: NDArray[np.float64]) -> tuple[int, float] | None:
    """(period in samples, correlation there) of the positions ``q`` (T, n), or None when they
    do not repeat (see the module's docstring)."""
    r = autocorrelation(q)
    last = int(q.shape[0] * (1 - MIN_OVERLAP))
    below = np.flatnonzero(r[1 : last + 1] < 0.0)
    if below.size == 0:
        return None
    start = int(below[0]) + 1
    above = np.flatnonzero(r[start : last + 1] >= MIN_CORRELATION)
    if above.size == 0:
        return None
    lag = start + int(above[0])
    while lag + 1 <= last and r[lag + 1] > r[lag]:
        lag += 1
    return lag, float(r[lag])


def period_starts(length: int, period: float) -> NDArray[np.int64]:
    """The first sample of each whole period of ``period`` samples (a real number) in a log of
    ``length`` samples: round(m * period), m = 0, 1, ...; each period is int(period) samples
    from there, so a period that is not a whole number of samples is never more than half a
    sample out of phase (no drift over the periods)."""
    K = int(period)
    count = 0
    while round(count * period) + K <= length:
        count += 1
    return np.array([round(m * period) for m in range(count)], dtype=np.int64)
