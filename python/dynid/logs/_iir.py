"""Butterworth low-pass design and zero-phase filtering in second-order sections.

The same filters as ``scipy.signal.butter(order, wn, output="sos")`` and
``scipy.signal.sosfiltfilt`` (tested against them), written here because importing
``scipy.signal`` costs about 0.5 s (it imports ``scipy.stats`` and ``scipy.interpolate``), a
quarter of the 2 s that `dynid demo` may take (issue 13, item 5); SciPy stays the reference in
the tests. The recursion runs in C++ (``dynid._core._sos_filter``, cpp/src/sos_filter.cpp).

Design (Oppenheim & Schafer, Discrete-Time Signal Processing, 3rd ed., Sect. 7.2): the analog
Butterworth prototype's poles -exp(i pi m / (2 N)), m = -N+1, -N+3, ..., N-1, scaled to the
pre-warped cutoff 2 fs tan(pi f_c / fs) and mapped by the bilinear transform
z = (2 fs + s) / (2 fs - s); all N zeros at z = -1; the gain makes H(1) = 1. Conjugate pole
pairs become sections [1, 2, 1, 1, -2 Re p, |p|^2] and an odd order's real pole
[1, 1, 0, 1, -p, 0]; the poles closest to the unit circle (the sharpest resonances) go last, as
in SciPy, so that the earlier sections have already removed what would excite them.

Zero phase (Gustafsson 1996, "Determining the initial states in forward-backward filtering";
SciPy's ``filtfilt``): the signal is extended at both ends (odd, even or constant extension),
filtered forwards from the steady state of its first value, then backwards from the steady state
of the last output, and the extension removed.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import NDArray

from .. import _core

#: How the signal is extended at both ends before filtering (as scipy.signal.sosfiltfilt).
PadType = Literal["odd", "even", "constant"]


def butterworth_lowpass(order: int, wn: float) -> NDArray[np.float64]:
    """(S, 6) second-order sections of the digital Butterworth low-pass of ``order`` with its
    -3 dB cutoff at ``wn`` times the Nyquist frequency (0 < wn < 1)."""
    m = np.arange(-order + 1, order, 2)
    analog = -np.exp(1j * np.pi * m / (2 * order)) * 4.0 * np.tan(np.pi * wn / 2.0)  # fs = 2
    digital = (4.0 + analog) / (4.0 - analog)
    pairs = digital[digital.imag > 0]
    pairs = pairs[np.argsort(np.abs(pairs))]  # farthest from the unit circle first
    sections = [[1.0, 2.0, 1.0, 1.0, -2.0 * p.real, abs(p) ** 2] for p in pairs]
    if order % 2:
        real = digital[np.argmin(np.abs(digital.imag))].real
        sections.insert(0, [1.0, 1.0, 0.0, 1.0, -real, 0.0])
    sos = np.array(sections)
    # Unit gain at DC (z = 1): the product of the sections' A(1) / B(1), put in the first one.
    sos[0, :3] *= np.prod(sos[:, 3:].sum(axis=1) / sos[:, :3].sum(axis=1))
    return sos


def steady_state(sos: NDArray[np.float64]) -> NDArray[np.float64]:
    """(S, 2) states of the sections at rest under a unit step input (scipy.signal.sosfilt_zi):
    section s sees the DC gain of the sections before it."""
    states = np.empty((len(sos), 2))
    gain = 1.0
    for s, (b0, b1, b2, _, a1, a2) in enumerate(sos):
        # Transposed direct form II at rest with input x = 1 and output y = H(1) x:
        # z1 = y - b0, z2 = b2 - a2 y (the state equations with z unchanged).
        y = (b0 + b1 + b2) / (1.0 + a1 + a2)
        states[s] = gain * np.array([y - b0, b2 - a2 * y])
        gain *= y
    return states


def default_padding(sos: NDArray[np.float64]) -> int:
    """scipy.signal.sosfiltfilt's default extension: 3 (2 S + 1 - trailing zero coefficients)."""
    zeros = min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    return 3 * (2 * len(sos) + 1 - zeros)


def zero_phase(
    sos: NDArray[np.float64], x: NDArray[np.float64], padtype: PadType, padlen: int
) -> NDArray[np.float64]:
    """Forward-backward filtering of the columns of ``x`` (T, C), time along axis 0, after
    extending it by ``padlen`` samples (< T) at both ends."""
    extended = _extend(x, padtype, padlen)
    rest = steady_state(sos)[:, :, None]  # (S, 2, 1): times the signal's end values
    forward, _ = _core._sos_filter(sos, extended, rest * extended[0])
    backward, _ = _core._sos_filter(sos, forward[::-1], rest * forward[-1])
    return backward[::-1][padlen : len(backward) - padlen]


def _extend(x: NDArray[np.float64], padtype: PadType, padlen: int) -> NDArray[np.float64]:
    if padlen == 0:
        return x
    first, last = x[:1], x[-1:]
    if padtype == "constant":
        before, after = np.repeat(first, padlen, axis=0), np.repeat(last, padlen, axis=0)
    else:
        before, after = x[padlen:0:-1], x[-2 : -padlen - 2 : -1]  # mirrored about the ends
        if padtype == "odd":
            before, after = 2 * first - before, 2 * last - after
    return np.concatenate([before, x, after])
