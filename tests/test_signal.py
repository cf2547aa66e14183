"""dynid.signal against closed forms: zero phase, Butterworth magnitude, derivative order, masks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal as sp

from dynid.logs import signal as sig

FS = 200.0  # Hz, the rate of the KUKA LWR4+ logs


def fit_sinusoid(t: np.ndarray, y: np.ndarray, f: float) -> tuple[float, float]:
    """Amplitude and phase of y ~ A sin(2 pi f t + phi), by linear least squares."""
    basis = np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)])
    (a, b), *_ = np.linalg.lstsq(basis, y, rcond=None)
    return float(np.hypot(a, b)), float(np.arctan2(b, a))


def xcorr_lag(x: np.ndarray, y: np.ndarray, max_lag: int) -> int:
    """The lag (samples) that maximises sum x[k] y[k + lag]; positive when y is delayed."""
    lags = np.arange(-max_lag, max_lag + 1)
    core = slice(max_lag, len(x) - max_lag)
    scores = [np.dot(x[core], np.roll(y, -lag)[core]) for lag in lags]
    return int(lags[int(np.argmax(scores))])


# ------------------------------------------------------------------------------ lowpass


def test_lowpass_is_zero_phase_and_a_causal_filter_is_not() -> None:
    """A 0.5 Hz sine through a 5 Hz filter: lag 0, phase and amplitude kept to 1e-3.

    The same sine through the causal (one-pass) filter of the same design is delayed by about
    16 samples (the group delay of a 4th-order Butterworth, 2.61 / (2 pi fc) = 83 ms), so the
    test can tell the two apart.
    """
    t = np.arange(4000) / FS
    f = 0.5
    x = np.sin(2 * np.pi * f * t)
    y = sig.lowpass(x, FS, cutoff=5.0, order=4)
    inner = slice(400, -400)  # away from the ends, where the padding acts
    amplitude, phase = fit_sinusoid(t[inner], y[inner], f)
    assert abs(amplitude - 1.0) < 1e-3
    assert abs(phase) < 1e-3
    assert xcorr_lag(x, y, 50) == 0

    causal = sp.sosfilt(sp.butter(4, 5.0, fs=FS, output="sos"), x)
    _, causal_phase = fit_sinusoid(t[inner], causal[inner], f)
    assert abs(causal_phase) > 0.2  # 2 pi * 0.5 Hz * 83 ms = 0.26 rad
    assert xcorr_lag(x, causal, 50) > 10


@pytest.mark.parametrize("order", [2, 4, 5])
def test_lowpass_magnitude_is_squared_butterworth(order: int) -> None:
    """Forward-backward squares the Butterworth magnitude: gain 1/2 at the cutoff, and
    1 / (1 + (f/fc)^(2 order)) in general (bilinear design, nearly analog far below fs/2)."""
    t = np.arange(8000) / FS
    fc = 2.0
    inner = slice(1000, -1000)
    for f, tolerance in ((fc, 1e-3), (0.5 * fc, 1e-3), (5 * fc, 5e-3)):
        y = sig.lowpass(np.sin(2 * np.pi * f * t), FS, fc, order=order)
        amplitude, _ = fit_sinusoid(t[inner], y[inner], f)
        assert amplitude == pytest.approx(1.0 / (1.0 + (f / fc) ** (2 * order)), abs=tolerance)
        if f == 5 * fc and order == 4:
            assert amplitude < 0.05


def test_lowpass_axis_and_columns() -> None:
    rng = np.random.default_rng(1)
    x = rng.normal(size=(500, 3))
    y0 = sig.lowpass(x, FS, 10.0)
    y1 = sig.lowpass(x.T, FS, 10.0, axis=1)
    np.testing.assert_allclose(y1.T, y0, atol=1e-13)
    np.testing.assert_allclose(y0[:, 2], sig.lowpass(x[:, 2], FS, 10.0), atol=1e-13)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"cutoff": 100.0}, "cutoff"),
        ({"cutoff": 150.0}, "cutoff"),
        ({"cutoff": 0.0}, "cutoff"),
        ({"cutoff": -1.0}, "cutoff"),
        ({"cutoff": 5.0, "order": 0}, "order"),
        ({"cutoff": 5.0, "order": 2.5}, "order"),
        ({"cutoff": 5.0, "axis": 2}, "axis"),
    ],
)
def test_lowpass_rejects_bad_arguments(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        sig.lowpass(np.zeros((100, 2)), FS, **kwargs)


def test_lowpass_rejects_short_and_non_finite_signals() -> None:
    # order 4 -> 2 second-order sections -> sosfiltfilt pads 3 * (2 * 2 + 1) = 15 samples
    with pytest.raises(ValueError, match=r"x: 15 samples .* too few .* at least 16"):
        sig.lowpass(np.zeros(15), FS, 5.0)
    sig.lowpass(np.zeros(16), FS, 5.0)
    x = np.zeros((50, 2))
    x[7, 1] = np.nan
    with pytest.raises(ValueError, match=r"x: non-finite .* \(7, 1\)"):
        sig.lowpass(x, FS, 5.0)
    with pytest.raises(ValueError, match="fs"):
        sig.lowpass(np.zeros(50), -FS, 5.0)


# ------------------------------------------------------------------------------ differentiate


def jittered_grid(h: float, duration: float, rng: np.random.Generator) -> np.ndarray:
    """Times i*h moved by up to +-30 % of h: strictly increasing, non-uniform."""
    base = np.arange(0.0, duration, h)
    return base + rng.uniform(-0.3, 0.3, base.size) * h


def test_differentiate_sine_uniform_grid() -> None:
    t = np.arange(2000) / FS
    x = np.column_stack([np.sin(3 * t), np.cos(2 * t)])
    exact = np.column_stack([3 * np.cos(3 * t), -2 * np.sin(2 * t)])
    dx_fs = sig.differentiate(x, fs=FS)
    dx_t = sig.differentiate(x, t=t)
    # central differences: error x''' h^2 / 6 = 27 * 2.5e-5 / 6 ~ 1.1e-4
    np.testing.assert_allclose(dx_fs, exact, atol=3e-4)
    np.testing.assert_allclose(dx_t, dx_fs, atol=1e-9)
    np.testing.assert_allclose(sig.differentiate(x.T, fs=FS, axis=1), dx_fs.T, atol=1e-12)


def test_differentiate_is_exact_for_quadratics_on_any_grid() -> None:
    """Three-point differences on a non-uniform grid differentiate the parabola through three
    samples, so a quadratic comes out exact everywhere, ends included (edge_order=2)."""
    t = jittered_grid(0.01, 2.0, np.random.default_rng(3))
    x = 1.5 - 2.0 * t + 0.7 * t**2
    np.testing.assert_allclose(sig.differentiate(x, t), -2.0 + 1.4 * t, atol=1e-10)


@pytest.mark.parametrize("grid", ["uniform", "jittered"])
def test_differentiate_is_second_order(grid: str) -> None:
    """Halving the step divides the error by about 4 (second order), on both kinds of grid."""
    rng = np.random.default_rng(11)
    errors = []
    for h in (0.02, 0.01, 0.005):
        t = np.arange(0.0, 3.0, h) if grid == "uniform" else jittered_grid(h, 3.0, rng)
        x = np.sin(2.0 * t) + 0.3 * t**3
        exact = 2.0 * np.cos(2.0 * t) + 0.9 * t**2
        errors.append(np.sqrt(np.mean((sig.differentiate(x, t) - exact) ** 2)))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.0) & (ratios < 5.5)), ratios


def test_differentiate_rejects_bad_arguments() -> None:
    x = np.zeros((10, 2))
    with pytest.raises(ValueError, match="exactly one"):
        sig.differentiate(x)
    with pytest.raises(ValueError, match="exactly one"):
        sig.differentiate(x, t=np.arange(10.0), fs=1.0)
    with pytest.raises(ValueError, match="t: has 9 samples"):
        sig.differentiate(x, t=np.arange(9.0))
    with pytest.raises(ValueError, match=r"t: not strictly increasing at sample 4"):
        sig.differentiate(x, t=np.array([0, 1, 2, 3, 3, 5, 6, 7, 8, 9.0]))
    with pytest.raises(ValueError, match="fs"):
        sig.differentiate(x, fs=0.0)
    with pytest.raises(ValueError, match="at least 2 samples"):
        sig.differentiate(np.zeros(1), fs=1.0)


# ------------------------------------------------------------------------------ sampling_rate


def test_sampling_rate_is_the_median_rate() -> None:
    rng = np.random.default_rng(5)
    t = 1.46e9 + np.arange(1001) / FS  # a Unix-time start, as the KUKA logs
    assert sig.sampling_rate(t) == pytest.approx(FS, rel=1e-4)  # float64 Unix time: ~0.2 us steps
    dt = np.full(1000, 1 / FS)
    dt[::50] = 3 / FS  # a few late samples pull the mean rate, not the median
    assert sig.sampling_rate(np.concatenate([[0.0], np.cumsum(dt)])) == pytest.approx(FS)
    t_j = jittered_grid(1 / FS, 5.0, rng)
    assert sig.sampling_rate(t_j) == pytest.approx(FS, rel=0.02)


@pytest.mark.parametrize(
    ("t", "match"),
    [
        ([0.0, 0.1, 0.1, 0.3], r"not strictly increasing at sample 2"),
        ([0.0, 0.2, 0.1], r"not strictly increasing at sample 2"),
        ([0.0], "at least 2 samples"),
        ([[0.0, 1.0], [2.0, 3.0]], "1-D"),
        ([0.0, np.inf], "non-finite"),
    ],
)
def test_sampling_rate_rejects_bad_time(t: list, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        sig.sampling_rate(t)


# ------------------------------------------------------------------------------ decimate


def test_decimate_keeps_the_band_and_removes_what_would_alias() -> None:
    """Decimating 200 Hz by 4 (new Nyquist 25 Hz): a 1 Hz sine is kept sample for sample; a
    45 Hz sine, which would fold back to 5 Hz, is removed. Without the anti-alias filter the
    45 Hz sine shows up at full amplitude."""
    t = np.arange(4000) / FS
    slow = np.sin(2 * np.pi * 1.0 * t)
    fast = np.sin(2 * np.pi * 45.0 * t)
    slow_d, fast_d = sig.decimate(slow, fast, 4)
    inner = slice(50, -50)
    np.testing.assert_allclose(slow_d[inner], slow[::4][inner], atol=1e-6)
    assert np.max(np.abs(fast_d[inner])) < 1e-3
    aliased = sig.decimate(fast, factor=4, antialias=False)
    np.testing.assert_array_equal(aliased, fast[::4])
    amplitude, _ = fit_sinusoid(t[::4], aliased, 5.0)
    assert amplitude > 0.99


def test_decimate_forms_and_errors() -> None:
    x = np.arange(100.0)
    assert sig.decimate(x, 1).shape == (100,)
    assert sig.decimate(x, factor=3).shape == (34,)
    assert len(sig.decimate(x, x, factor=3)) == 2
    with pytest.raises(ValueError, match="factor"):
        sig.decimate(x)
    with pytest.raises(ValueError, match="factor"):
        sig.decimate(x, factor=0)
    with pytest.raises(ValueError, match="too few"):
        sig.decimate(np.arange(10.0), 2)


# ------------------------------------------------------------------------------ masks


def test_moving_mask_all_joints_and_per_joint() -> None:
    qd = np.array([[0.5, -0.5], [0.05, 1.0], [-1.0, -0.01], [0.0, 0.0], [0.1, -0.1]])
    np.testing.assert_array_equal(
        sig.moving_mask_min_velocity(qd, 0.1), [True, False, False, False, True]
    )
    np.testing.assert_array_equal(
        sig.moving_mask_min_velocity(qd, 0.1, per_joint=True),
        [[True, True], [False, True], [True, False], [False, False], [True, True]],
    )
    np.testing.assert_array_equal(
        sig.moving_mask_min_velocity(qd, [0.01, 0.5]), [True, True, False, False, False]
    )
    np.testing.assert_array_equal(sig.moving_mask_min_velocity(qd[:, 0], 0.1).shape, (5,))
    with pytest.raises(ValueError, match="threshold"):
        sig.moving_mask_min_velocity(qd, [0.1, 0.1, 0.1])
    with pytest.raises(ValueError, match="threshold"):
        sig.moving_mask_min_velocity(qd, -0.1)
    with pytest.raises(ValueError, match="qd"):
        sig.moving_mask_min_velocity(np.full((2, 2), np.nan), 0.1)


def test_outlier_mask_finds_planted_outliers_that_a_std_rule_misses() -> None:
    """10 % of samples at 8-14 sigma: median/MAD finds exactly them; mean/std, inflated by the
    outliers themselves (std 2.7 to 4.5), would call none of them outliers at 5 std."""
    rng = np.random.default_rng(7)
    residual = rng.normal(0.0, 1.0, (2000, 3))
    planted = np.zeros(residual.shape, dtype=bool)
    for j in range(3):
        rows = rng.choice(2000, 200, replace=False)
        planted[rows, j] = True
        residual[rows, j] = rng.choice([-1.0, 1.0], 200) * (8.0 + 3.0 * j)
    np.testing.assert_array_equal(sig.outlier_mask(residual, k=5.0), planted)
    naive = np.abs(residual - residual.mean(0)) > 5 * residual.std(0)
    assert naive.sum() < planted.sum() / 10
    np.testing.assert_array_equal(sig.outlier_mask(residual[:, 0], 5.0), planted[:, 0])


def test_outlier_mask_degenerate_columns() -> None:
    r = np.zeros((100, 2))
    r[10, 0] = 1.0  # MAD is 0: falls back to the mean absolute deviation
    mask = sig.outlier_mask(r)
    assert mask[10, 0]
    assert mask.sum() == 1  # a constant column has no outliers
    assert not sig.outlier_mask(r, min_sigma=1.0).any()
    with pytest.raises(ValueError, match="k"):
        sig.outlier_mask(r, k=0)
    with pytest.raises(ValueError, match="min_sigma"):
        sig.outlier_mask(r, min_sigma=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="residual"):
        sig.outlier_mask(np.zeros((3, 2, 2)))


def test_spike_mask_on_smooth_and_on_noisy_signals() -> None:
    """Spikes in a smooth or a noisy signal are found exactly; the smooth signal alone gives no
    flags (its residual is near round-off, which the relative floor ignores)."""
    rng = np.random.default_rng(9)
    t = np.arange(3000) / FS
    smooth = np.column_stack([30 * np.sin(0.5 * t), 2 * np.cos(1.3 * t) + 0.5 * np.sin(4 * t)])
    assert not sig.spike_mask(smooth, FS)[0].any()
    rows = rng.choice(np.arange(20, 2980), 15, replace=False)
    for base in (smooth, smooth + rng.normal(0.0, 0.02, smooth.shape)):
        spiky = base.copy()
        spiky[rows, 0] += 3.0
        spiky[rows[:5], 1] -= 1.0
        mask, smoothed = sig.spike_mask(spiky, FS)
        assert set(np.nonzero(mask[:, 0])[0]) == set(rows)
        assert set(np.nonzero(mask[:, 1])[0]) == set(rows[:5])
        # the smoothed signal does not carry the spikes
        assert np.max(np.abs(smoothed - smooth)[100:-100]) < 0.05
