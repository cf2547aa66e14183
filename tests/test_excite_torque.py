"""Torque limits of the exciting trajectory (issue 21, item 1; docs/excitation.md, "Torque limits").

Independent computations: the constraint's Jacobian against central differences of robot.rnea
on trajectories evaluated here; the bound of |tau| over the period against robot.rnea on a grid
100x denser; the optimiser's result against every limit (q, qd, qdd, tau) on a grid 100x denser
than its samples, and its condition number against the optimiser run without torque limits.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from coupled_robots import coupled_puma
from dynid.excitation import FourierTrajectory, optimize_excitation, rest_to_rest
from dynid.excitation.torque_limits import TorqueConstraint, torque_extents, torque_scale

SEED = 20261127


@pytest.fixture(scope="module")
def lwr():
    return dynid.models.kuka_lwr4()  # rotor inertias, viscous and Coulomb friction


def random_trajectory(rng, n, harmonics=3, period=8.0, amplitude=0.3) -> FourierTrajectory:
    ell = np.arange(1.0, harmonics + 1)
    return FourierTrajectory(
        2 * np.pi / period,
        amplitude * rng.normal(size=(n, harmonics)) / ell,
        amplitude * rng.normal(size=(n, harmonics)) / ell,
        rng.uniform(-0.5, 0.5, n),
    )


def dense_torque(robot, traj, points) -> np.ndarray:
    t = traj.period * np.arange(points) / points
    return np.abs(robot.rnea(*traj.evaluate(t))).max(axis=0)


def test_constraint_jacobian_matches_central_differences_of_rnea(lwr) -> None:
    rng = np.random.default_rng(SEED)
    traj = random_trajectory(rng, lwr.n)
    t = np.linspace(0.0, traj.period, 13, endpoint=False)
    limit = np.full(lwr.n, 50.0)
    constraint = TorqueConstraint(lwr, t, traj.base_frequency, traj.harmonics, limit)
    x = traj.to_vector()
    value, J = constraint.value(x), constraint.jacobian(x)
    tau = lwr.rnea(*traj.evaluate(t))
    np.testing.assert_allclose(
        value, np.concatenate([50 - tau.ravel(), 50 + tau.ravel()]), atol=1e-12
    )
    h = 1e-6
    for k in rng.choice(x.size, 12, replace=False):
        step = np.zeros(x.size)
        step[k] = h

        def torque(v):
            f = FourierTrajectory.from_vector(v, lwr.n, traj.harmonics, traj.base_frequency)
            return lwr.rnea(*f.evaluate(t)).ravel()

        # qd keeps its signs under a 1e-6 step here, so Coulomb friction is constant
        difference = (torque(x + step) - torque(x - step)) / (2 * h)
        np.testing.assert_allclose(J[tau.size :, k], difference, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(J[: tau.size, k], -difference, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("at_rest", [False, True])
def test_torque_bound_holds_on_a_grid_100_times_denser_and_is_tight(lwr, at_rest) -> None:
    rng = np.random.default_rng(SEED + 1)
    for _ in range(3):
        traj = random_trajectory(rng, lwr.n, harmonics=4)
        traj = rest_to_rest(traj) if at_rest else traj
        bound = torque_extents(lwr, traj, 400)
        dense = dense_torque(lwr, traj, 40_000)
        assert np.all(bound >= dense)
        # tight up to the Coulomb torque where the bound cannot tell a sign change (a start at
        # rest: qd = 0 there) and the curvature term (~1e-6)
        assert np.all(bound - dense <= 2 * lwr.Fs + 1e-3)


def test_torque_bound_of_a_coupled_wrist_holds_on_a_dense_grid() -> None:
    robot = coupled_puma()
    rng = np.random.default_rng(SEED + 2)
    traj = random_trajectory(rng, robot.n)
    assert np.all(torque_extents(robot, traj, 400) >= dense_torque(robot, traj, 40_000))


def test_torque_scale_meets_the_limits_or_names_gravity(lwr) -> None:
    rng = np.random.default_rng(SEED + 3)
    traj = random_trajectory(rng, lwr.n, amplitude=1.0)
    peak = dense_torque(lwr, traj, 40_000)
    gravity = np.abs(lwr.gravity(traj.q0))
    limit = 0.5 * (peak + gravity) + 0.5  # between standing at q0 and the motion's peak
    factor = torque_scale(lwr, traj, limit, 400)
    assert 0.0 < factor < 1.0
    shrunk = FourierTrajectory(traj.base_frequency, factor * traj.a, factor * traj.b, traj.q0)
    assert np.all(dense_torque(lwr, shrunk, 40_000) <= limit)
    with pytest.raises(ValueError, match="tau_max: the gravity torque"):
        torque_scale(lwr, traj, np.maximum(0.5 * gravity, 1e-3), 400)


# a small case as in test_excitation.py: 2 harmonics, 40 samples, a few SLSQP iterations
SMALL = {"harmonics": 2, "period": 8.0, "samples": 40, "qdd_max": 1.5, "seed": 3, "maxiter": 8}
TAU_MAX = np.array([60.0, 40.0, 25.0, 15.0, 5.0, 3.0, 2.0])


@pytest.fixture(scope="module")
def limited(lwr):
    return {
        at_rest: optimize_excitation(lwr, **SMALL, at_rest=at_rest, tau_max=TAU_MAX)
        for at_rest in (False, True)
    }


@pytest.mark.parametrize("at_rest", [False, True])
def test_every_limit_holds_on_a_grid_100_times_denser(lwr, limited, at_rest) -> None:
    result = limited[at_rest]
    span = lwr.qlim[:, 1] - lwr.qlim[:, 0]
    qlim = lwr.qlim + np.outer(span, [0.02, -0.02])
    for traj in (result.trajectory, result.initial):
        t = traj.period * np.arange(100 * SMALL["samples"]) / (100 * SMALL["samples"])
        q, qd, qdd = traj.evaluate(t)
        assert np.all(q >= qlim[:, 0]) and np.all(q <= qlim[:, 1])
        assert np.all(np.abs(qd) <= 1.0) and np.all(np.abs(qdd) <= 1.5)
        assert np.all(np.abs(lwr.rnea(q, qd, qdd)) <= TAU_MAX)
    # the limits matter: without them the optimum's torque exceeds some
    free = optimize_excitation(lwr, **SMALL, at_rest=at_rest)
    assert np.any(dense_torque(lwr, free.trajectory, 4000) > TAU_MAX)
    assert result.condition_after < result.condition_before


@pytest.mark.parametrize("at_rest", [False, True])
def test_loose_torque_limits_leave_the_condition_number_as_without(lwr, at_rest) -> None:
    free = optimize_excitation(lwr, **SMALL, at_rest=at_rest)
    loose = optimize_excitation(lwr, **SMALL, at_rest=at_rest, tau_max=1e6)
    assert loose.condition_after <= free.condition_after * (1 + 1e-9)


def test_torque_of_a_prior_model_is_the_one_limited(lwr) -> None:
    prior = lwr.with_payload(3.0, [0.0, 0.0, 0.1])  # heavier than the model optimised
    result = optimize_excitation(lwr, **SMALL, tau_max=TAU_MAX, torque_model=prior)
    assert np.all(dense_torque(prior, result.trajectory, 4000) <= TAU_MAX)


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"tau_max": -1.0}, "tau_max"),
        ({"tau_max": [1.0, 2.0]}, "tau_max"),
        ({"tau_max": np.nan}, "tau_max"),
        ({"tau_max": 100.0, "torque_model": "lwr"}, "torque_model"),
        ({"tau_max": 100.0, "torque_model": dynid.models.planar_2r()}, "torque_model"),
        ({"tau_max": 1e-3}, "tau_max"),  # gravity alone exceeds it
    ],
)
def test_bad_torque_arguments_raise_value_error_naming_them(lwr, kwargs, argument) -> None:
    with pytest.raises(ValueError, match=argument):
        optimize_excitation(lwr, harmonics=2, samples=30, maxiter=0, **kwargs)


def test_progress_reports_each_iteration(lwr) -> None:
    seen: list[tuple[int, float]] = []
    result = optimize_excitation(lwr, **SMALL, progress=lambda i, c: seen.append((i, c)))
    assert [i for i, _ in seen] == list(range(1, result.iterations + 1))
    assert all(np.isfinite(c) and c >= 1.0 for _, c in seen)
