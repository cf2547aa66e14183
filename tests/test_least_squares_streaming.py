"""Least squares from triangular factors (R of [Y | tau] per joint, chunk by chunk, no Q) against
the textbook formulas evaluated directly on the stacked matrix (lecture p. 27): numpy's lstsq for
the estimate, sigma^2 pinv(A) pinv(A)^T for the OLS covariance, the WLS weights from the per-joint
OLS residuals. Tolerance 1e-9 relative (the issue's contract) on theta, std, the noise variances
and the residual RMS; the rank-deficient error is the same as least_squares'.

The factors are kept in power-of-two units that grow with the largest value seen so far; chunks
whose scales differ (issue 22: a first chunk with max |Y| or max |tau| in [0.5, 1), whose exponent
is 0, followed by larger ones) are checked against a closed form and, on random scales and
chunkings, against numpy's lstsq on the stacked rows.
"""

from __future__ import annotations

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

import dynid
from dynid.identification import identify
from dynid.identification.identify import RankDeficientError, stack_by_joint

RTOL = 1e-9


def lwr_problem(samples: int, seed: int = 0):
    """A random, well-excited LWR data set: base regressor (T, 7, p), noisy torques (T, 7)."""
    rng = np.random.default_rng(seed)
    robot = dynid.models.kuka_lwr4()
    base = dynid.base_parameters(robot, "torque", rotor=True, friction=True)  # 62 columns
    q = rng.uniform(-2.5, 2.5, (samples, 7))
    qd = rng.uniform(-2, 2, (samples, 7))
    qdd = rng.uniform(-4, 4, (samples, 7))
    noise = rng.normal(size=(samples, 7)) * np.array([2.0, 1.5, 1.0, 0.5, 0.2, 0.1, 0.05])
    tau = robot.rnea(q, qd, qdd) + noise
    return robot, base, (q, qd, qdd, tau)


def reference(Y: np.ndarray, tau: np.ndarray, method: str, exclude=()):
    """theta, std, per-joint noise variance and residual RMS by the direct formulas."""
    A, b, group = stack_by_joint(Y, tau, exclude)
    N, p = A.shape
    theta, *_ = np.linalg.lstsq(A, b, rcond=None)
    r = b - A @ theta
    joints = np.unique(group)
    counts = np.array([np.sum(group == j) for j in joints])
    variance = np.array([np.sum(r[group == j] ** 2) for j in joints]) / (counts * (N - p) / N)
    pinv = np.linalg.pinv(A)
    covariance = (r @ r / (N - p)) * pinv @ pinv.T
    if method == "wls":
        w = 1.0 / np.sqrt(variance[np.searchsorted(joints, group)])
        theta, *_ = np.linalg.lstsq(A * w[:, None], b * w, rcond=None)
        r = b - A @ theta
        pinv = np.linalg.pinv(A * w[:, None])
        covariance = pinv @ pinv.T
    rms = np.sqrt(np.array([np.sum(r[group == j] ** 2) for j in joints]) / counts)
    return theta, np.sqrt(np.diag(covariance)), variance, rms


def assert_close(actual, expected, what):
    error = np.max(np.abs(actual - expected) / np.abs(expected))
    assert error <= RTOL, f"{what}: largest relative difference {error:.3g}"


@pytest.mark.parametrize("method", ["ols", "wls"])
@pytest.mark.parametrize("exclude", [()])
def test_least_squares_matches_the_direct_formulas(method, exclude):
    robot, base, (q, qd, qdd, tau) = lwr_problem(3000)
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)[..., base.independent]
    fit = dynid.least_squares(Y, tau, method=method, exclude_joints=exclude)
    theta, std, variance, rms = reference(Y, tau, method, exclude)
    assert_close(fit.theta, theta, "theta")
    assert_close(fit.std, std, "std")
    assert_close(fit.noise_variance, variance, "noise variance")
    assert_close(fit.residual_rms, rms, "residual rms")


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_streaming_equals_least_squares_whatever_the_chunks(method):
    robot, base, (q, qd, qdd, tau) = lwr_problem(2500, seed=1)
    # The last samples with torques and regressor rows 2^30 larger: the factors so far are
    # rescaled when a chunk brings larger values.
    q, qd, qdd, tau = (x.copy() for x in (q, qd, qdd, tau))
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)[..., base.independent]
    Y[-300:] *= 2.0**30
    tau[-300:] *= 2.0**30
    whole = dynid.least_squares(Y, tau, method=method)
    theta, std, variance, rms = reference(Y, tau, method)
    assert_close(whole.theta, theta, "theta")
    assert_close(whole.std, std, "std")
    bounds = [0, 1, 8, 9, 1000, 2200, 2500]  # uneven chunks, one of a single sample
    acc = dynid.LeastSquaresAccumulator(7, base.independent.size)
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        acc.add(Y[lo:hi], tau[lo:hi])
    assert acc.samples == 2500
    fit = acc.solve(method=method)
    assert_close(fit.theta, theta, "theta")
    assert_close(fit.std, std, "std")
    assert_close(fit.noise_variance, variance, "noise variance")
    assert_close(fit.residual_rms, rms, "residual rms")


def test_streaming_from_trajectory_chunks_uses_the_cpp_regressor():
    robot, base, (q, qd, qdd, tau) = lwr_problem(2000, seed=2)
    chunks = (
        (q[k : k + 300], qd[k : k + 300], qdd[k : k + 300], tau[k : k + 300])
        for k in range(0, 2000, 300)
    )
    fit = dynid.least_squares_streaming(
        robot,
        chunks,
        rotor=True,
        friction=True,
        columns=base.independent,
        method="wls",
        names=base.names,
    )
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)[..., base.independent]
    theta, std, _, _ = reference(Y, tau, "wls")
    assert_close(fit.theta, theta, "theta")
    assert_close(fit.std, std, "std")
    assert fit.names == list(base.names)
    # The estimate reproduces the model's base parameters up to the noise: 5 std.
    assert np.all(np.abs(fit.theta - base.values(robot)) <= 5 * fit.std)


def test_streaming_rank_deficiency_and_bad_input_are_named():
    robot, base, (q, qd, qdd, tau) = lwr_problem(500, seed=3)
    q, qd, qdd = q.copy(), qd.copy(), qdd.copy()
    q[:, 6] = qd[:, 6] = qdd[:, 6] = 0.0  # joint 7 never moves: its parameters are not excited
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)[..., base.independent]
    acc = dynid.LeastSquaresAccumulator(7, base.independent.size)
    acc.add(Y, tau)
    with pytest.raises(RankDeficientError, match="do not excite all base parameters") as streamed:
        acc.solve(names=base.names)
    with pytest.raises(RankDeficientError) as whole:
        dynid.least_squares(Y, tau, names=base.names)
    assert str(streamed.value) == str(whole.value)
    with pytest.raises(ValueError, match=r"Y: expected shape \(T, 7, "):
        acc.add(Y[..., :-1], tau)
    with pytest.raises(ValueError, match="chunks: expected at least one"):
        dynid.least_squares_streaming(robot, [])
    with pytest.raises(ValueError, match="chunks: expected \\(q, qd, qdd, tau\\)"):
        dynid.least_squares_streaming(robot, [(q, qd)])
    with pytest.raises(ValueError, match="columns: expected indices in"):
        dynid.least_squares_streaming(robot, [(q, qd, qdd, tau)], columns=[0, 91])
    with pytest.raises(ValueError, match="n: expected an integer >= 1"):
        dynid.LeastSquaresAccumulator(0, 3)


# --- scales: chunks of different magnitudes (issue 22) ------------------------------------------


def one_parameter_fit(y: np.ndarray, tau: np.ndarray) -> tuple[float, float]:
    """theta = sum(y tau) / sum(y^2) and the residual norm of tau = y theta (closed form)."""
    theta = float(y @ tau / (y @ y))
    return theta, float(np.linalg.norm(tau - y * theta))


@pytest.mark.parametrize(
    ("first", "later"),
    [
        # (y, tau) rows of the first chunk, then of a later one; exponent 0 means max in [0.5, 1)
        (([0.75, -0.5], [1.6, -1.0]), ([3.0, 5.0], [6.4, 10.6])),  # max |Y| exponent 0
        (([0.3, -0.2], [0.64, -0.45]), ([3.0, 5.0], [6.4, 10.6])),  # max |tau| exponent 0
        (([0.75, 0.5], [0.9, 0.6]), ([3.0, 5.0], [6.4, 10.6])),  # both
        (([0.75, 0.5], [1.6, 1.0]), ([-(2.0**40), 3.0], [-2.13 * 2.0**40, 6.0])),  # far larger
    ],
)
def test_a_first_chunk_below_one_keeps_its_scale_when_later_chunks_are_larger(first, later):
    y = np.concatenate([first[0], later[0]])
    tau = np.concatenate([first[1], later[1]])
    theta, residual = one_parameter_fit(y, tau)
    acc = dynid.LeastSquaresAccumulator(1, 1)
    for rows, torques in (first, later):
        acc.add(np.reshape(rows, (-1, 1, 1)), np.reshape(torques, (-1, 1)))
    fit = acc.solve()
    assert fit.theta[0] == pytest.approx(theta, rel=1e-14)
    # A residual norm is computed to about eps ||tau|| (cancellation in tau - y theta).
    residual_error = abs(fit.residual_rms[0] * np.sqrt(y.size) - residual)
    assert residual_error <= 1e-14 * np.linalg.norm(tau)


def test_the_issue_example_one_parameter_streaming_returns_the_exact_value():
    # Consistent rows (tau = 2.13 y) in two chunks, the first with max |Y| = 0.75: 2.13 whatever
    # the weighting, up to rounding.
    acc = dynid.LeastSquaresAccumulator(1, 1)
    acc.add(np.full((3, 1, 1), 0.75), np.full((3, 1), 2.13 * 0.75))
    acc.add(np.full((3, 1, 1), 6.0), np.full((3, 1), 2.13 * 6.0))
    assert acc.solve().theta[0] == pytest.approx(2.13, rel=1e-14)


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_least_squares_keeps_the_scale_of_its_first_internal_chunk(method):
    # least_squares folds CHUNK_SAMPLES samples at a time: the first chunk's values are in
    # [0.5, 1), the second's 2^10 times larger. Closed form per parameter (p = 1, one joint).
    T = identify.CHUNK_SAMPLES
    rng = np.random.default_rng(22)
    y = np.concatenate([rng.uniform(0.5, 0.99, T), rng.uniform(0.5, 0.99, T) * 2.0**10])
    tau = 2.13 * y + rng.normal(scale=0.01, size=2 * T) * np.abs(y)
    theta, residual = one_parameter_fit(y, tau)
    fit = dynid.least_squares(y[:, None, None], tau[:, None], method=method)
    assert fit.theta[0] == pytest.approx(theta, rel=1e-12)
    assert fit.residual_rms[0] * np.sqrt(y.size) == pytest.approx(residual, rel=1e-10)


#: Random problems: derandomized (the same examples every run) and no example database on disk.
SCALES = settings(
    max_examples=80,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)

#: Power-of-two exponents of the whole Y and tau: 0 (max in [0.5, 1)) often, and a wide range.
EXPONENTS = st.sampled_from([0, -1, 1]) | st.integers(-60, 60)


@st.composite
def scaled_problems(draw):
    """A well-conditioned Gaussian problem Y (T, n, p), tau (T, n), cut into chunks of samples
    whose max |Y| has the power-of-two exponent a + shift_k exactly (rows scaled by powers of
    two, Y and tau alike, so the model still holds), tau scaled by 2^b."""
    p = draw(st.integers(1, 5))
    n = draw(st.integers(1, 3))
    sizes = draw(st.lists(st.integers(1, 12), min_size=1, max_size=6))
    sizes.append(draw(st.integers(2 * p + 4, 2 * p + 20)))  # enough rows in every case
    if draw(st.booleans()):
        sizes.reverse()
    a, b = draw(EXPONENTS), draw(EXPONENTS)
    shifts = draw(st.lists(st.integers(-3, 3), min_size=len(sizes), max_size=len(sizes)))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    theta = rng.normal(size=p)
    chunks = []
    for size, shift in zip(sizes, shifts):
        Y = rng.normal(size=(size, n, p))
        tau = Y @ theta + rng.normal(scale=0.3, size=(size, n))
        # Row scale: max |Y| becomes 2^(a + shift) times a value in [0.5, 1).
        row = np.ldexp(1.0, a + shift - int(np.frexp(np.abs(Y).max())[1]))
        chunks.append((Y * row, np.ldexp(tau * row, b - a)))
    return chunks


def relative_error(actual, expected) -> float:
    return float(np.linalg.norm(actual - expected) / np.linalg.norm(expected))


@SCALES
@given(chunks=scaled_problems())
def test_streaming_matches_lstsq_on_random_scales_and_chunkings(chunks):
    Y = np.concatenate([c[0] for c in chunks])
    tau = np.concatenate([c[1] for c in chunks])
    A, b, group = stack_by_joint(Y, tau)
    # The reference in units where the exponents are small (exact powers of two), so that
    # lstsq's own arithmetic cannot underflow or overflow.
    a = int(np.frexp(np.abs(A).max())[1])
    e = int(np.frexp(np.abs(b).max())[1])
    theta, *_ = np.linalg.lstsq(np.ldexp(A, -a), np.ldexp(b, -e), rcond=None)
    assert np.linalg.cond(np.ldexp(A, -a)) < 1e4  # well conditioned: 1e-9 is attainable
    theta = np.ldexp(theta, e - a)
    r = b - A @ theta
    norms = np.array([np.linalg.norm(r[group == j]) for j in np.unique(group)])

    acc = dynid.LeastSquaresAccumulator(Y.shape[1], Y.shape[2])
    for Y_k, tau_k in chunks:
        acc.add(Y_k, tau_k)
    fit = acc.solve()
    assert relative_error(fit.theta, theta) <= 1e-9
    assert relative_error(fit.residual_rms * np.sqrt(Y.shape[0]), norms) <= 1e-9
