"""The estimators' extension point (dynid.identification.estimators): a toy estimator defined
here, registered by one line, becomes ``identify_log(method=...)`` and ``--method``; it sees the
stacked problem of the training logs, its options are checked, its report is saved and loaded
with the result, and its row weights reach the physically consistent fit.

The toy estimator solves the stacked rows with numpy.linalg.lstsq (an independent solver): on
noisy data it must equal identify_log's own OLS to 1e-10.
"""

from __future__ import annotations

import argparse

import numpy as np
import pytest

import dynid
from dynid.cli.commands import estimator_options
from dynid.export.result_files import result_from_dict, result_to_dict
from dynid.identification.estimators import EstimatorFit, Problem, methods, register
from dynid.identification.estimators.registry import unregister
from dynid.identification.identify import LeastSquaresResult, relative_std
from dynid.identification.log_identification import identify_log
from dynid.logs import Log
from test_log_identification import fourier_log

SEEN: list[Problem] = []


def toy_lstsq(problem: Problem) -> EstimatorFit:
    """OLS by numpy on the kept rows of the kept joints; ``half`` weights the second half of the
    samples 0 (for the physical fit's row weights)."""
    SEEN.append(problem)
    rows = problem.keep.copy()
    rows[:, list(problem.excluded)] = False
    A, b = problem.Y[rows], problem.tau[rows]
    theta, *_ = np.linalg.lstsq(A, b, rcond=None)
    r = b - A @ theta
    sigma2 = r @ r / (A.shape[0] - A.shape[1])
    covariance = sigma2 * np.linalg.inv(A.T @ A)
    std = np.sqrt(np.diag(covariance))
    weights = None
    if problem.options.get("half"):
        weights = np.ones(problem.tau.shape)
        weights[problem.tau.shape[0] // 2 :] = 0.0
    result = LeastSquaresResult(
        theta=theta,
        std=std,
        relative_std=relative_std(theta, std),
        covariance=covariance,
        condition_number=float(np.linalg.cond(A)),
        rank=int(np.linalg.matrix_rank(A)),
        method="toy",
        noise_variance=np.ones(len(problem.joints)),
        residual_rms=np.full(len(problem.joints), np.sqrt(sigma2)),
        names=problem.names,
        excluded=problem.excluded,
        joints=problem.joints,
    )
    return EstimatorFit(result, weights, {"rows": int(A.shape[0])}, ("toy note",))


@pytest.fixture
def toy():
    register("toy", toy_lstsq, "numpy's lstsq", options=("half",))
    SEEN.clear()
    yield
    unregister("toy")


@pytest.fixture(scope="module")
def noisy():
    robot = dynid.models.planar_2r()
    log = fourier_log(robot, 3, seconds=10.0)
    rng = np.random.default_rng(0)
    tau = log.tau + rng.normal(scale=0.05, size=log.tau.shape)
    return robot, Log(t=log.t, q=log.q, tau=tau, qd=log.qd, qdd=log.qdd, source="noisy")


def test_registered_estimator_is_a_method_and_equals_ols(toy, noisy):
    robot, log = noisy
    assert "toy" in methods() and methods()[:2] == ("ols", "wls")
    ols = identify_log(log, robot, friction=True, offset=True, method="ols")
    got = identify_log(log, robot, friction=True, offset=True, method="toy")
    np.testing.assert_allclose(got.theta, ols.theta, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(got.std, ols.std, rtol=1e-8)
    assert got.method == "toy"
    assert got.estimator == {"method": "toy", "options": {}, "rows": 2 * log.T}
    assert "toy note" in got.training["notes"]
    (problem,) = SEEN
    assert problem.Y.shape == (log.T, 2, ols.theta.size) and problem.tau.shape == (log.T, 2)
    assert problem.names == ols.names and problem.start.method == "wls"
    np.testing.assert_allclose(problem.Y @ ols.theta, ols.fitted, rtol=0, atol=1e-12)


def test_rows_left_out_are_zero_and_not_kept(toy, noisy):
    robot, log = noisy
    identify_log(log, robot, friction=True, method="toy", preparation={"min_velocity": 0.3})
    problem = SEEN[-1]
    moving = np.abs(log.qd) >= 0.3
    assert np.array_equal(problem.keep, moving) and not moving.all()
    assert np.all(problem.Y[~moving] == 0) and np.all(problem.tau[~moving] == 0)


def test_options_are_checked(toy, noisy):
    robot, log = noisy
    with pytest.raises(ValueError, match=r"method: expected one of 'ols', 'wls'.*'toy'"):
        identify_log(log, robot, method="nope")
    with pytest.raises(
        ValueError, match="estimator_options: 'scale' not an option of method 'toy'"
    ):
        identify_log(log, robot, method="toy", estimator_options={"scale": 2})
    with pytest.raises(ValueError, match="estimator_options: 'half' not an option of method 'wls'"):
        identify_log(log, robot, method="wls", estimator_options={"half": True})
    with pytest.raises(ValueError, match="estimator_options: expected a mapping"):
        identify_log(log, robot, method="toy", estimator_options=[("half", True)])
    with pytest.raises(ValueError, match="method: an estimator named 'ols' exists already"):
        register("ols", toy_lstsq, "no")


def test_cli_flags_are_the_options(toy):
    args = argparse.Namespace(half=True)
    assert estimator_options(args, "toy") == {"half": True}
    with pytest.raises(ValueError, match="--half: not an option of --method wls"):
        estimator_options(args, "wls")
    assert estimator_options(argparse.Namespace(half=None), "wls") == {}


def test_report_is_saved_and_loaded(toy, noisy):
    robot, log = noisy
    got = identify_log(log, robot, friction=True, method="toy", estimator_options={"half": True})
    data = result_to_dict(got)
    assert data["estimator"] == {"method": "toy", "options": {"half": True}, "rows": 2 * log.T}
    back = result_from_dict(data)
    assert back.estimator == got.estimator and back.method == "toy"
    data["estimator"]["method"] = "wls"
    with pytest.raises(ValueError, match=r"estimator\.method: expected 'toy'"):
        result_from_dict(data)


def test_row_weights_reach_the_physical_fit(toy, noisy):
    """Row weights 0 on the second half: the physical fit equals the one on the first half
    alone (OLS weights there: the toy's noise variances are all 1)."""
    robot, log = noisy
    half = log.T // 2
    first = Log(
        t=log.t[:half], q=log.q[:half], tau=log.tau[:half], qd=log.qd[:half], qdd=log.qdd[:half]
    )
    weighted = identify_log(
        log, robot, friction=True, method="toy", physical=True, estimator_options={"half": True}
    )
    alone = identify_log(first, robot, friction=True, method="ols", physical=True)
    scale = np.abs(alone.theta).max()
    np.testing.assert_allclose(weighted.theta, alone.theta, rtol=0, atol=1e-5 * scale)
    unweighted = identify_log(log, robot, friction=True, method="toy", physical=True)
    assert np.abs(unweighted.theta - alone.theta).max() > 1e-3 * scale
