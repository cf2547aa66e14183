"""Recursive least squares (dynid.RecursiveLeastSquares, C++): tests against independent
computations, on the KUKA LWR4 base regressor (7 x 43 blocks) where the issue asks for it.

- forgetting 1: the estimate and covariance equal the ridge-regularised batch solution computed by
  np.linalg.lstsq on the stacked data augmented with the prior rows (1e-8 relative), and plain
  least squares loosely (1e-6) when the prior is weak (P0 = 1e6 I);
- a full initial covariance and theta0: the batch solution with that prior (1e-8);
- forgetting < 1: the exponentially weighted batch solution, written in information form (1e-8);
- random small problems (hypothesis): the textbook recursion K, theta, P run in NumPy (1e-8);
- stationary noise: the error shrinks like 1/sqrt(T) and stays within 3 sigma of the predicted
  spread sigma^2 P; a payload grasped halfway is tracked with forgetting < 1 and not without;
- 10^5 updates: P exactly symmetric, positive definite (Cholesky), equal to the inverse of the
  weighted information matrix of the last samples (1e-6), i.e. no drift;
- windup: unexcited directions stay at the cap; batch == sequential updates bit for bit;
- bad input: ValueError naming the argument, estimator unchanged;
- no heap allocation per update: tests/cpp/test_rls_no_allocation.cpp compiled and run.
"""

from __future__ import annotations

import copy
import re
import threading
from collections.abc import Callable
from pathlib import Path

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import given, settings
from numpy.typing import NDArray

import dynid

RLS = dynid.RecursiveLeastSquares
REPO = Path(__file__).resolve().parents[1]
Array = NDArray[np.float64]


# --------------------------------------------------------------------------- data


@pytest.fixture(scope="module")
def lwr():
    robot = dynid.models.kuka_lwr4()
    return robot, dynid.base_parameters(robot)


def lwr_blocks(robot, base, count: int, seed: int) -> Array:
    """Base regressor blocks (count, 7, p) on random states within the joint limits."""
    rng = np.random.default_rng(seed)
    q = robot.random_configurations(count, seed=seed)
    qd = rng.uniform(-2.0, 2.0, (count, robot.n))
    qdd = rng.uniform(-4.0, 4.0, (count, robot.n))
    return base.reduce(robot.regressor(q, qd, qdd))


def with_payload(robot, mass: float, com: Array):
    """A copy of the robot with a point mass on the last link. Standard parameters of a point
    mass about the frame origin (docs/conventions.md, "Inertial parameters"): [m, m r, m (|r|^2 E -
    r r^T)]."""
    other = dynid.models.kuka_lwr4()
    params = np.array(robot.params, dtype=float)
    inertia = mass * (com @ com * np.eye(3) - np.outer(com, com))
    params[-1] += np.concatenate(
        [[mass], mass * com, inertia[0, [0, 1, 2]], inertia[1, [1, 2]], [inertia[2, 2]]]
    )
    other.params = params
    return other


def weighted_solution(
    Y: Array, tau: Array, forgetting: float, prior_information: Array, theta0: Array
) -> tuple[Array, Array]:
    """theta and P after T blocks, in information form (independent of the recursion):
    P^-1 = l^T P0^-1 + sum_k l^(T-k) Y_k^T Y_k, theta = P (l^T P0^-1 theta0 + sum ... Y_k^T tau_k).
    Solved by lstsq on the square-root-weighted stacked rows plus the prior's Cholesky rows."""
    T, p = Y.shape[0], Y.shape[-1]
    weights = np.sqrt(forgetting ** np.arange(T - 1, -1, -1.0))
    rows = (Y * weights[:, None, None]).reshape(-1, p)
    rhs = (tau * weights[:, None]).reshape(-1)
    prior_root = np.linalg.cholesky(forgetting**T * prior_information).T  # R^T R = prior
    A = np.vstack([rows, prior_root])
    b = np.concatenate([rhs, prior_root @ theta0])
    theta = np.linalg.lstsq(A, b, rcond=None)[0]
    return theta, np.linalg.inv(A.T @ A)


def relative(a: Array, b: Array) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


# --------------------------------------------------------------------------- equivalences


@pytest.mark.parametrize("c", [1e6, 10.0, 0.01])
def test_forgetting_one_equals_ridge_batch_solution(lwr, c):
    # c = 1e6 is the default (prior negligible); c = 10 and 0.01 make the prior visible, so that
    # a recursion that got P0 wrong fails the 1e-8 comparison.
    robot, base = lwr
    Y = lwr_blocks(robot, base, 300, seed=1)
    rng = np.random.default_rng(2)
    tau = Y @ base.values(robot) + 0.05 * rng.normal(size=Y.shape[:2])
    rls = RLS(base.count, 1.0, c)
    theta = rls.update_batch(Y, tau)

    W, t = Y.reshape(-1, base.count), tau.reshape(-1)
    augmented = np.vstack([W, np.eye(base.count) / np.sqrt(c)])
    ridge = np.linalg.lstsq(augmented, np.concatenate([t, np.zeros(base.count)]), rcond=None)[0]
    assert relative(theta, ridge) < 1e-8
    assert np.array_equal(theta, rls.theta)
    P = np.linalg.inv(W.T @ W + np.eye(base.count) / c)
    assert relative(rls.covariance, P) < 1e-8
    if c == 1e6:  # the weak prior moves the solution by ~1e-9 (relative)
        assert relative(theta, np.linalg.lstsq(W, t, rcond=None)[0]) < 1e-6


def test_initial_theta_and_full_covariance_are_a_prior(lwr):
    robot, base = lwr
    p = base.count
    rng = np.random.default_rng(3)
    Y = lwr_blocks(robot, base, 40, seed=4)  # 280 rows: the prior still matters
    tau = Y @ base.values(robot) + 0.1 * rng.normal(size=Y.shape[:2])
    A = rng.normal(size=(p, p))
    P0 = A @ A.T / p + 0.05 * np.eye(p)  # full, symmetric positive definite
    theta0 = rng.normal(size=p)
    expected, P = weighted_solution(Y, tau, 1.0, np.linalg.inv(P0), theta0)

    rls = RLS(p, initial_covariance=P0, theta0=theta0)
    assert relative(rls.covariance, P0) < 1e-12  # the UD factorisation of P0 is exact
    rls.update_batch(Y, tau)
    assert relative(rls.theta, expected) < 1e-8
    assert relative(rls.covariance, P) < 1e-8

    other = RLS(p)
    other.update_batch(Y[:5], tau[:5])
    other.reset(initial_covariance=P0, theta0=theta0)  # the same state through reset
    other.update_batch(Y, tau)
    assert np.array_equal(other.theta, rls.theta)


@pytest.mark.parametrize("forgetting", [0.99, 0.9])
def test_forgetting_equals_exponentially_weighted_batch_solution(lwr, forgetting):
    # max_variance huge: the windup cap must not act, so the recursion is the textbook one.
    robot, base = lwr
    p, c = base.count, 10.0
    rng = np.random.default_rng(5)
    Y = lwr_blocks(robot, base, 120, seed=6)
    tau = Y @ base.values(robot) + 0.1 * rng.normal(size=Y.shape[:2])
    rls = RLS(p, forgetting, c, max_variance=1e300)
    rls.update_batch(Y, tau)
    expected, P = weighted_solution(Y, tau, forgetting, np.eye(p) / c, np.zeros(p))
    assert relative(rls.theta, expected) < 1e-8
    assert relative(rls.covariance, P) < 1e-8


def textbook_recursion(Y, tau, forgetting, c):
    """The three equations of the docstring, as written, in NumPy (covariance form)."""
    p = Y.shape[-1]
    theta, P = np.zeros(p), c * np.eye(p)
    for Y_k, tau_k in zip(Y, tau):
        S = forgetting * np.eye(len(tau_k)) + Y_k @ P @ Y_k.T
        K = np.linalg.solve(S, Y_k @ P).T  # P Y^T S^-1 (S and P symmetric)
        theta = theta + K @ (tau_k - Y_k @ theta)
        P = (P - K @ Y_k @ P) / forgetting
    return theta, P


# Derandomized (the same examples every run, no database): CI must not be flaky. Forgetting
# factors below ~0.8 over 25 blocks inflate unexcited directions of P by lambda^-25 > 1e5; the
# textbook recursion used as the reference then loses more than 1e-8 itself.
@settings(max_examples=60, deadline=None, derandomize=True, database=None)
@given(
    p=st.integers(1, 8),
    m=st.integers(1, 5),
    blocks=st.integers(1, 25),
    forgetting=st.floats(0.8, 1.0),
    log_c=st.floats(-1.0, 3.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_matches_textbook_recursion(p, m, blocks, forgetting, log_c, seed):
    rng = np.random.default_rng(seed)
    Y = rng.normal(size=(blocks, m, p))
    tau = rng.normal(size=(blocks, m))
    c = 10.0**log_c
    rls = RLS(p, forgetting, c, max_variance=1e300)
    rls.update_batch(Y, tau)
    theta, P = textbook_recursion(Y, tau, forgetting, c)
    scale = np.linalg.norm(P)
    assert np.linalg.norm(rls.covariance - P) <= 1e-8 * scale
    assert np.linalg.norm(rls.theta - theta) <= 1e-8 * (np.linalg.norm(theta) + 1e-300) + 1e-12


def test_batch_equals_sequential_updates_exactly(lwr):
    robot, base = lwr
    Y = lwr_blocks(robot, base, 200, seed=7)
    tau = Y @ base.values(robot)
    sequential = RLS(base.count, 0.99)
    estimates = []
    for Y_k, tau_k in zip(Y, tau):
        sequential.update(Y_k, tau_k)
        estimates.append(sequential.theta)
    batch = RLS(base.count, 0.99)
    history = batch.update_batch(Y, tau, history=True)
    assert np.array_equal(history, np.array(estimates))
    assert np.array_equal(batch.theta, sequential.theta)
    assert np.array_equal(batch.covariance, sequential.covariance)

    # One row per block: Y (T, p) with tau (T,), and update(Y_k (p,), tau_k scalar).
    rows, torques = Y[:, 2, :], tau[:, 2]
    single = RLS(base.count, 0.95)
    for Y_k, tau_k in zip(rows, torques):
        single.update(Y_k, float(tau_k))
    assert np.array_equal(RLS(base.count, 0.95).update_batch(rows, torques), single.theta)


# --------------------------------------------------------------------------- behaviour


def test_converges_on_stationary_noisy_data(lwr):
    robot, base = lwr
    sigma = 0.5  # N m, white torque noise
    rng = np.random.default_rng(8)
    Y = lwr_blocks(robot, base, 4000, seed=9)
    theta_true = base.values(robot)
    tau = Y @ theta_true + sigma * rng.normal(size=Y.shape[:2])
    rls = RLS(base.count)
    history = rls.update_batch(Y, tau, history=True)
    errors = np.linalg.norm(history - theta_true, axis=1)
    # Spread of the estimate: E|theta - theta_true|^2 = sigma^2 trace(P); 43 degrees of freedom
    # keep the ratio near 1, so 3x only fails when the estimate is wrong.
    predicted = sigma * np.sqrt(np.trace(rls.covariance))
    assert errors[-1] < 3.0 * predicted
    # 1/sqrt(T): from 100 to 4000 samples the error falls ~6x; ask for 3x.
    assert errors[-1] < errors[99] / 3.0
    # The residual on fresh data is the noise alone.
    Y_new = lwr_blocks(robot, base, 500, seed=10)
    tau_new = Y_new @ theta_true + sigma * rng.normal(size=Y_new.shape[:2])
    rms = np.sqrt(np.mean((tau_new - Y_new @ rls.theta) ** 2))
    assert rms == pytest.approx(sigma, rel=0.05)


def test_tracks_a_payload_with_forgetting(lwr):
    # A 3 kg payload grasped by the last link halfway through the log (notes pp. 32-33, "rule of
    # change in dynamic parameters": only the last link's standard parameters change).
    robot, base = lwr
    loaded = with_payload(robot, 3.0, np.array([0.02, -0.01, 0.08]))
    before, after = base.values(robot), base.values(loaded)
    change = np.linalg.norm(after - before)
    half = 1500
    Y = lwr_blocks(robot, base, 2 * half, seed=11)
    rng = np.random.default_rng(12)
    tau = np.concatenate([Y[:half] @ before, Y[half:] @ after])
    tau += 0.05 * rng.normal(size=tau.shape)

    forgetting = 0.99  # memory ~ 1 / (1 - lambda) = 100 samples
    history = RLS(base.count, forgetting).update_batch(Y, tau, history=True)
    error = np.linalg.norm(history[half:] - after, axis=1) / change
    assert np.linalg.norm(history[half - 1] - before) < 0.01 * change  # converged before
    assert error[0] > 0.5  # the change is seen as an error at first
    # The old data weigh lambda^k after k samples: the error decays below ~e^-1, e^-3, ...
    assert error[100] < 0.5
    assert error[300] < 0.1
    assert error[-1] < 0.01
    assert np.all(np.diff(error[:300:20]) < 0)  # monotone decay, sampled every 20 steps

    # Without forgetting the estimate stays a compromise between the two halves.
    without = RLS(base.count, 1.0).update_batch(Y, tau)
    assert np.linalg.norm(without - after) > 0.2 * change


@pytest.mark.parametrize("forgetting", [1.0, 0.995])
def test_covariance_stays_symmetric_positive_definite_over_1e5_updates(lwr, forgetting):
    robot, base = lwr
    p = base.count
    pool = lwr_blocks(robot, base, 1000, seed=13)  # 10^5 updates cycle through these blocks
    rng = np.random.default_rng(14)
    theta_true = base.values(robot)
    rls = RLS(p, forgetting)
    for _ in range(100):
        tau = pool @ theta_true + 0.05 * rng.normal(size=pool.shape[:2])
        rls.update_batch(pool, tau)
        P = rls.covariance
        assert np.all(np.isfinite(P))
        assert np.array_equal(P, P.T)
        np.linalg.cholesky(P)  # raises LinAlgError unless positive definite
    assert relative(rls.theta, theta_true) < 1e-3
    # No drift: P equals the inverse of the information of the data it has seen (the prior's
    # share has decayed to nothing: 1e-6/1e5 with lambda = 1, lambda^(1e5) with 0.995).
    weights = forgetting ** np.arange(len(pool) - 1, -1, -1.0)
    information = np.einsum("t,tmi,tmj->ij", weights, pool, pool)
    cycles = 100 if forgetting == 1.0 else 1.0 / (1.0 - forgetting ** len(pool))
    assert relative(rls.covariance, np.linalg.inv(cycles * information)) < 1e-6


def test_windup_is_capped_in_unexcited_directions():
    # Only the first 5 of 12 parameters are excited. With lambda = 0.9, 300 updates would grow
    # the other variances by 0.9^-300 ~ 5e13 (and overflow to inf after ~7000); the cap keeps
    # them at the prior, or at max_variance when given. The excited block is untouched by it.
    p, c = 12, 100.0
    rng = np.random.default_rng(15)
    Y = np.zeros((300, 3, p))
    Y[:, :, :5] = rng.normal(size=(300, 3, 5))
    tau = rng.normal(size=(300, 3))
    for max_variance, expected in [(None, c), (1e8, 1e8), (1e300, c * 0.9**-300)]:
        rls = RLS(p, 0.9, c, max_variance=max_variance)
        rls.update_batch(Y, tau)
        P = rls.covariance
        assert rls.max_variance == (c if max_variance is None else max_variance)
        np.testing.assert_allclose(P[5:, 5:], expected * np.eye(p - 5), rtol=1e-12)
        assert np.all(P[:5, 5:] == 0.0)
        reference, P_excited = weighted_solution(Y[:, :, :5], tau, 0.9, np.eye(5) / c, np.zeros(5))
        assert relative(P[:5, :5], P_excited) < 1e-8
        assert relative(rls.theta[:5], reference) < 1e-8
    long = RLS(p, 0.9, c)
    for _ in range(30):  # 9000 updates: far past the overflow of 0.9^-k
        long.update_batch(Y, tau)
    assert np.all(np.isfinite(long.covariance))
    assert np.all(np.isfinite(long.theta))


def test_reset_copy_and_properties(lwr):
    robot, base = lwr
    Y = lwr_blocks(robot, base, 20, seed=16)
    tau = Y @ base.values(robot)
    rls = RLS(base.count, 0.98, 1e4)
    assert (rls.p, rls.forgetting, rls.max_variance) == (base.count, 0.98, 1e4)
    assert repr(rls) == f"RecursiveLeastSquares(p={base.count}, forgetting=0.98)"
    rls.update_batch(Y, tau)
    snapshot = copy.deepcopy(rls)
    rls.update_batch(Y, tau)
    assert not np.array_equal(snapshot.theta, rls.theta)  # the copy is independent
    rls.reset()
    assert np.array_equal(rls.theta, np.zeros(base.count))
    assert np.array_equal(rls.covariance, 1e4 * np.eye(base.count))
    rls.forgetting = 1.0
    assert rls.forgetting == 1.0
    theta = rls.theta
    theta[0] = 1.0  # a copy: the estimator does not change
    assert rls.theta[0] == 0.0


# --------------------------------------------------------------------------- bad input

P = 4
GOOD_Y, GOOD_TAU = np.ones((2, P)), np.ones(2)


def construct(**kwargs) -> Callable[[], object]:
    return lambda: RLS(**{"p": P, **kwargs})


BAD_CONSTRUCTION = [
    ("p", construct(p=0)),
    ("p", construct(p=-3)),
    ("p", construct(p=2.5)),
    ("p", construct(p="4")),
    ("p", construct(p=True)),
    ("forgetting", construct(forgetting=0.0)),
    ("forgetting", construct(forgetting=-0.5)),
    ("forgetting", construct(forgetting=1.0 + 1e-12)),
    ("forgetting", construct(forgetting=float("nan"))),
    ("forgetting", construct(forgetting="0.9")),
    ("initial_covariance", construct(initial_covariance=0.0)),
    ("initial_covariance", construct(initial_covariance=-1.0)),
    ("initial_covariance", construct(initial_covariance=float("inf"))),
    ("initial_covariance", construct(initial_covariance=float("nan"))),
    ("initial_covariance", construct(initial_covariance=np.eye(P - 1))),
    ("initial_covariance", construct(initial_covariance=np.ones(P))),
    (
        "initial_covariance",
        construct(initial_covariance=np.triu(np.ones((P, P)))),
    ),  # not symmetric
    (
        "initial_covariance",
        construct(initial_covariance=np.diag([1.0, 1.0, -1.0, 1.0])),
    ),
    ("initial_covariance", construct(initial_covariance=np.ones((P, P)))),  # singular
    ("initial_covariance", construct(initial_covariance="big")),
    ("theta0", construct(theta0=np.ones(P + 1))),
    ("theta0", construct(theta0=[np.nan] * P)),
    ("max_variance", construct(max_variance=0.0)),
    ("max_variance", construct(max_variance=-1.0)),
    ("max_variance", construct(max_variance=float("inf"))),
    ("max_variance", construct(max_variance=[1.0])),
]


@pytest.mark.parametrize(("name", "call"), BAD_CONSTRUCTION)
def test_bad_construction_raises_value_error_naming_argument(name, call):
    with pytest.raises(ValueError, match=rf"^{name}: "):
        call()


BAD_CALLS: list[tuple[str, Callable[[RLS], object]]] = [
    ("Y_k", lambda r: r.update(np.ones((2, P + 1)), GOOD_TAU)),
    ("Y_k", lambda r: r.update(np.ones((0, P)), np.ones(0))),
    ("Y_k", lambda r: r.update(np.ones((1, 2, P)), GOOD_TAU)),
    ("Y_k", lambda r: r.update(np.full((2, P), np.inf), GOOD_TAU)),
    ("Y_k", lambda r: r.update("Y", GOOD_TAU)),
    ("Y_k", lambda r: r.update(np.ones((2, P), dtype=complex), GOOD_TAU)),
    ("tau_k", lambda r: r.update(GOOD_Y, np.ones(3))),
    ("tau_k", lambda r: r.update(GOOD_Y, 1.0)),  # a number only for one row
    ("tau_k", lambda r: r.update(GOOD_Y, [1.0, np.nan])),
    ("tau_k", lambda r: r.update(np.ones(P), np.ones((1, 1)))),
    ("Y", lambda r: r.update_batch(np.ones((5, 2, P + 1)), np.ones((5, 2)))),
    ("Y", lambda r: r.update_batch(np.ones(P), np.ones(1))),
    ("Y", lambda r: r.update_batch(np.ones((5, 0, P)), np.ones((5, 0)))),
    ("tau", lambda r: r.update_batch(np.ones((5, 2, P)), np.ones((5, 3)))),
    ("tau", lambda r: r.update_batch(np.ones((5, 2, P)), np.ones(5))),
    ("tau", lambda r: r.update_batch(np.ones((5, P)), np.ones((5, 1)))),
    # A bad value in the last block: rejected before the first update (state checked below).
    (
        "Y",
        lambda r: r.update_batch(
            np.concatenate([np.ones((4, 2, P)), np.full((1, 2, P), np.nan)]),
            np.ones((5, 2)),
        ),
    ),
    (
        "tau",
        lambda r: r.update_batch(np.ones((5, 2, P)), np.r_[np.ones((4, 2)), [[1.0, np.inf]]]),
    ),
    (
        "history",
        lambda r: r.update_batch(np.ones((5, 2, P)), np.ones((5, 2)), history="yes"),
    ),
    ("forgetting", lambda r: setattr(r, "forgetting", 0.0)),
    ("forgetting", lambda r: setattr(r, "forgetting", None)),
    ("max_variance", lambda r: setattr(r, "max_variance", -2.0)),
    ("initial_covariance", lambda r: r.reset(initial_covariance=-np.eye(P))),
    ("theta0", lambda r: r.reset(theta0=np.ones(P - 1))),
]


@pytest.mark.parametrize(("name", "call"), BAD_CALLS)
def test_bad_call_raises_value_error_naming_argument_and_changes_nothing(name, call):
    rls = RLS(P, 0.9, 5.0)
    rls.update(np.arange(2.0 * P).reshape(2, P), [1.0, -1.0])
    theta, covariance = rls.theta, rls.covariance
    with pytest.raises(ValueError, match=rf"^{name}: "):
        call(rls)
    assert np.array_equal(rls.theta, theta)
    assert np.array_equal(rls.covariance, covariance)
    assert rls.forgetting == 0.9


def test_accepted_input_forms():
    # Lists, integers, float32, Fortran order and strided views give the float64 result.
    rng = np.random.default_rng(17)
    Y = rng.normal(size=(6, 3, P))
    tau = rng.normal(size=(6, 3))
    expected = RLS(P).update_batch(Y, tau)
    assert np.array_equal(RLS(np.int64(P)).update_batch(Y.tolist(), tau.tolist()), expected)
    assert np.array_equal(RLS(P).update_batch(np.asfortranarray(Y), tau), expected)
    wide = np.zeros((6, 3, 2 * P))
    wide[:, :, ::2] = Y
    assert np.array_equal(RLS(P).update_batch(wide[:, :, ::2], tau), expected)
    integers = RLS(P)
    integers.update(np.arange(3 * P).reshape(3, P), [1, 2, 3])
    floats = RLS(P)
    floats.update(np.arange(3.0 * P).reshape(3, P), [1.0, 2.0, 3.0])
    assert np.array_equal(integers.theta, floats.theta)
    empty = RLS(P)
    assert np.array_equal(empty.update_batch(np.ones((0, 2, P)), np.ones((0, 2))), np.zeros(P))


# --------------------------------------------------------------------------- real time


def test_update_makes_no_heap_allocation(cpp_tests, record_property):
    """Runs tests/cpp/test_rls_no_allocation.cpp (built against the installed package): it
    counts every operator new and malloc during 10^4 updates with 7 x 43 blocks (and blocks of
    1..24 rows) and exits non-zero on any. Skipped only without a C++ compiler."""
    output = cpp_tests.run("rls_no_allocation")
    assert re.search(r"^allocations_during_updates=0$", output, re.MULTILINE), output
    timing = re.search(r"us_per_update_median=([0-9.]+)", output)
    assert timing, output
    # Reported, not asserted (the machine may be busy): the target is < 10 us per update.
    record_property("us_per_update", float(timing.group(1)))
    print(output)


def test_one_estimator_shared_by_two_threads_runs_the_batches_one_after_the_other():
    """update_batch releases the GIL: two threads updating one estimator must not interleave
    (issue 22). The result is exactly that of the two batches in one of the two orders."""
    rng = np.random.default_rng(20261126)
    p, m, T = 43, 7, 20_000
    batches = [(rng.normal(size=(T, m, p)), rng.normal(size=(T, m))) for _ in range(2)]
    orders = []
    for order in ((0, 1), (1, 0)):
        serial = dynid.RecursiveLeastSquares(p)
        for k in order:
            serial.update_batch(*batches[k])
        orders.append(serial.theta)

    shared = dynid.RecursiveLeastSquares(p)
    start = threading.Barrier(2)

    def worker(k: int) -> None:
        start.wait()
        shared.update_batch(*batches[k])

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert any(np.array_equal(shared.theta, theta) for theta in orders), (
        np.abs(shared.theta - orders[0]).max(),
        np.abs(shared.theta - orders[1]).max(),
    )
