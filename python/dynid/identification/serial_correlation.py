"""Standard deviations of a least-squares estimate when the residuals are correlated in time.

The covariance sigma^2 (Y^T W Y)^-1 of :func:`dynid.least_squares` treats every row as an
independent draw. A log low-passed before the fit (``dynid.prepare_log(cutoff=...)``, or a robot
that filters its torque signal itself) breaks that: the noise of neighbouring samples is nearly
the same, a log of T samples holds about T / tau_int independent ones, and the white-noise
standard deviations come out too small by about sqrt(tau_int), the integrated autocorrelation
time of the noise (in samples). On a simulated UR5 with a payload, low-passed at 10 Hz at
500 Hz (tau_int ~ 30), the payload's inertia came out 4.5-7 of these standard deviations off
(docs/payload.md, "Why the inertia was 5 standard deviations off").

The estimate is theta_hat - theta = A^-1 sum_t g_t, with A = sum_t Y_t^T W Y_t and
g_t = Y_t^T W e_t the sample's weighted residual on its regressor rows (all joints of sample t).
Its covariance is A^-1 Omega A^-1 with Omega = sum over lags l of sum_t g_t g_{t+l}^T, the
long-run covariance of g (the "sandwich"; white rows: Omega = A). Omega is estimated with the
Bartlett kernel of width L (Newey & West, Econometrica 55(3), 1987), computed as overlapping
batch means: Omega ~ 1/L sum_t (g_t + ... + g_{t+L-1}) (...)^T, positive semi-definite by
construction. L comes from the residuals themselves: twice Sokal's automatic window M for the
integrated autocorrelation time (the smallest M with M >= C tau_int(M), C = 5; A. D. Sokal,
"Monte Carlo methods in statistical mechanics", 1996, sect. 3), pooled over the joints. So no
filter needs to be known: the correlation the data show is the one accounted for.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

#: Sokal's constant: the window M is the first with M >= SOKAL_C tau_int(M).
SOKAL_C = 5.0
#: The Bartlett width as a multiple of Sokal's window (lags up to M keep half their weight or
#: more). Measured on the UR5 (docs/payload.md): C = 3, 5, 8 gave the same z-scores.
WIDTH_PER_WINDOW = 2
#: At most this fraction of the shortest segment (the kernel's bias grows with L / T).
MAX_WIDTH_FRACTION = 0.1
#: Residuals whose integrated autocorrelation time (in samples, 1 for independent ones) is below
#: this keep the independent-samples standard deviations; above it the correlation-robust ones
#: replace them. White noise gives 1 +- a few hundredths.
WHITE_CORRELATION_TIME = 1.5


def autocorrelation(residuals: Sequence[NDArray[np.float64]], lags: int) -> NDArray[np.float64]:
    """(lags + 1,) the autocorrelation of the (T_k, n) residual segments (weighted by the
    joints' noise, so that every joint counts alike), pooled over joints and segments; rho[0] =
    1. Lags never cross from one segment into the next."""
    total = np.zeros(lags + 1)
    for segment in residuals:
        T = segment.shape[0]
        spectrum = np.fft.rfft(segment, n=2 * T, axis=0)  # zero-padded: no wrap-around
        auto = np.fft.irfft(np.abs(spectrum) ** 2, n=2 * T, axis=0)
        total[: min(lags + 1, T)] += auto[: min(lags + 1, T)].sum(axis=1)
    if total[0] <= 0.0:  # no residual at all (noise-free data): nothing correlates
        rho = np.zeros(lags + 1)
        rho[0] = 1.0
        return rho
    return total / total[0]


def correlation_window(residuals: Sequence[NDArray[np.float64]]) -> int:
    """Sokal's window M for the residual segments: the first M with M >= SOKAL_C tau_int(M),
    tau_int(M) = 1 + 2 sum_{l=1}^{M} rho_l (at least 1; capped by the segments' length)."""
    shortest = min(segment.shape[0] for segment in residuals)
    limit = max(1, int(MAX_WIDTH_FRACTION * shortest) // WIDTH_PER_WINDOW)
    rho = autocorrelation(residuals, limit)
    tau = 1.0 + 2.0 * np.cumsum(rho[1:])
    for M in range(1, limit + 1):
        if SOKAL_C * tau[M - 1] <= M:
            return M
    return limit


def bartlett_width(residuals: Sequence[NDArray[np.float64]]) -> int:
    """The Bartlett kernel's width L for :func:`long_run_covariance`: WIDTH_PER_WINDOW times
    :func:`correlation_window`."""
    return WIDTH_PER_WINDOW * correlation_window(residuals)


def long_run_covariance(
    influence: Sequence[NDArray[np.float64]], width: int
) -> NDArray[np.float64]:
    """(q, q) the Bartlett-kernel estimate of Var(sum_t h_t) from the (T_k, q) segments of
    h_t (e.g. rows of A^-1 times g_t): overlapping batch means of ``width`` samples, each segment
    on its own, summed. ``width`` 1 is the white-noise sum of h_t h_t^T."""
    q = influence[0].shape[1]
    omega = np.zeros((q, q))
    for h in influence:
        T = h.shape[0]
        L = max(1, min(int(width), T))
        if L == 1:
            omega += h.T @ h
            continue
        cumulative = np.vstack([np.zeros(q), np.cumsum(h, axis=0)])
        batches = cumulative[L:] - cumulative[:-L]  # (T - L + 1, q) sums of L consecutive h_t
        omega += batches.T @ batches / L * _batch_scale(T, L)
    return omega


def correlation_robust_covariance(
    Y: NDArray[np.float64], residuals: NDArray[np.float64], weights: NDArray[np.float64]
) -> tuple[NDArray[np.float64], float, int] | None:
    """The sandwich A^-1 Omega A^-1 of a least-squares fit held in memory: Y (T, n, p) the
    regressor, residuals (T, n) tau - Y theta, weights (n,) the fit's row weights (1 for OLS,
    1 / sigma_j^2 for WLS). With the integrated correlation time and the Bartlett width; None
    when the residuals are independent (correlation time below WHITE_CORRELATION_TIME), so that
    the least-squares covariance stands. (``identify_log`` does the same chunk by chunk.)"""
    weighted = residuals * np.sqrt(weights)
    window = correlation_window([weighted])
    correlation_time = 1.0 + 2.0 * float(autocorrelation([weighted], window)[1:].sum())
    if correlation_time < WHITE_CORRELATION_TIME:
        return None
    width = WIDTH_PER_WINDOW * window
    WY = Y * weights[None, :, None]
    inverse = scaled_inverse(np.einsum("tjp,tjq->pq", WY, Y))
    influence = np.einsum("tjp,tj->tp", WY, residuals) @ inverse.T
    return long_run_covariance([influence], width), correlation_time, width


def scaled_inverse(A: NDArray[np.float64]) -> NDArray[np.float64]:
    """A^-1 of the normal matrix A = sum Y^T W Y, computed on its unit-diagonal scaling (columns
    of very different units keep their precision); a pseudo-inverse for a singular A."""
    scale = 1.0 / np.sqrt(np.where(np.diag(A) > 0, np.diag(A), 1.0))
    inverse: NDArray[np.float64] = (
        scale[:, None] * np.linalg.pinv(A * scale[:, None] * scale[None, :]) * scale[None, :]
    )
    return inverse


def correlation_note(correlation_time: float, width: int, ratio: NDArray[np.float64]) -> str:
    """What a result's notes say when its standard deviations are the correlation-robust ones:
    ``ratio`` is robust / independent-samples std, parameter by parameter."""
    return (
        f"the residuals are correlated in time (integrated correlation time "
        f"{correlation_time:.3g} samples, e.g. a filtered log or a model error): standard "
        f"deviations from that correlation (Newey-West, Bartlett width {width}), "
        f"{np.nanmin(ratio):.2g}-{np.nanmax(ratio):.2g} times the independent-samples ones"
    )


class LongRunAccumulator:
    """:func:`long_run_covariance` of h_t fed chunk by chunk (a log of any length: memory of
    ``width`` samples, not of the log): overlapping batch means of ``width`` consecutive h_t,
    a segment (one log) at a time; :meth:`end_segment` between logs, so that no batch spans two.
    """

    def __init__(self, p: int, width: int) -> None:
        self.p, self.width = int(p), max(1, int(width))
        self.omega = np.zeros((self.p, self.p))
        self._tail = np.zeros((0, self.p))  # the last ``width`` cumulative sums of the segment
        self._total = np.zeros(self.p)
        self._count = 0
        self._batches = np.zeros((self.p, self.p))

    def add(self, h: NDArray[np.float64]) -> None:
        """Add the next (T_k, p) h_t of the current segment."""
        if h.shape[0] == 0:
            return
        cumulative = self._total + np.cumsum(h, axis=0)
        if self._count == 0:
            cumulative = np.vstack([np.zeros(self.p), cumulative])
        known = np.vstack([self._tail, cumulative])
        L = self.width
        if known.shape[0] > L:
            batches = known[L:] - known[:-L]
            self._batches += batches.T @ batches
        self._tail = known[-L:]
        self._total = cumulative[-1]
        self._count += h.shape[0]

    def end_segment(self) -> None:
        """Close the current segment (with the factors of :func:`long_run_covariance`)."""
        T, L = self._count, min(self.width, max(self._count, 1))
        if T:  # as long_run_covariance (white rows, L = 1: no factor)
            self.omega += self._batches / L * (1.0 if L == 1 else _batch_scale(T, L))
        self._tail = np.zeros((0, self.p))
        self._total = np.zeros(self.p)
        self._count = 0
        self._batches = np.zeros((self.p, self.p))


def _batch_scale(T: int, L: int) -> float:
    """The factor of overlapping batch means of L samples in a segment of T: T / (T - L + 1),
    the batches cover T - L + 1 starts of the T samples; T / (T - L), the fitted residuals sum
    to zero on the regressor (the normal equations), which takes about L / T of the batches'
    variance away (Meketon & Schmeiser's overlapping batch means, Proc. Winter Simulation
    Conference 1984, have the same factor)."""
    return T / (T - L + 1) * (T / (T - L) if T > L else 1.0)
