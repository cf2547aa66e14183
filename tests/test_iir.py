"""dynid's Butterworth design and zero-phase filter (dynid._iir, C++ sos_filter) against SciPy's
scipy.signal.butter / sosfilt / sosfilt_zi / sosfiltfilt, an independent implementation."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy import signal as sp

from dynid import _core
from dynid.logs import signal as sig
from dynid.logs._iir import butterworth_lowpass, steady_state

ORDERS = range(1, 9)
CUTOFFS = (0.01, 0.05, 0.2, 0.5, 0.9)  # times the Nyquist frequency


def _signal(T: int = 3000, columns: int = 3, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.cumsum(rng.standard_normal((T, columns)), axis=0)  # a random walk: low and high f


@pytest.mark.parametrize("order", ORDERS)
@pytest.mark.parametrize("wn", CUTOFFS)
def test_design_has_scipys_frequency_response(order: int, wn: float) -> None:
    """Same transfer function as scipy.signal.butter(output="sos"): the responses agree to 1e-10
    on 512 frequencies; unit DC gain and -3 dB at the cutoff (Butterworth's definition) to 1e-10."""
    w = np.linspace(0.0, np.pi, 512)
    _, ours = sp.sosfreqz(butterworth_lowpass(order, wn), w)
    _, scipys = sp.sosfreqz(sp.butter(order, wn, output="sos"), w)
    np.testing.assert_allclose(ours, scipys, rtol=0, atol=1e-10)
    _, at = sp.sosfreqz(butterworth_lowpass(order, wn), [0.0, np.pi * wn])
    np.testing.assert_allclose(np.abs(at), [1.0, np.sqrt(0.5)], rtol=0, atol=1e-10)


@pytest.mark.parametrize("order", ORDERS)
def test_steady_state_is_scipys_sosfilt_zi(order: int) -> None:
    """The rest state under a unit step (closed form here, a linear solve in SciPy) to 1e-10."""
    sos = sp.butter(order, 0.1, output="sos")
    np.testing.assert_allclose(steady_state(sos), sp.sosfilt_zi(sos), rtol=0, atol=1e-10)


def test_cpp_sos_filter_is_scipys_sosfilt_and_continues_across_blocks() -> None:
    """_core._sos_filter equals scipy.signal.sosfilt with zi (1e-12 relative), and filtering in
    two blocks, the state carried over, equals filtering at once (exactly)."""
    sos = sp.butter(5, 0.07, output="sos")
    x = _signal(columns=4)
    state = np.random.default_rng(1).standard_normal((len(sos), 2, 4))
    ours, final = _core._sos_filter(sos, x, state)
    scipys, scipy_final = sp.sosfilt(sos, x, axis=0, zi=state)
    scale = np.abs(scipys).max()
    np.testing.assert_allclose(ours, scipys, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(final, scipy_final, rtol=0, atol=1e-12 * scale)
    first, middle = _core._sos_filter(sos, x[:1234], state)
    second, last = _core._sos_filter(sos, x[1234:], middle)
    np.testing.assert_array_equal(np.vstack([first, second]), ours)
    np.testing.assert_array_equal(last, final)


@pytest.mark.parametrize("padtype", ["odd", "even", "constant"])
@pytest.mark.parametrize("order", [1, 2, 4, 5, 8])
def test_lowpass_is_scipys_sosfiltfilt(padtype: str, order: int) -> None:
    """dynid.signal.lowpass == scipy.signal.sosfiltfilt(butter(...)) to 1e-10 relative, for every
    extension, odd and even orders, the default and the settled padding."""
    x = _signal()
    sos = sp.butter(order, 5.0, fs=200.0, output="sos")
    expected = sp.sosfiltfilt(sos, x, axis=0, padtype=padtype)
    ours = sig.lowpass(x, 200.0, 5.0, order=order, padtype=padtype)
    np.testing.assert_allclose(ours, expected, rtol=0, atol=1e-10 * np.abs(expected).max())
    settled = sig.lowpass(x, 200.0, 5.0, order=order, padtype=padtype, settle=True)
    expected = sp.sosfiltfilt(sos, x, axis=0, padtype=padtype, padlen=120)  # 3 fs / cutoff
    np.testing.assert_allclose(settled, expected, rtol=0, atol=1e-10 * np.abs(expected).max())


def test_lowpass_along_other_axes_and_one_dimension() -> None:
    """Time along axis 1 of a 3-D array and a 1-D signal: as SciPy's (1e-10 relative)."""
    x = _signal(T=800, columns=6).T.reshape(2, 3, 800).transpose(0, 2, 1)  # (2, 800, 3)
    sos = sp.butter(4, 0.1, output="sos")
    expected = sp.sosfiltfilt(sos, x, axis=1)
    ours = sig.lowpass(x, 2.0, 0.1, axis=1)
    np.testing.assert_allclose(ours, expected, rtol=0, atol=1e-10 * np.abs(expected).max())
    one = sig.lowpass(x[0, :, 0], 2.0, 0.1)
    np.testing.assert_allclose(one, expected[0, :, 0], rtol=0, atol=1e-10 * np.abs(one).max())


def test_decimate_filters_like_scipy() -> None:
    """The anti-aliasing filter of dynid.signal.decimate is SciPy's Butterworth at 0.8 / factor
    of the Nyquist frequency, run forwards and backwards (1e-10 relative)."""
    x = _signal()
    expected = sp.sosfiltfilt(sp.butter(8, 0.8 / 4, output="sos"), x, axis=0)[::4]
    ours = sig.decimate(x, 4, order=8)
    np.testing.assert_allclose(ours, expected, rtol=0, atol=1e-10 * np.abs(expected).max())


@pytest.mark.parametrize(
    ("sections", "x", "state", "name"),
    [
        (np.ones((2, 5)), np.ones((10, 1)), np.zeros((2, 2, 1)), "sections"),
        (np.ones((0, 6)), np.ones((10, 1)), np.zeros((0, 2, 1)), "sections"),
        (np.ones((2, 6)) * [1, 1, 1, 2, 1, 1], np.ones((10, 1)), np.zeros((2, 2, 1)), "sections"),
        (sp.butter(4, 0.1, output="sos"), np.ones(10), np.zeros((2, 2, 1)), "x"),
        (sp.butter(4, 0.1, output="sos"), np.full((10, 1), np.nan), np.zeros((2, 2, 1)), "x"),
        (sp.butter(4, 0.1, output="sos"), np.ones((10, 1)), np.zeros((2, 2, 2)), "state"),
    ],
)
def test_sos_filter_rejects_bad_arguments_by_name(sections, x, state, name) -> None:
    """Wrong shapes, a0 != 1 (unnormalised sections) and NaN: a ValueError naming the argument."""
    with pytest.raises(ValueError, match=f"^{name}:"):
        _core._sos_filter(sections, x, state)


def test_import_dynid_signal_does_not_import_scipy_signal() -> None:
    """The reason for dynid._iir: filtering without scipy.signal's 0.5 s import (its time is
    measured in bench/import_time.py, never here). spike_mask still imports it when called."""
    code = (
        "import sys, numpy as np, dynid.logs.signal as s; "
        "s.lowpass(np.arange(100.0), 100.0, 5.0); s.decimate(np.arange(100.0), 2); "
        "print('scipy.signal' in sys.modules, 'scipy.ndimage' in sys.modules)"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.split()
    assert loaded == ["False", "False"]
