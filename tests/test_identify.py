"""Least-squares identification (dynid.identification.identify) against independent computations.

Lecture, Robotics 2 "Least Squares (LS) identification" (p. 27) and "Additional remarks on LS
identification" (p. 28). The data come from the real LWR-IV regressor (noise added with known
per-joint standard deviations) or from small random problems solved here by the normal
equations, which the library must never use but which are a fine independent check on
well-conditioned data.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.identification.identify import (
    LeastSquaresResult,
    RankDeficientError,
    least_squares,
    stack_by_joint,
)


@pytest.fixture(scope="module")
def lwr():
    """The rigid-body LWR-IV (drive terms zeroed, so rnea == Y @ pi) and its 43 base parameters."""
    robot = dynid.models.kuka_lwr4()
    robot.Ia = np.zeros(robot.n)
    robot.Fv = np.zeros(robot.n)
    robot.Fs = np.zeros(robot.n)
    base = dynid.base_parameters(robot)
    assert base.count == 43
    return robot, base


def lwr_state(robot, T: int, seed: int):
    rng = np.random.default_rng(seed)
    q = robot.random_configurations(T, seed=seed)
    return q, rng.uniform(-2.0, 2.0, (T, robot.n)), rng.uniform(-4.0, 4.0, (T, robot.n))


def lwr_data(robot, base, T: int, seed: int):
    q, qd, qdd = lwr_state(robot, T, seed)
    return base.reduce(robot.regressor(q, qd, qdd))


# --- exactness on noise-free data -------------------------------------------------------------


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_noise_free_torques_give_the_true_base_parameters(lwr, method):
    # tau from the RNEA (not from the regressor); tolerance 1e-8 relative, per parameter.
    robot, base = lwr
    q, qd, qdd = lwr_state(robot, 60, seed=1)
    Y = base.reduce(robot.regressor(q, qd, qdd))
    tau = robot.rnea(q, qd, qdd)
    result = least_squares(Y, tau, method=method, names=base.names)
    theta_true = base.values(robot)
    np.testing.assert_allclose(result.theta, theta_true, rtol=1e-8, atol=0)
    assert result.rank == 43 and result.method == method and result.names == base.names
    assert np.all(result.residual_rms < 1e-9 * np.sqrt(np.mean(tau**2)))
    assert np.all(np.isfinite(result.std)) and np.all(result.std < 1e-9)


def test_noise_free_gravity_with_paper_row_selection(lwr):
    # Paper: joint 1's gravity row is dropped (exclude_joints=(0,)). That row vanishes for the LWR
    # (vertical first axis), up to roundoff; set exactly to zero, its residual is exactly zero
    # and WLS must floor that joint's variance instead of dividing by zero.
    robot, _ = lwr
    gravity_base = dynid.base_parameters(robot, "gravity")
    q = robot.random_configurations(100, seed=2)
    Y = gravity_base.reduce(robot.gravity_regressor(q))
    tau = robot.gravity(q)
    assert np.abs(Y[:, 0]).max() < 1e-12 and np.abs(tau[:, 0]).max() < 1e-12
    theta_true = gravity_base.values(robot)
    paper = least_squares(Y, tau, exclude_joints=(0,), method="wls")
    np.testing.assert_allclose(paper.theta, theta_true, rtol=1e-8, atol=0)
    assert paper.excluded == (0,) and paper.joints == (1, 2, 3, 4, 5, 6)
    assert paper.noise_variance.shape == (6,)
    Y[:, 0], tau[:, 0] = 0.0, 0.0
    all_rows = least_squares(Y, tau, method="wls")
    assert all_rows.noise_variance[0] == 0.0 and all_rows.joints == tuple(range(7))
    np.testing.assert_allclose(all_rows.theta, theta_true, rtol=1e-8, atol=0)
    for field in ("theta", "std", "covariance", "noise_variance", "residual_rms"):
        assert np.all(np.isfinite(getattr(all_rows, field))), field


# --- against the normal equations and np.linalg.lstsq (independent, well conditioned) ---------


def random_problem(seed: int, T: int = 40, n: int = 3, p: int = 5):
    rng = np.random.default_rng(seed)
    Y = rng.normal(size=(T, n, p))
    theta = rng.normal(size=p)
    sigma = np.array([0.1, 0.5, 2.0])[:n]
    return Y, Y @ theta + rng.normal(size=(T, n)) * sigma


def test_ols_matches_normal_equations_and_lstsq():
    Y, tau = random_problem(3)
    T, n, p = Y.shape
    A, b = Y.reshape(-1, p), tau.reshape(-1)  # time-major: the row order must not matter
    theta = np.linalg.solve(A.T @ A, A.T @ b)
    np.testing.assert_allclose(np.linalg.lstsq(A, b, rcond=None)[0], theta, rtol=1e-12)
    r = b - A @ theta
    covariance = (r @ r / (T * n - p)) * np.linalg.inv(A.T @ A)
    result = least_squares(Y, tau)
    np.testing.assert_allclose(result.theta, theta, rtol=1e-10)
    np.testing.assert_allclose(result.covariance, covariance, rtol=1e-10, atol=1e-16)
    np.testing.assert_allclose(result.std, np.sqrt(np.diag(covariance)), rtol=1e-10)
    np.testing.assert_allclose(result.relative_std, 100 * result.std / np.abs(theta), rtol=1e-10)
    assert result.condition_number == pytest.approx(np.linalg.cond(A), rel=1e-10)
    joint = np.tile(np.arange(n), T)
    rms = [np.sqrt(np.mean(r[joint == j] ** 2)) for j in range(n)]
    np.testing.assert_allclose(result.residual_rms, rms, rtol=1e-10)


def test_wls_matches_weighted_normal_equations():
    Y, tau = random_problem(4)
    T, n, p = Y.shape
    A, b = Y.reshape(-1, p), tau.reshape(-1)
    N, joint = T * n, np.tile(np.arange(n), T)
    r = b - A @ np.linalg.solve(A.T @ A, A.T @ b)
    variance = np.array([r[joint == j] @ r[joint == j] / (T - p * T / N) for j in range(n)])
    w = 1.0 / variance[joint]
    theta = np.linalg.solve(A.T @ (w[:, None] * A), A.T @ (w * b))
    result = least_squares(Y, tau, method="wls")
    np.testing.assert_allclose(result.noise_variance, variance, rtol=1e-10)
    np.testing.assert_allclose(result.theta, theta, rtol=1e-10)
    np.testing.assert_allclose(
        result.covariance, np.linalg.inv(A.T @ (w[:, None] * A)), rtol=1e-10, atol=1e-16
    )
    cond = np.linalg.cond(np.sqrt(w)[:, None] * A)
    assert result.condition_number == pytest.approx(cond, rel=1e-10)
    rw = b - A @ theta
    rms = [np.sqrt(np.mean(rw[joint == j] ** 2)) for j in range(n)]
    np.testing.assert_allclose(result.residual_rms, rms, rtol=1e-10)


# --- a stacked system Y (N, p), tau (N,): one group, one noise level (issue 22) -------------------


def stacked_problem(seed: int, N: int = 200, p: int = 6, sigma: float = 0.3):
    """A fixed, well-conditioned A (N, p) and theta; b with homoscedastic noise of the seed."""
    A = np.random.default_rng(0).normal(size=(N, p))
    theta = np.linspace(-1.0, 2.0, p)
    return A, theta, A @ theta + np.random.default_rng(seed).normal(size=N) * sigma


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_a_stacked_y_is_one_system_with_one_noise_level(method):
    # Independent: lstsq and sigma^2 (A^T A)^-1 with sigma^2 = ||r||^2 / (N - p), one variance.
    A, _, b = stacked_problem(5)
    N, p = A.shape
    theta, *_ = np.linalg.lstsq(A, b, rcond=None)
    r = b - A @ theta
    variance = r @ r / (N - p)
    result = least_squares(A, b, method=method)
    np.testing.assert_allclose(result.theta, theta, rtol=1e-10)
    np.testing.assert_allclose(
        result.std, np.sqrt(variance * np.diag(np.linalg.inv(A.T @ A))), rtol=1e-10
    )
    np.testing.assert_allclose(result.noise_variance, [variance], rtol=1e-10)
    np.testing.assert_allclose(result.residual_rms, [np.sqrt(r @ r / N)], rtol=1e-10)
    assert result.joints == (0,) and result.excluded == ()
    np.testing.assert_allclose(result.predict(A), A @ result.theta, rtol=1e-14)
    # The explicit form of the same system: one joint of N samples. Same path, same numbers.
    explicit = least_squares(A[:, np.newaxis], b[:, np.newaxis], method=method)
    assert explicit == result


def test_a_stacked_y_equals_the_per_joint_form_under_ols():
    # OLS pools the noise whatever the groups: the (T, n, p) form and its stack_by_joint agree.
    Y, tau = random_problem(14)
    A, b, _ = stack_by_joint(Y, tau)
    per_joint, stacked = least_squares(Y, tau), least_squares(A, b)
    np.testing.assert_allclose(stacked.theta, per_joint.theta, rtol=1e-10)
    np.testing.assert_allclose(stacked.std, per_joint.std, rtol=1e-10)
    np.testing.assert_allclose(stacked.covariance, per_joint.covariance, rtol=1e-10, atol=1e-16)
    (T, _, p), N = Y.shape, b.size
    pooled = np.sum(per_joint.residual_rms**2) * T / (N - p)  # ||r||^2 / (N - p)
    np.testing.assert_allclose(stacked.noise_variance, [pooled], rtol=1e-10)


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_stacked_std_is_calibrated_on_homoscedastic_data(method):
    # 200 noise draws x 6 parameters: the z-scores (theta - theta_true) / std of a calibrated std
    # have RMS ~1 (t with 194 dof: 1.005). Read as one sample of 200 joints, every row had its own
    # noise variance and the WLS z-scores an RMS of 9.7.
    z = []
    for seed in range(200):
        A, theta_true, b = stacked_problem(seed)
        fit = least_squares(A, b, method=method)
        z.append((fit.theta - theta_true) / fit.std)
    rms = np.sqrt(np.mean(np.square(z)))
    assert 0.8 <= rms <= 1.2, rms


def test_one_sample_of_n_joints_is_the_per_joint_form_with_t_1():
    rng = np.random.default_rng(5)
    Y, tau = rng.normal(size=(1, 8, 3)), rng.normal(size=8)
    result = least_squares(Y, tau)
    np.testing.assert_allclose(result.theta, np.linalg.lstsq(Y[0], tau, rcond=None)[0], rtol=1e-10)
    assert result.joints == tuple(range(8))


def test_no_degrees_of_freedom_left_warns_and_reports_infinite_std():
    rng = np.random.default_rng(6)
    Y, tau = rng.normal(size=(1, 4, 4)), rng.normal(size=(1, 4))
    with pytest.warns(RuntimeWarning, match="degrees of freedom"):
        result = least_squares(Y, tau)
    np.testing.assert_allclose(result.theta, np.linalg.solve(Y[0], tau[0]), rtol=1e-10)
    assert np.all(np.isinf(result.std))


# --- statistics: standard deviations, weighting, sample size ----------------------------------


def noisy_fits(Y, theta_true, sigma, method: str, repetitions: int):
    """(estimates, stds) over independent noise draws with per-joint standard deviation sigma."""
    tau = Y @ theta_true
    fits = [
        least_squares(
            Y, tau + np.random.default_rng(k).normal(size=tau.shape) * sigma, method=method
        )
        for k in range(repetitions)
    ]
    return np.array([f.theta for f in fits]), np.array([f.std for f in fits])


@pytest.mark.parametrize(
    ("method", "sigma"),
    [("ols", [0.2] * 7), ("wls", [0.1, 0.3, 0.1, 0.2, 0.1, 0.1, 0.1])],
)
def test_two_std_cover_the_true_error_95_percent_of_the_time(lwr, method, sigma):
    # 200 draws x 43 parameters; a correct std gives P(|error| < 2 std) = 0.954.
    robot, base = lwr
    Y, theta_true = lwr_data(robot, base, 40, seed=7), base.values(robot)
    estimates, stds = noisy_fits(Y, theta_true, np.array(sigma), method, 200)
    coverage = np.mean(np.abs(estimates - theta_true) < 2 * stds)
    assert 0.9 <= coverage <= 0.99, coverage


def test_wls_beats_ols_when_joint_noise_levels_differ(lwr):
    # Joints 2 and 4 are 25-50 times noisier: WLS should be far more accurate, parameter by
    # parameter (RMS error over 100 draws).
    robot, base = lwr
    Y, theta_true = lwr_data(robot, base, 40, seed=8), base.values(robot)
    sigma = np.array([0.02, 1.0, 0.02, 0.5, 0.02, 0.02, 0.02])
    rms = {
        m: np.sqrt(np.mean((noisy_fits(Y, theta_true, sigma, m, 100)[0] - theta_true) ** 2, axis=0))
        for m in ("ols", "wls")
    }
    ratio = rms["wls"] / rms["ols"]
    assert np.median(ratio) < 0.5 and np.mean(ratio < 1.0) > 0.9, ratio


def test_errors_shrink_as_samples_grow(lwr):
    # 9 times the samples: RMS error ~3 times smaller (1/sqrt(N)); require at least 2.
    robot, base = lwr
    theta_true = base.values(robot)
    rms = []
    for T in (20, 180):
        estimates = noisy_fits(lwr_data(robot, base, T, 9), theta_true, 0.2, "ols", 20)[0]
        rms.append(np.sqrt(np.mean((estimates - theta_true) ** 2)))
    assert rms[0] / rms[1] > 2.0, rms


# --- stacking (lecture p. 28) ------------------------------------------------------------------


def test_stack_by_joint_orders_rows_by_joint_then_time():
    T, n, p = 4, 3, 2
    Y = np.array([[[100 * t + 10 * j + k for k in range(p)] for j in range(n)] for t in range(T)])
    tau = np.array([[100.0 * t + 10 * j for j in range(n)] for t in range(T)])
    A, b, group = stack_by_joint(Y, tau)
    expected_rows = [(t, j) for j in range(n) for t in range(T)]  # joint 1 for all t, then joint 2
    np.testing.assert_array_equal(A, [Y[t, j] for t, j in expected_rows])
    np.testing.assert_array_equal(b, [tau[t, j] for t, j in expected_rows])
    np.testing.assert_array_equal(group, [j for _, j in expected_rows])

    A, b, group = stack_by_joint(Y, tau, exclude_joints=(0,))
    assert 0 not in group and A.shape == (T * (n - 1), p)
    for j in (1, 2):  # contiguous, in time order
        rows = np.flatnonzero(group == j)
        np.testing.assert_array_equal(np.diff(rows), 1)
        np.testing.assert_array_equal(b[rows], tau[:, j])

    A, b, group = stack_by_joint(Y[0], tau[0], exclude_joints=[2])
    np.testing.assert_array_equal(A, Y[0, :2])
    np.testing.assert_array_equal(group, [0, 1])


# --- rank deficiency ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def same_q2(lwr):
    """Gravity data with q2 the same in every sample: mx2 and mz2R cannot be told apart."""
    robot, _ = lwr
    gravity_base = dynid.base_parameters(robot, "gravity")
    q = robot.random_configurations(200, seed=10)
    q[:, 1] = 0.7
    Y = gravity_base.reduce(robot.gravity_regressor(q))
    return Y, robot.gravity(q), gravity_base, gravity_base.values(robot)


def test_rank_deficient_data_raise_naming_the_parameter(same_q2):
    Y, tau, gravity_base, _ = same_q2
    with pytest.raises(
        RankDeficientError, match=r"rank 11 < 12.*mz2R, mx2|rank 11 < 12.*mx2, mz2R"
    ):
        least_squares(Y, tau, exclude_joints=(0,), names=gravity_base.names)
    with pytest.raises(RankDeficientError, match=r"theta\[0\]"):  # unnamed: indices
        least_squares(Y, tau, exclude_joints=(0,))
    with pytest.raises(RankDeficientError, match="rows"):  # one sample: 6 rows < 12 parameters
        least_squares(Y[:1], tau[:1], exclude_joints=(0,), on_rank_deficient="warn")


def test_unexcited_column_is_named():
    rng = np.random.default_rng(11)
    Y = rng.normal(size=(30, 2, 4))
    Y[..., 2] = 0.0
    with pytest.raises(RankDeficientError, match="least excited: c "):
        least_squares(Y, Y @ np.ones(4), names=["a", "b", "c", "d"])


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_rank_deficient_warn_returns_scaled_minimum_norm_solution(same_q2, method):
    Y, tau, gravity_base, theta_true = same_q2
    with pytest.warns(RuntimeWarning, match="mx2"):
        result = least_squares(
            Y,
            tau,
            exclude_joints=(0,),
            names=gravity_base.names,
            on_rank_deficient="warn",
            method=method,
        )
    assert result.rank == 11
    # Independent: pseudo-inverse of the column-scaled stack, min ||D theta||.
    A = Y[:, 1:, :].reshape(-1, 12)
    d = np.linalg.norm(A, axis=0)
    theta = np.linalg.pinv(A / d, rcond=1e-10) @ tau[:, 1:].reshape(-1) / d
    np.testing.assert_allclose(result.theta, theta, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(result.predict(Y)[:, 1:], tau[:, 1:], atol=1e-10)
    unidentifiable = np.isin(gravity_base.names, ["mx2", "mz2R"])
    assert np.all(np.isinf(result.std[unidentifiable]))
    assert np.all(np.isfinite(result.std[~unidentifiable]))
    np.testing.assert_allclose(
        result.theta[~unidentifiable], theta_true[~unidentifiable], rtol=1e-8
    )


# --- results and bad input ----------------------------------------------------------------------


def test_predict_and_table():
    Y, tau = random_problem(12)
    names = ["m1", "mx1", "Izz1R", "Fv1", "Fs1"]
    result = least_squares(Y, tau, names=names)
    assert isinstance(result, LeastSquaresResult)
    np.testing.assert_allclose(result.predict(Y), Y @ result.theta, rtol=1e-14)
    lines = result.table().splitlines()
    assert len(lines) == 6 and "rel.std %" in lines[0]
    for line, name, value in zip(lines[1:], names, result.theta):
        assert line.split()[0] == name and float(line.split()[1]) == pytest.approx(value, rel=1e-5)
    with pytest.raises(ValueError, match="Y"):
        result.predict(np.ones((3, 4)))


GOOD_Y, GOOD_TAU = random_problem(13)


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"Y": np.where(GOOD_Y[0, 0, 0] == GOOD_Y, np.nan, GOOD_Y)}, "Y"),
        ({"Y": GOOD_Y[:, :, 0]}, "tau"),  # (T, n) Y is a stacked system of T rows: tau (T,)
        ({"Y": GOOD_Y[:, 0], "tau": GOOD_TAU[:, :1]}, "tau"),
        ({"Y": GOOD_Y[:0, 0], "tau": GOOD_TAU[:0, 0]}, "Y"),
        ({"Y": GOOD_Y[:, 0], "tau": GOOD_TAU[:, 0], "exclude_joints": (0,)}, "exclude_joints"),
        ({"Y": GOOD_Y[:, 0], "tau": GOOD_TAU[:, 0], "exclude_joints": 0}, "exclude_joints"),
        ({"Y": GOOD_Y[0, 0]}, "Y"),
        ({"Y": "abc"}, "Y"),
        ({"tau": np.where(GOOD_TAU[0, 0] == GOOD_TAU, np.inf, GOOD_TAU)}, "tau"),
        ({"tau": GOOD_TAU[:-1]}, "tau"),
        ({"tau": GOOD_TAU[0]}, "tau"),
        ({"exclude_joints": (3,)}, "exclude_joints"),
        ({"exclude_joints": (-1,)}, "exclude_joints"),
        ({"exclude_joints": ("a",)}, "exclude_joints"),
        ({"exclude_joints": (True,)}, "exclude_joints"),
        ({"exclude_joints": 1}, "exclude_joints"),
        ({"exclude_joints": (0, 1, 2)}, "exclude_joints"),
        ({"method": "gls"}, "method"),
        ({"names": ["a", "b"]}, "names"),
        ({"on_rank_deficient": "ignore"}, "on_rank_deficient"),
        ({"rank_tolerance": 0.0}, "rank_tolerance"),
    ],
)
def test_bad_input_raises_value_error_naming_the_argument(kwargs, argument):
    arguments = {"Y": GOOD_Y, "tau": GOOD_TAU, **kwargs}
    with pytest.raises(ValueError, match=argument):
        least_squares(**arguments)
