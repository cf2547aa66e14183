"""The zero-phase filters' edge transients, trimmed by prepare_log (dynid.logs.edges; issue 20).

The trim is checked against the impulse response of scipy's own forward-backward filter (an
independent implementation) and, on a log cut mid-motion from a known trajectory, by what it is
for: the accelerations left at the ends match the closed form.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal as sp

from dynid.logs import Log, load_log, prepare_log, save_log
from dynid.logs.edges import EDGE_FRACTION, edge_trim, zero_phase_impulse_response


@pytest.mark.parametrize(("order", "wn"), [(4, 0.04), (4, 0.01), (2, 0.2), (8, 0.1), (5, 0.05)])
def test_zero_phase_impulse_response_is_scipys(order, wn) -> None:
    """h_zp from the autocorrelation equals sosfiltfilt of a unit impulse (no padding) far from
    the ends, to 1e-12 of its peak; the trim is where |h_zp| last reaches EDGE_FRACTION of it."""
    sos = sp.butter(order, wn, output="sos")
    ours = zero_phase_impulse_response(sos)
    L = 4 * ours.size
    impulse = np.zeros(2 * L + 1)
    impulse[L] = 1.0
    theirs = sp.sosfiltfilt(sos, impulse, padlen=0)[L:]
    np.testing.assert_allclose(ours, theirs[: ours.size], rtol=0, atol=1e-12 * theirs[0])
    above = np.nonzero(np.abs(theirs) >= EDGE_FRACTION * theirs[0])[0]
    assert edge_trim(sos) == above[-1] + 1


def test_butterworth_trim_in_seconds() -> None:
    """Order 4: the response decays below 1e-3 of its peak after ~2.54 / cutoff seconds,
    whatever the sampling rate (the filter scales with cutoff / fs)."""
    for fs, cutoff in [(5000.0, 100.0), (200.0, 1.0), (100.0, 5.0)]:
        trim = edge_trim(sp.butter(4, 2 * cutoff / fs, output="sos"))
        assert trim / fs * cutoff == pytest.approx(2.54, abs=0.02)


def cut_log(fs: float = 500.0, seconds: float = 6.0, noise: float = 0.0) -> tuple[Log, ...]:
    """q = A sin(w t + phi) per joint, cut at t = 0 and at the end mid-motion (qd, qdd != 0)."""
    t = np.arange(0.0, seconds, 1.0 / fs)
    w = 2 * np.pi * np.array([0.5, 0.8, 1.3])
    phase = np.array([0.4, 1.1, 2.0])
    q = np.sin(w * t[:, None] + phase)
    qd = w * np.cos(w * t[:, None] + phase)
    qdd = -(w**2) * q
    rng = np.random.default_rng(5)
    log = Log(t=t, q=q + rng.normal(0, noise, q.shape), tau=np.zeros_like(q))
    truth = Log(t=t, q=q, tau=np.zeros_like(q), qd=qd, qdd=qdd)
    return log, truth


def test_edge_trim_leaves_true_accelerations_at_the_ends() -> None:
    """A log cut mid-motion, low-passed at 20 Hz: untrimmed, the first and last accelerations
    are far off (the odd extension is not the motion); trimmed by the filter's own decay, every
    acceleration kept is within 0.5 % of the peak true acceleration (the middle: 1e-4)."""
    log, truth = cut_log(noise=1e-5)
    kept = prepare_log(log, cutoff=20.0)
    untrimmed = prepare_log(log, cutoff=20.0, trim_edges=False)
    trim = edge_trim(sp.butter(4, 2 * 20.0 / 500.0, output="sos"))
    assert log.T - 2 * trim == kept.T
    np.testing.assert_array_equal(kept.t, log.t[trim:-trim])
    assert f"trimmed {trim} samples" in kept.notes[-1]
    peak = np.abs(truth.qdd).max()
    error = np.abs(kept.qdd - truth.qdd[trim:-trim]) / peak
    assert error.max() < 5e-3, error.max()
    assert np.abs(untrimmed.qdd - truth.qdd).max() / peak > 10 * error.max()
    np.testing.assert_allclose(kept.qdd, untrimmed.qdd[trim:-trim], rtol=0, atol=1e-12)


def test_no_filter_no_trim() -> None:
    log, _ = cut_log()
    assert prepare_log(log).T == log.T


def test_decimation_adds_its_anti_alias_filter_to_the_trim() -> None:
    log, _ = cut_log()
    out = prepare_log(log, decimate=5)
    trim = -(-edge_trim(sp.butter(8, 0.8 / 5, output="sos")) // 5)
    assert len(log.t[::5]) - 2 * trim == out.T
    np.testing.assert_array_equal(out.t, log.t[::5][trim:-trim])


def test_skip_end_drops_the_last_samples(tmp_path) -> None:
    log, _ = cut_log()
    save_log(log, tmp_path / "log.npz")
    loaded = load_log(tmp_path / "log.npz", skip=10, skip_end=25)
    np.testing.assert_array_equal(loaded.t, log.t[10:-25])
    assert loaded.notes[-1] == "skipped the last 25 samples"
    with pytest.raises(ValueError, match="skip_end"):
        load_log(tmp_path / "log.npz", skip_end=log.T - 1)
