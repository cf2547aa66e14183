"""Bad array input to the Python layer raises ValueError naming the argument (docs/conventions.md,
"Bad input").

Every array argument goes through dynid._checks.real_array. NumPy's float cast alone would drop
the imaginary part of complex numbers (a ComplexWarning at most), turn booleans into 0/1 and
accept object arrays, so each argument below is given, in place of a valid value of the same
shape: complex numbers, booleans, an object array, ragged nested lists and a NaN. Each must raise
a ValueError whose message starts with the argument's name (and, for the wrong dtypes, says
which dtype was given), never a result.

Also: least squares on values near the float64 limits (no misleading rank error, no NaN),
error_metrics on empty input, payload_mass_estimates on NaN, and `dynid demo` with too few
configurations (exit status 2, one line on stderr, no traceback).
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import dynid
import dynid.cli
import dynid.cli.demo
from dynid import excitation, signal
from dynid.identification.from_controller import identify_from_controller, payload_mass_estimates
from dynid.identification.identify import RankDeficientError, least_squares, stack_by_joint
from dynid.identification.validation import error_metrics
from dynid.io import Log, prepare_log

RNG = np.random.default_rng(2024)
T, N, P = 40, 2, 3
Y = RNG.normal(size=(T, N, P))
THETA = np.array([1.0, -2.0, 0.5])
TAU = Y @ THETA + 1e-3 * RNG.normal(size=(T, N))
FIT = least_squares(Y, TAU)

TIME = np.arange(T) * 0.01
SIG = np.column_stack([np.sin(3 * TIME), np.cos(2 * TIME)])  # (T, 2), smooth
LOG = Log(t=TIME, q=SIG, tau=2 * SIG, qd=SIG, qdd=SIG)

PLANAR = dynid.models.planar_2r()
GRAVITY_BASE = dynid.base_parameters(PLANAR, "gravity")
Q = RNG.uniform(-1, 1, size=(5, 2))
G = PLANAR.gravity(Q)
M = PLANAR.mass_matrix(Q)

TRAJECTORY = excitation.FourierTrajectory(1.0, np.ones((2, 3)), np.zeros((2, 3)), np.zeros(2))
LONG = np.column_stack([np.sin(np.linspace(0, 20, 400)), np.cos(np.linspace(0, 13, 400))])


def _from_controller(q, g, M):
    # The 2R's joint 1 is not vertical: keep its gravity row.
    return identify_from_controller(PLANAR, q, g, M, exclude_gravity_joints=())


# (id, call with the argument replaced, the argument's name in the message, a valid value)
CASES = [
    ("least_squares Y", lambda v: least_squares(v, TAU), "Y", Y),
    ("least_squares tau", lambda v: least_squares(Y, v), "tau", TAU),
    ("stack_by_joint Y", lambda v: stack_by_joint(v, TAU), "Y", Y),
    ("predict Y", lambda v: FIT.predict(v), "Y", Y),
    ("identify_from_controller q", lambda v: _from_controller(v, G, M), "q", Q),
    ("identify_from_controller g", lambda v: _from_controller(Q, v, M), "g", G),
    ("identify_from_controller M", lambda v: _from_controller(Q, G, v), "M", M),
    (
        "payload before",
        lambda v: payload_mass_estimates(GRAVITY_BASE, v, np.ones(GRAVITY_BASE.count)),
        "before",
        np.ones(GRAVITY_BASE.count),
    ),
    (
        "payload after",
        lambda v: payload_mass_estimates(GRAVITY_BASE, np.ones(GRAVITY_BASE.count), v),
        "after",
        np.ones(GRAVITY_BASE.count),
    ),
    ("Log t", lambda v: Log(t=v, q=SIG, tau=SIG), "t", TIME),
    ("Log q", lambda v: Log(t=TIME, q=v, tau=SIG), "q", SIG),
    ("Log tau", lambda v: Log(t=TIME, q=SIG, tau=v), "tau", SIG),
    ("Log qd", lambda v: Log(t=TIME, q=SIG, tau=SIG, qd=v), "qd", SIG),
    ("Log qdd", lambda v: Log(t=TIME, q=SIG, tau=SIG, qdd=v), "qdd", SIG),
    (
        "prepare_log reference_tau",
        lambda v: prepare_log(LOG, outlier_k=5.0, reference_tau=v),
        "reference_tau",
        SIG,
    ),
    ("lowpass x", lambda v: signal.lowpass(v, 100.0, 5.0), "x", LONG),
    ("differentiate x", lambda v: signal.differentiate(v, fs=100.0), "x", SIG),
    ("differentiate t", lambda v: signal.differentiate(SIG, t=v), "t", TIME),
    ("decimate", lambda v: signal.decimate(v, 2), "data[0]", LONG),
    ("check_time t", lambda v: signal.check_time(v), "t", TIME),
    ("moving_mask_min_velocity qd", lambda v: signal.moving_mask_min_velocity(v, 0.1), "qd", SIG),
    ("outlier_mask residual", lambda v: signal.outlier_mask(v, 5.0), "residual", SIG),
    (
        "FourierTrajectory a",
        lambda v: excitation.FourierTrajectory(1.0, v, np.zeros((2, 3)), np.zeros(2)),
        "a",
        np.ones((2, 3)),
    ),
    (
        "FourierTrajectory b",
        lambda v: excitation.FourierTrajectory(1.0, np.ones((2, 3)), v, np.zeros(2)),
        "b",
        np.ones((2, 3)),
    ),
    (
        "FourierTrajectory q0",
        lambda v: excitation.FourierTrajectory(1.0, np.ones((2, 3)), np.zeros((2, 3)), v),
        "q0",
        np.zeros(2),
    ),
    ("FourierTrajectory.evaluate t", lambda v: TRAJECTORY.evaluate(v), "t", TIME),
    (
        "FourierTrajectory.from_vector x",
        lambda v: excitation.FourierTrajectory.from_vector(v, 2, 3, 1.0),
        "x",
        np.ones(14),
    ),
    ("error_metrics measured", lambda v: error_metrics(v, SIG), "measured", SIG),
    ("error_metrics predicted", lambda v: error_metrics(SIG, v), "predicted", SIG),
]


def _ragged(good: np.ndarray) -> list:
    """Nested lists like ``good`` with the last innermost row one element short."""
    if good.ndim == 1:
        return [list(good), list(good[:-1])]
    nested = good.tolist()
    inner = nested
    while isinstance(inner[-1][-1], list):
        inner = inner[-1]
    inner[-1] = inner[-1][:-1]
    return nested


def _nan(good: np.ndarray) -> np.ndarray:
    bad = np.array(good, dtype=float)
    bad.flat[bad.size // 2] = np.nan
    return bad


BAD = {  # (make the bad value from a good one, what the message must say was given)
    "complex": (lambda good: np.asarray(good) + 0.5j, "complex"),
    "bool": (lambda good: np.ones(np.shape(good), dtype=bool), "bool"),
    "object": (lambda good: np.asarray(good).astype(object), "object"),
    "ragged": (_ragged, "ragged"),
    "nan": (_nan, "non-finite|finite|nan"),
}


@pytest.mark.parametrize("kind", list(BAD))
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_array_raises_value_error_naming_the_argument(case, kind):
    _, call, name, good = case
    make, given = BAD[kind]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a ComplexWarning would mean a silent cast
        with pytest.raises(ValueError, match=f"^{re.escape(name)}: ") as info:
            call(make(good))
    assert re.search(given, str(info.value), flags=re.IGNORECASE), str(info.value)
    assert not isinstance(info.value, RankDeficientError)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_the_valid_value_is_accepted(case):
    """The bad values above differ from an accepted one only in what the test says."""
    _, call, _, good = case
    call(good)


def test_valid_integer_and_list_input_is_still_accepted():
    a = least_squares(Y.tolist(), TAU.tolist())
    b = least_squares(Y, TAU)
    np.testing.assert_array_equal(a.theta, b.theta)
    integers = np.arange(T * N).reshape(T, N)
    metrics = error_metrics(integers, integers + 1)
    np.testing.assert_allclose(metrics["rms"], 1.0)


def test_strings_are_not_numbers():
    with pytest.raises(ValueError, match=r"^Y: .*str"):
        least_squares(np.full((T, N, P), "1.0"), TAU)
    with pytest.raises(ValueError, match=r"^x: .*str"):
        signal.lowpass("1.0", 100.0, 5.0)


def test_payload_mass_estimates_with_nan_raises():
    before = np.ones(GRAVITY_BASE.count)
    after = before.copy()
    after[-1] = np.nan
    with pytest.raises(ValueError, match=r"^after: non-finite"):
        payload_mass_estimates(GRAVITY_BASE, before, after)
    with pytest.raises(ValueError, match=r"^before: expected shape"):
        payload_mass_estimates(GRAVITY_BASE, before[:-1], before)
    lwr = dynid.base_parameters(dynid.models.kuka_lwr4(), "gravity")
    estimates = payload_mass_estimates(lwr, np.ones(lwr.count), np.ones(lwr.count) + 0.4)
    assert [e["mass"] for e in estimates] == pytest.approx([0.4 / e["factor"] for e in estimates])
    assert estimates


@pytest.mark.parametrize("empty", [[], np.zeros((0, 3)), np.zeros((5, 0))])
def test_error_metrics_with_empty_input_raises(empty):
    with pytest.raises(ValueError, match=r"^measured: expected at least one sample"):
        error_metrics(empty, empty)


# --------------------------------------------------------------------------- large values


def test_error_metrics_on_large_values():
    """Values ~3e156 (squares ~1e313) with errors ~3e152: every metric as for the unscaled
    values, scaled exactly; values ~1e200: the mse itself overflows, a ValueError."""
    predicted = SIG + 1e-4 * np.cos(7 * TIME)[:, None]
    reference = error_metrics(SIG, predicted)
    scale = 2.0**520  # exact
    scaled = error_metrics(SIG * scale, predicted * scale)
    for key in ("r2", "relative_rms"):
        np.testing.assert_array_equal(scaled[key], reference[key])
    for key in ("rms", "max_abs"):
        np.testing.assert_array_equal(scaled[key], reference[key] * scale)
    np.testing.assert_array_equal(scaled["mse"], reference["mse"] * scale * scale)
    with pytest.raises(ValueError, match=r"^measured, predicted: the mean square error overflows"):
        error_metrics(SIG * 1e200, predicted * 1e200)


@pytest.mark.parametrize("scale", [1e150, 1e200, 1e300, 1e-150])
@pytest.mark.parametrize("method", ["ols", "wls"])
def test_least_squares_on_large_or_tiny_regressors_scales_exactly(scale, method):
    """Y scaled by s: theta / s, std / s; no overflow in the column norms, no rank error."""
    reference = least_squares(Y, TAU, method=method)
    fit = least_squares(Y * scale, TAU, method=method)
    assert fit.rank == P
    np.testing.assert_allclose(fit.theta * scale, reference.theta, rtol=1e-12)
    np.testing.assert_allclose(fit.std * scale, reference.std, rtol=1e-10)
    np.testing.assert_allclose(fit.relative_std, reference.relative_std, rtol=1e-10)
    np.testing.assert_allclose(fit.residual_rms, reference.residual_rms, rtol=1e-10)
    assert np.isfinite(fit.condition_number)


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_least_squares_on_large_torques_and_regressors(method):
    """Y and tau both ~1e150: theta as before; ~1e200: the noise variance (tau^2 ~ 1e368) cannot
    be represented, a ValueError naming tau, not a rank error or NaN."""
    reference = least_squares(Y, TAU, method=method)
    fit = least_squares(Y * 1e150, TAU * 1e150, method=method)
    np.testing.assert_allclose(fit.theta, reference.theta, rtol=1e-12)
    np.testing.assert_allclose(fit.noise_variance / 1e300, reference.noise_variance, rtol=1e-10)
    with pytest.raises(ValueError, match=r"^tau: .*overflows") as info:
        least_squares(Y * 1e200, TAU * 1e200, method=method)
    assert not isinstance(info.value, RankDeficientError)


def test_least_squares_estimate_that_overflows_names_y_and_tau():
    with pytest.raises(ValueError, match=r"^Y, tau: the estimate .*overflows"):
        least_squares(Y * 1e-200, TAU * 1e200)
    # theta ~ 1e200 is representable, its covariance (~1e400) is not
    with pytest.raises(ValueError, match=r"^Y, tau: the covariance .*overflows"):
        least_squares(Y * 1e-200, TAU)


def test_predict_overflow_raises():
    fit = least_squares(Y * 1e-150, TAU)
    with pytest.raises(ValueError, match=r"^Y: the predicted torque .*overflows"):
        fit.predict(Y * 1e160)
    np.testing.assert_allclose(fit.predict(Y * 1e-150), FIT.predict(Y), rtol=1e-12)


# --------------------------------------------------------------------------- demo CLI


@pytest.mark.parametrize(
    ("argv", "argument"),
    [
        (["--train", "0"], "train"),
        (["--train", "1"], "train"),
        (["--train", "2"], "train"),
        (["--train", "-5"], "train"),
        (["--validation", "0"], "validation"),
    ],
)
def test_demo_with_too_few_configurations_exits_2_with_one_line(tmp_path, capsys, argv, argument):
    out = tmp_path / "demo"
    status = dynid.cli.main(["demo", "--output", str(out), *argv])
    captured = capsys.readouterr()
    assert status == 2
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith(f"dynid demo: error: {argument}: expected an integer >= ")
    assert "Traceback" not in captured.err
    assert not out.exists()  # refused before any work


def test_demo_minimum_sizes_are_checked_by_one_function():
    assert dynid.cli.demo.check_demo_sizes(3, 1) == (3, 1)
    with pytest.raises(ValueError, match=r"^train: expected an integer >= 3"):
        dynid.cli.demo.check_demo_sizes(2, 1)
    with pytest.raises(ValueError, match=r"^validation: expected an integer >= 1"):
        dynid.cli.demo.check_demo_sizes(3, 0)
    with pytest.raises(ValueError, match=r"^train: "):
        dynid.cli.demo.check_demo_sizes(True, 1)


# --------------------------------------------------------------------------- the helper itself


def test_real_array_helper():
    from dynid._checks import real_array

    given = np.arange(6.0).reshape(2, 3)
    assert real_array(given, "x") is given  # float64 input is not copied
    np.testing.assert_array_equal(
        real_array([[1, 2], [3, 4]], "x", ndim=2), [[1.0, 2.0], [3.0, 4.0]]
    )
    assert real_array(np.arange(3, dtype=np.uint8), "x").dtype == np.float64
    with pytest.raises(ValueError, match=r"^x: expected a 1-dimensional array, got shape \(2, 3\)"):
        real_array(given, "x", ndim=1)
    with pytest.raises(ValueError, match=r"^x: .*complex.*complex128"):
        real_array([1.0, 2.0 + 0j], "x")
    with pytest.raises(ValueError, match=r"^x: .*ragged"):
        real_array([[1.0, 2.0], [3.0]], "x")
    with pytest.raises(ValueError, match=r"^x: .*objects.*object"):
        real_array([1.0, None], "x")
    with pytest.raises(ValueError, match=r"^x: non-finite value inf at index \(1,\)"):
        real_array([1.0, np.inf], "x")
    with pytest.raises(ValueError, match=r"^x: expected a finite number, got nan"):
        real_array(np.nan, "x")
    assert np.isnan(real_array([np.nan], "x", finite=False)[0])
