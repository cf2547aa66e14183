"""Least squares from triangular factors (R of [Y | tau] per joint, chunk by chunk, no Q) against
the textbook formulas evaluated directly on the stacked matrix (lecture p. 27): numpy's lstsq for
the estimate, sigma^2 pinv(A) pinv(A)^T for the OLS covariance, the WLS weights from the per-joint
OLS residuals. Tolerance 1e-9 relative (the issue's contract) on theta, std, the noise variances
and the residual RMS; the rank-deficient error is the same as least_squares'.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.identify import RankDeficientError, stack_by_joint

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
