"""Exciting trajectories: the Fourier series, its limits, and the optimisation of its coefficients.

Every check is against an independent computation: the series summed term by term from its
formula, finite differences, a closed-form single harmonic, and the condition number recomputed
here with np.linalg.cond on a regressor stacked here.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.excitation import (
    ExcitationResult,
    FourierTrajectory,
    excitation_condition_number,
    optimize_excitation,
    rest_to_rest,
)

SEED = 20240611


def random_trajectory(
    rng: np.random.Generator, n: int = 3, harmonics: int = 4
) -> FourierTrajectory:
    return FourierTrajectory(
        base_frequency=rng.uniform(0.3, 1.5),
        a=rng.normal(size=(n, harmonics)),
        b=rng.normal(size=(n, harmonics)),
        q0=rng.uniform(-1.0, 1.0, n),
    )


def series(traj: FourierTrajectory, t: np.ndarray) -> np.ndarray:
    """q(t) summed term by term from the formula of Swevers et al. (module docstring)."""
    q = np.tile(traj.q0, (t.size, 1))
    for i in range(traj.n):
        for ell in range(1, traj.harmonics + 1):
            w = traj.base_frequency * ell
            q[:, i] += traj.a[i, ell - 1] / w * np.sin(w * t) - traj.b[i, ell - 1] / w * np.cos(
                w * t
            )
    return q


def stacked_condition(robot, traj, samples, rotor=False, friction=False) -> float:
    """cond of the column-scaled base regressor, stacked sample by sample here."""
    base = dynid.base_parameters(robot, "torque", rotor=rotor, friction=friction)
    t = traj.period * np.arange(samples) / samples
    q, qd, qdd = traj.evaluate(t)
    rows = [
        robot.regressor(q[k], qd[k], qdd[k], rotor=rotor, friction=friction)[:, base.independent]
        for k in range(samples)
    ]
    W = np.vstack(rows)
    return float(np.linalg.cond(W / np.linalg.norm(W, axis=0)))


# ---- the series --------------------------------------------------------------------------------
def test_positions_match_the_formula_and_derivatives_match_finite_differences() -> None:
    traj = random_trajectory(np.random.default_rng(SEED))
    t = np.linspace(0.0, traj.period, 37)
    q, qd, qdd = traj.evaluate(t)
    np.testing.assert_allclose(q, series(traj, t), rtol=0, atol=1e-12)
    h = 1e-5  # central differences: truncation ~h^2 |q'''| ~ 1e-9, rounding ~1e-16/h ~ 1e-11
    q_plus, qd_plus, _ = traj.evaluate(t + h)
    q_minus, qd_minus, _ = traj.evaluate(t - h)
    np.testing.assert_allclose(qd, (q_plus - q_minus) / (2 * h), rtol=0, atol=1e-6)
    np.testing.assert_allclose(qdd, (qd_plus - qd_minus) / (2 * h), rtol=0, atol=1e-6)


def test_one_time_gives_one_sample() -> None:
    traj = random_trajectory(np.random.default_rng(SEED))
    q, qd, qdd = traj.evaluate(0.7)
    assert q.shape == qd.shape == qdd.shape == (traj.n,)
    np.testing.assert_allclose(q, series(traj, np.array([0.7]))[0], rtol=0, atol=1e-12)


def test_periodic() -> None:
    traj = random_trajectory(np.random.default_rng(SEED))
    start = traj.evaluate(np.array([0.0, 0.3]))
    end = traj.evaluate(np.array([0.0, 0.3]) + traj.period)
    for x0, x1 in zip(start, end):
        np.testing.assert_allclose(x1, x0, rtol=0, atol=1e-10)
    assert traj.period == pytest.approx(2 * np.pi / traj.base_frequency, rel=1e-15)


def test_sample_covers_one_period_without_repeating_the_end() -> None:
    traj = random_trajectory(np.random.default_rng(SEED))
    t, q, _, _ = traj.sample(50)
    np.testing.assert_allclose(t, traj.period * np.arange(50) / 50, rtol=0, atol=1e-15)
    np.testing.assert_allclose(q, series(traj, t), rtol=0, atol=1e-12)
    # q0 is the mean position: every harmonic averages out over the equally spaced samples
    np.testing.assert_allclose(q.mean(axis=0), traj.q0, rtol=0, atol=1e-12)
    t_fs, *_ = traj.sample(fs=100.0)
    assert t_fs[0] == 0.0 and t_fs[-1] < traj.period <= t_fs[-1] + 0.01 + 1e-12
    np.testing.assert_allclose(np.diff(t_fs), 0.01, rtol=0, atol=1e-12)


def test_vector_round_trip() -> None:
    traj = random_trajectory(np.random.default_rng(SEED))
    x = traj.to_vector()
    assert x.shape == (traj.n * (2 * traj.harmonics + 1),)
    back = FourierTrajectory.from_vector(x, traj.n, traj.harmonics, traj.base_frequency)
    for name in ("a", "b", "q0"):
        np.testing.assert_array_equal(getattr(back, name), getattr(traj, name))


def test_rest_to_rest_starts_and_ends_at_rest() -> None:
    traj = rest_to_rest(random_trajectory(np.random.default_rng(SEED)))
    _, qd, qdd = traj.evaluate(np.array([0.0, traj.period, 3 * traj.period]))
    np.testing.assert_allclose(qd, 0.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(qdd, 0.0, rtol=0, atol=1e-12)
    again = rest_to_rest(traj)  # a projection: nothing left to remove
    np.testing.assert_allclose(again.a, traj.a, rtol=0, atol=1e-15)
    np.testing.assert_allclose(again.b, traj.b, rtol=0, atol=1e-15)


def test_limits_margin_of_a_single_harmonic() -> None:
    # q = q0 + (a / w) sin(w t): |q - q0| <= a / w, |qd| <= a, |qdd| <= a w, all attained
    w, amplitude, q0 = 0.8, 0.6, 0.2
    traj = FourierTrajectory(w, [[amplitude]], [[0.0]], [q0])
    margins = traj.limits_margin([[-1.0, 1.5]], qd_max=1.0, qdd_max=0.4)
    exact = (
        min(1.5 - q0 - amplitude / w, q0 - amplitude / w + 1.0),
        1.0 - amplitude,
        0.4 - amplitude * w,
    )
    got = (margins.position[0], margins.velocity[0], margins.acceleration[0])
    for lower_bound, value in zip(got, exact):
        assert value - 1e-4 <= lower_bound <= value  # guaranteed (never above), and tight
    assert not margins.satisfied  # a w = 0.48 exceeds 0.4
    assert traj.limits_margin([[-1.0, 1.5]], 1.0, 1.0).satisfied


# ---- condition number and optimisation ---------------------------------------------------------
@pytest.fixture(scope="module")
def lwr():
    return dynid.models.kuka_lwr4()


@pytest.mark.parametrize(("rotor", "friction"), [(False, False), (True, True)])
def test_condition_number_matches_an_independent_stacking(lwr, rotor, friction) -> None:
    rng = np.random.default_rng(SEED)
    traj = FourierTrajectory(
        0.6, 0.3 * rng.normal(size=(7, 3)), 0.3 * rng.normal(size=(7, 3)), rng.uniform(-1.0, 1.0, 7)
    )
    got = excitation_condition_number(lwr, traj, samples=40, rotor=rotor, friction=friction)
    expected = stacked_condition(lwr, traj, 40, rotor, friction)
    assert got == pytest.approx(expected, rel=1e-8)
    unscaled = excitation_condition_number(lwr, traj, 40, rotor, friction, scaled=False)
    base = dynid.base_parameters(lwr, "torque", rotor=rotor, friction=friction)
    _, q, qd, qdd = traj.sample(40)
    W = base.reduce(lwr.regressor(q, qd, qdd, rotor=rotor, friction=friction)).reshape(
        -1, base.count
    )
    assert unscaled == pytest.approx(np.linalg.cond(W), rel=1e-8)


def test_gradient_of_the_objective_matches_finite_differences(lwr) -> None:
    from dynid.excitation.optimization import (
        _LogCondition,  # the optimiser's core, checked directly
    )

    rng = np.random.default_rng(SEED)
    base = dynid.base_parameters(lwr, "torque", rotor=True, friction=True)
    t = 10.0 * np.arange(40) / 40
    objective = _LogCondition(lwr, base, t, 2 * np.pi / 10.0, 3, True, True)
    x = np.concatenate([0.3 * rng.normal(size=42), rng.uniform(-1.0, 1.0, 7)])
    gradient = objective.gradient(x)
    h = 1e-6  # central differences of log cond: error ~1e-9 against a slope of order 1
    for direction in rng.normal(size=(4, x.size)):
        slope = (objective.value(x + h * direction) - objective.value(x - h * direction)) / (2 * h)
        assert gradient @ direction == pytest.approx(slope, rel=1e-5, abs=1e-7)


@pytest.fixture(scope="module")
def optimised(lwr) -> dict[bool, ExcitationResult]:
    # a small case: 2 harmonics, 40 samples, 5 SLSQP iterations (about a second each)
    qd_max = np.array([1.0, 0.8, 1.0, 0.8, 1.2, 1.2, 1.5])
    return {
        at_rest: optimize_excitation(
            lwr,
            harmonics=2,
            period=8.0,
            samples=40,
            qd_max=qd_max,
            qdd_max=1.5,
            at_rest=at_rest,
            seed=3,
            maxiter=5,
        )
        for at_rest in (False, True)
    }


@pytest.mark.parametrize("at_rest", [False, True])
def test_optimised_trajectory_respects_the_limits(lwr, optimised, at_rest) -> None:
    result = optimised[at_rest]
    qd_max = np.array([1.0, 0.8, 1.0, 0.8, 1.2, 1.2, 1.5])
    span = lwr.qlim[:, 1] - lwr.qlim[:, 0]
    qlim = lwr.qlim + np.outer(span, [0.02, -0.02])  # the default position_margin, 2 % of range
    for traj in (result.trajectory, result.initial):
        t = np.linspace(0.0, traj.period, 20001)  # 500 x the optimisation's samples
        q, qd, qdd = traj.evaluate(t)
        assert np.all(q >= qlim[:, 0]) and np.all(q <= qlim[:, 1])
        assert np.all(np.abs(qd) <= qd_max) and np.all(np.abs(qdd) <= 1.5)
        assert traj.harmonics == 2 and traj.period == pytest.approx(8.0, rel=1e-15)
    # the start is stretched until it touches its nearest limit (a fair comparison): the
    # smallest margin is zero up to the between-samples bound of a 400-point grid (~1e-4)
    margins = result.initial.limits_margin(qlim, qd_max, 1.5)
    smallest = min(margins.position.min(), margins.velocity.min(), margins.acceleration.min())
    assert 0.0 <= smallest < 1e-3


@pytest.mark.parametrize("at_rest", [False, True])
def test_optimisation_lowers_the_condition_number(lwr, optimised, at_rest) -> None:
    result = optimised[at_rest]
    before = stacked_condition(lwr, result.initial, 40)
    after = stacked_condition(lwr, result.trajectory, 40)
    assert result.condition_before == pytest.approx(before, rel=1e-8)
    assert result.condition_after == pytest.approx(after, rel=1e-8)
    assert after < 0.8 * before
    assert result.iterations <= 5


def test_at_rest_result_starts_and_ends_at_rest(optimised) -> None:
    traj = optimised[True].trajectory
    _, qd, qdd = traj.evaluate(np.array([0.0, traj.period]))
    np.testing.assert_allclose(qd, 0.0, rtol=0, atol=1e-10)
    np.testing.assert_allclose(qdd, 0.0, rtol=0, atol=1e-10)


def test_maxiter_zero_returns_the_start(lwr) -> None:
    result = optimize_excitation(lwr, harmonics=2, samples=30, maxiter=0, seed=1)
    assert result.iterations == 0 and not result.success
    assert result.trajectory is result.initial
    assert result.condition_after == result.condition_before


# ---- bad input ---------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"harmonics": 0}, "harmonics"),
        ({"harmonics": 2.0}, "harmonics"),
        ({"harmonics": 1, "at_rest": True}, "harmonics"),
        ({"period": -1.0}, "period"),
        ({"period": float("nan")}, "period"),
        ({"samples": 4}, "samples"),
        ({"qd_max": -1.0}, "qd_max"),
        ({"qd_max": [1.0, 2.0]}, "qd_max"),
        ({"qdd_max": 0.0}, "qdd_max"),
        ({"maxiter": -1}, "maxiter"),
        ({"position_margin": 0.5}, "position_margin"),
        ({"initial": "sine"}, "initial"),
        (
            {"initial": FourierTrajectory(1.0, np.ones((7, 5)), np.ones((7, 5)), np.zeros(7))},
            "initial",
        ),  # period 2 pi, not 10
    ],
)
def test_bad_arguments_raise_value_error_naming_them(lwr, kwargs, argument) -> None:
    with pytest.raises(ValueError, match=f"^{argument}:"):
        optimize_excitation(lwr, **kwargs)


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"base_frequency": 0.0}, "base_frequency"),
        ({"a": np.ones(3)}, "a"),
        ({"b": np.ones((2, 4))}, "b"),
        ({"q0": np.ones(3)}, "q0"),
        ({"a": [[np.inf, 0.0, 0.0], [0.0, 0.0, 0.0]]}, "a"),
    ],
)
def test_bad_trajectories_raise_value_error_naming_the_field(kwargs, argument) -> None:
    fields = {"base_frequency": 1.0, "a": np.ones((2, 3)), "b": np.ones((2, 3)), "q0": np.ones(2)}
    with pytest.raises(ValueError, match=f"^{argument}:"):
        FourierTrajectory(**{**fields, **kwargs})


def test_bad_sampling_and_limits_raise_value_error() -> None:
    traj = FourierTrajectory(1.0, np.ones((2, 3)), np.ones((2, 3)), np.zeros(2))
    with pytest.raises(ValueError, match=r"^samples, fs:"):
        traj.sample()
    with pytest.raises(ValueError, match=r"^samples, fs:"):
        traj.sample(10, fs=100.0)
    with pytest.raises(ValueError, match=r"^fs:"):
        traj.sample(fs=-1.0)
    with pytest.raises(ValueError, match=r"^qlim:"):
        traj.limits_margin(np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"^trajectory:"):
        rest_to_rest(FourierTrajectory(1.0, np.ones((2, 1)), np.ones((2, 1)), np.zeros(2)))
