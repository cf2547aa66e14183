"""dynid.export.plots.envelope (the min/max decimation of long signals before drawing) against a
bucket-by-bucket loop, and the plots of a long log."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.export.plots import MAX_POINTS, envelope, plot_torques


@pytest.mark.parametrize("T", [1, 10, MAX_POINTS, MAX_POINTS + 1, 3 * MAX_POINTS - 1, 100_003])
def test_envelope_keeps_every_buckets_extremes_in_time_order(T: int) -> None:
    """At most MAX_POINTS + 2 points; every bucket's minimum and maximum sample kept (the loop
    below finds them independently); the first and last samples kept; times increasing; short
    signals unchanged."""
    rng = np.random.default_rng(T)
    t = np.cumsum(rng.uniform(0.5, 1.5, T))
    y = rng.standard_normal(T)
    y[T // 3] = 50.0  # a spike must survive
    te, ye = envelope(t, y)
    if T <= MAX_POINTS:
        np.testing.assert_array_equal(te, t)
        np.testing.assert_array_equal(ye, y)
        return
    assert len(te) <= MAX_POINTS + 2
    assert np.all(np.diff(te) > 0)
    assert te[0] == t[0] and te[-1] == t[-1]
    kept = set(np.searchsorted(t, te))
    np.testing.assert_array_equal(y[sorted(kept)], ye)  # the points are samples of (t, y)
    size = -(-T // (MAX_POINTS // 2))
    for start in range(0, T, size):
        bucket = y[start : start + size]
        assert start + int(np.argmin(bucket)) in kept
        assert start + int(np.argmax(bucket)) in kept
    assert ye.max() == 50.0 and ye.min() == y.min()


def test_a_long_log_plots(tmp_path) -> None:
    """A 200k-sample, 7-joint torque plot is written (drawn from the envelope)."""
    t = np.arange(200_000) / 1000.0
    tau = np.sin(np.outer(t, np.arange(1, 8)))
    path = plot_torques(t, tau, 0.9 * tau, tmp_path / "torques.png")
    assert path.stat().st_size > 10_000
