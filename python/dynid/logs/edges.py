"""How many samples a zero-phase filter's edge transient spoils at each end of a log.

Forward-backward filtering extends the signal at both ends (odd extension, as
``scipy.signal.sosfiltfilt``) and the output near an end depends on that guess. A log that starts
or stops at rest is extended well; a log cut mid-motion is not, and the error, amplified twice by
the differentiation that follows, reached 1,400 rad/s^2 of acceleration against a typical 27-100
on the Staubli TX40 recording cut mid-motion (issue 20). The error at
distance m from an end is the extension's error seen through the zero-phase impulse response at
lags >= m, so it has died out where that response has: :func:`edge_trim` counts the samples until
the response stays below EDGE_FRACTION of its peak.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .. import _core

#: The trim ends where the zero-phase impulse response stays below this fraction of its peak.
#: For a Butterworth of order 4 that is 2.54 / cutoff seconds (order 8: 4.6 / cutoff). 1e-2
#: (1.8 / cutoff) left up to 3 % of the true peak acceleration at the ends of a log cut
#: mid-motion (tests/test_preparation_edges.py); 1e-3 leaves below 1 %.
EDGE_FRACTION = 1e-3


def zero_phase_impulse_response(sos: NDArray[np.float64]) -> NDArray[np.float64]:
    """h_zp[m], m = 0, 1, ... of the forward-backward filter (symmetric: h_zp[-m] = h_zp[m]):
    the autocorrelation sum_k h[k] h[k + m] of the causal impulse response h, computed until h
    has decayed below 1e-12 of its start (from the slowest pole's radius)."""
    radius = max(float(np.max(np.abs(np.roots([1.0, s[4], s[5]])))) for s in sos)
    length = int(np.ceil(np.log(1e-12) / np.log(radius))) + 8 * len(sos) + 16
    impulse = np.zeros((length, 1))
    impulse[0] = 1.0
    h, _ = _core._sos_filter(sos, impulse, np.zeros((len(sos), 2, 1)))
    spectrum = np.fft.rfft(h[:, 0], 2 * length)
    return np.fft.irfft(np.abs(spectrum) ** 2, 2 * length)[:length]


def edge_trim(sos: NDArray[np.float64], fraction: float = EDGE_FRACTION) -> int:
    """Samples to drop at each end after zero-phase filtering with ``sos``: the first lag from
    which |h_zp| stays below ``fraction`` of h_zp[0] (its peak, the filter's energy)."""
    response = np.abs(zero_phase_impulse_response(sos))
    above = np.nonzero(response >= fraction * response[0])[0]
    return int(above[-1]) + 1
