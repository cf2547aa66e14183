"""Physically consistent identification (dynid.physical_least_squares, docs/identification.md,
"Physically consistent identification") against independent computations.

The data come from the simulated KUKA LWR-IV of dynid.models (physically consistent links, rotor
inertias, viscous and Coulomb friction), at random states (q within the limits, |qd| <= 2 rad/s,
|qdd| <= 4 rad/s^2: every base parameter excited). The references: the true parameters, their
base values beta @ pi (base_parameters), the unconstrained least squares on the same data
(dynid.least_squares), the closed-form second moments of a uniform box, the C++ consistency check
(Robot.is_physically_consistent), RNEA against forward dynamics, eigenvalues of M(q).
"""

from __future__ import annotations

import copy
import pickle
import warnings

import numpy as np
import pytest

import dynid
from dynid.identification.identify import least_squares
from dynid.identification.log_identification import identify_log
from dynid.identification.physical import PhysicalIdentificationError, physical_least_squares
from dynid.logs import Log
from dynid.model.model_files import save_model
from dynid.model.pseudo_inertia import (
    nearest_with_margin,
    pseudo_inertia,
    standard_from_pseudo_inertia,
)

T = 300  # random states, 2100 stacked rows for 7 x 10 + 21 = 91 standard parameters


@pytest.fixture(scope="module")
def lwr():
    robot = dynid.models.kuka_lwr4()
    assert robot.is_physically_consistent() and robot.Ia.min() > 0 and robot.Fv.min() > 0
    return robot


def states(robot, count: int, seed: int):
    rng = np.random.default_rng(seed)
    q = robot.random_configurations(count, seed=seed)
    return q, rng.uniform(-2.0, 2.0, (count, robot.n)), rng.uniform(-4.0, 4.0, (count, robot.n))


@pytest.fixture(scope="module")
def data(lwr):
    q, qd, qdd = states(lwr, T, seed=1)
    Y = lwr.regressor(q, qd, qdd, rotor=True, friction=True)
    return Y, lwr.rnea(q, qd, qdd)


@pytest.fixture(scope="module")
def base(lwr):
    return dynid.base_parameters(lwr, rotor=True, friction=True)


@pytest.fixture(scope="module")
def exact(lwr, data):
    Y, tau = data
    return physical_least_squares(lwr, Y, tau, rotor=True, friction=True)


# --------------------------------------------------------------------------- pseudo-inertia


def test_pseudo_inertia_of_a_box_is_its_second_moment():
    """Uniform box, sides (a, b, c), mass m, centre at r, axes of frame i: integral of r r^T dm
    = m (diag(a^2, b^2, c^2) / 12 + r r^T), first moment m r (closed forms); exact to 1e-15."""
    m, sides, r = 2.5, np.array([0.3, 0.1, 0.05]), np.array([0.1, -0.2, 0.05])
    inertia_com = (
        m
        / 12
        * np.diag(
            [
                sides[1] ** 2 + sides[2] ** 2,
                sides[0] ** 2 + sides[2] ** 2,
                sides[0] ** 2 + sides[1] ** 2,
            ]
        )
    )
    robot = dynid.Robot.from_dh([[0, 0, 0, 0]])
    robot.set_link(0, m, r, inertia_com)
    J = pseudo_inertia(robot.params[0])
    np.testing.assert_allclose(
        J[:3, :3], m * (np.diag(sides**2) / 12 + np.outer(r, r)), rtol=0, atol=1e-15
    )
    np.testing.assert_allclose(J[:3, 3], m * r, rtol=0, atol=1e-15)
    assert J[3, 3] == m
    np.testing.assert_allclose(standard_from_pseudo_inertia(J), robot.params[0], rtol=0, atol=1e-15)


def test_positive_definite_pseudo_inertia_is_physical_consistency():
    """J > 0 (eigenvalues) agrees with the C++ check (m > 0, I_c > 0, triangle inequalities) on
    random parameter vectors, about half of them consistent."""
    rng = np.random.default_rng(3)
    robot = dynid.Robot.from_dh([[0, 0, 0, 0]])
    agree = consistent = 0
    for _ in range(400):
        r = rng.normal(0, 0.1, 3)
        L = rng.normal(0, 0.2, (3, 3))
        sigma_c = L @ L.T + rng.normal(0, 0.004) * np.eye(3)  # sometimes indefinite
        m = abs(rng.normal(1, 1)) * (1 if rng.random() < 0.9 else -1)
        J = np.zeros((4, 4))
        J[:3, :3] = m * (sigma_c / max(m, 1e-3) + np.outer(r, r)) if m > 0 else sigma_c
        J[:3, 3] = J[3, :3] = m * r
        J[3, 3] = m
        robot.params = standard_from_pseudo_inertia(J)[None]
        positive = np.linalg.eigvalsh(J).min() > 1e-12
        agree += positive == robot.is_physically_consistent()
        consistent += positive
    assert agree == 400 and 100 < consistent < 300


def test_nearest_with_margin_is_the_eigenvalue_clip():
    J = np.diag([2.0, -1e-9, 1e-3, 5.0])
    fixed = nearest_with_margin(J, 1e-6)
    np.testing.assert_array_equal(np.diag(fixed), [2.0, 1e-6, 1e-3, 5.0])
    np.testing.assert_array_equal(nearest_with_margin(fixed, 1e-6), fixed)


# --------------------------------------------------------------------------- recovery


def test_noise_free_data_give_the_true_base_parameters(lwr, base, exact):
    """No noise, no prior: the true base values to 1e-6 relative (each) plus 1e-9 of the
    largest (Clarabel's tolerances are ~1e-8); the residual below 1e-8 of the torques."""
    true = base.values(lwr)
    np.testing.assert_allclose(exact.base_values, true, rtol=1e-6, atol=1e-9 * np.abs(true).max())
    assert exact.status == "optimal" and exact.solver == "CLARABEL"
    assert exact.robot.is_physically_consistent()
    assert exact.min_eigenvalues.min() >= 1e-6 * (1 - 1e-12)  # the default margin holds
    assert np.all(exact.residual_rms < 1e-8 * 50)  # torques up to ~50 N m
    assert exact.solve_time > 0 and exact.objective < 1e-12


def test_noisy_data_stay_within_the_least_squares_uncertainty(lwr, base, data):
    """Gaussian noise of 1 % of each joint's RMS torque: the physical estimate's base values are
    within 5 standard deviations (WLS covariance of the unconstrained fit) of the truth."""
    Y, tau = data
    rms = np.sqrt(np.mean(tau**2, axis=0))
    noisy = tau + np.random.default_rng(5).normal(0, 0.01 * rms, tau.shape)
    ls = least_squares(Y[..., base.independent], noisy, method="wls")
    weights = 1 / np.sqrt(ls.noise_variance)
    fit = physical_least_squares(lwr, Y, noisy, rotor=True, friction=True, weights=weights)
    true = base.values(lwr)
    assert np.all(np.abs(fit.base_values - true) <= 5 * ls.std)
    assert np.all(np.abs(ls.theta - true) <= 5 * ls.std)  # the reference is sound
    np.testing.assert_allclose(fit.residual_rms, 0.01 * rms, rtol=0.1)  # the noise level


def test_prior_equal_to_the_truth_gives_the_full_standard_parameters(lwr, data):
    """With the truth as prior, the 91 - 62 directions the data cannot see come back too: every
    standard parameter to 1e-6 of the largest."""
    Y, tau = data
    fit = physical_least_squares(
        lwr, Y, tau, rotor=True, friction=True, prior=lwr, prior_weight=1e-4
    )
    truth = lwr.parameter_vector(True, True)
    np.testing.assert_allclose(fit.theta, truth, rtol=0, atol=1e-6 * np.abs(truth).max())


def test_the_unseen_directions_come_from_the_prior(lwr, base, data):
    """Prior = truth + delta with delta in the null space of beta (invisible in the torques):
    the estimate is the prior itself (its base values are the truth's, and its distance to the
    prior is 0), not the truth; to 1e-6 of the largest parameter."""
    Y, tau = data
    truth = lwr.parameter_vector(True, True)
    null = np.linalg.svd(base.beta)[2][base.count :].T  # (P, P - p)
    delta = null @ np.random.default_rng(7).normal(size=null.shape[1])
    delta[10 * lwr.n :] = 0.0
    delta = null @ np.linalg.lstsq(null, delta, rcond=None)[0]  # back in the null space
    prior = lwr.copy()
    scale = 0.02 / np.abs(delta).max()
    while True:  # the largest change (halving from 0.02) that keeps the prior consistent
        prior.params = (truth + scale * delta)[: 10 * lwr.n].reshape(lwr.n, 10)
        prior.Ia, prior.Fv, prior.Fs = (truth + scale * delta)[10 * lwr.n :].reshape(3, lwr.n)
        if prior.is_physically_consistent() and min(prior.Ia.min(), prior.Fv.min()) > 0:
            break
        scale /= 2
    assert np.abs(base.beta @ (scale * delta)).max() < 1e-14
    assert np.abs(scale * delta).max() > 1e-3  # a visible change of the standard parameters
    fit = physical_least_squares(
        lwr, Y, tau, rotor=True, friction=True, prior=prior, prior_weight=1e-3
    )
    np.testing.assert_allclose(
        fit.theta, prior.parameter_vector(True, True), rtol=0, atol=1e-6 * np.abs(truth).max()
    )
    np.testing.assert_allclose(
        fit.base_values, base.values(lwr), rtol=0, atol=1e-6 * np.abs(truth).max()
    )


def test_offsets_as_extra_columns_are_recovered(lwr, base, data):
    """Constant torque offsets (one per joint, any sign) added to tau and a column of ones per
    joint: recovered to 1e-7 N m, the base values unchanged."""
    Y, tau = data
    offsets = np.array([0.8, -0.9, 0.1, 0.2, -0.5, 0.3, -0.3])
    ones = np.broadcast_to(np.eye(lwr.n), (Y.shape[0], lwr.n, lwr.n))
    fit = physical_least_squares(
        lwr,
        np.concatenate([Y, ones], axis=2),
        tau + offsets,
        rotor=True,
        friction=True,
        extra_columns=lwr.n,
    )
    np.testing.assert_allclose(fit.extra, offsets, rtol=0, atol=1e-7)
    true = base.values(lwr)
    np.testing.assert_allclose(fit.base_values, true, rtol=1e-6, atol=1e-9 * np.abs(true).max())


# --------------------------------------------------------------------------- identifiability


@pytest.fixture(scope="module")
def unexciting(lwr):
    """Data that cannot determine the 62 base parameters: one sample (7 rows), and 300 random
    configurations at rest (qd = qdd = 0: only gravity acts, the inertias are invisible)."""
    q, qd, qdd = states(lwr, T, seed=41)
    still = np.zeros_like(qd)
    return {"one sample": (q[:1], qd[:1], qdd[:1]), "static": (q, still, still)}


def test_well_excited_data_have_full_rank_and_no_warning(lwr, base, data):
    """The 300 random states excite every base parameter (the unconstrained least squares on
    the same data has full rank): rank 62 of 62, nothing unidentified, no UserWarning."""
    Y, tau = data
    assert least_squares(Y[..., base.independent], tau).rank == base.count
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = physical_least_squares(lwr, Y, tau, rotor=True, friction=True)
    assert not [w for w in caught if issubclass(w.category, UserWarning)]
    assert fit.rank == fit.parameter_count == base.count and fit.unidentified == []


@pytest.mark.parametrize(("case", "rank"), [("one sample", 7), ("static", 12)])
def test_data_that_do_not_determine_the_parameters_warn_and_report_the_rank(
    lwr, base, unexciting, case, rank
):
    """Issue 22: these fits were "optimal" without a word, with unexcited base values off by
    100 % and more. Now a UserWarning says the data do not excite them and nothing but the
    solver fixes them, and the result reports the rank: 7 (one row per joint) and 12 (at rest
    the torque is gravity, a function of the masses and first moments only: the 12 base
    parameters m*, e.g. mx2, mz2R, my7); the same as the SVD of the column-scaled base
    regressor (numpy, 1e-10 as least_squares). The parameters not named unidentified are
    determined by these noise-free data: the true values (1e-6 relative)."""
    q, qd, qdd = unexciting[case]
    Y = lwr.regressor(q, qd, qdd, rotor=True, friction=True)
    with pytest.warns(UserWarning, match="do not excite.* Without a prior nothing fixes"):
        fit = physical_least_squares(lwr, Y, lwr.rnea(q, qd, qdd), rotor=True, friction=True)
    Yb = Y[..., base.independent].reshape(-1, base.count)
    norms = np.linalg.norm(Yb, axis=0)
    singular = np.linalg.svd(Yb / np.where(norms > 0, norms, 1.0), compute_uv=False)
    assert fit.rank == rank == np.count_nonzero(singular > 1e-10 * singular[0])
    assert fit.parameter_count == base.count
    determined = [j for j, name in enumerate(base.names) if name not in fit.unidentified]
    assert len(fit.unidentified) == base.count - len(determined)
    if case == "static":
        assert [base.names[j] for j in determined] == [
            name for name in base.names if name.startswith("m")
        ]
    true = base.values(lwr)
    np.testing.assert_allclose(fit.base_values[determined], true[determined], rtol=1e-6)


def test_with_a_prior_the_warning_says_the_prior_decides(lwr, unexciting):
    """Static data and the truth as prior: the warning says the 50 unexcited directions come
    from the prior, and the estimate is the prior (every standard parameter to 1e-6 of the
    largest), a legitimate result whose rank (12) is reported."""
    q, qd, qdd = unexciting["static"]
    Y = lwr.regressor(q, qd, qdd, rotor=True, friction=True)
    with pytest.warns(UserWarning, match="come from the prior"):
        fit = physical_least_squares(
            lwr, Y, lwr.rnea(q, qd, qdd), rotor=True, friction=True, prior=lwr, prior_weight=1e-4
        )
    truth = lwr.parameter_vector(True, True)
    np.testing.assert_allclose(fit.theta, truth, rtol=0, atol=1e-6 * np.abs(truth).max())
    assert fit.rank == 12 and len(fit.unidentified) == 50


# --------------------------------------------------------------------------- constraints


@pytest.fixture(scope="module")
def inconsistent(lwr):
    """A "robot" that cannot exist: link 4 with a negative mass and inertia, Ia6 < 0, Fv2 < 0."""
    bad = lwr.copy()
    params = bad.params.copy()
    params[3] *= -1.0
    bad.params = params
    bad.Ia = bad.Ia * np.array([1, 1, 1, 1, 1, -1, 1])
    bad.Fv = bad.Fv * np.array([1, -1, 1, 1, 1, 1, 1])
    assert not bad.is_physically_consistent()
    q, qd, qdd = states(lwr, T, seed=11)
    return bad, bad.regressor(q, qd, qdd, rotor=True, friction=True), bad.rnea(q, qd, qdd)


def test_data_of_an_impossible_robot_give_a_consistent_robot_and_a_larger_residual(
    lwr, base, inconsistent
):
    """Unconstrained LS fits these data exactly with inconsistent values; the SDP returns a
    consistent robot whose residual is at least the LS residual (it is optimal over a smaller
    set), and whose Ia, Fv are on their bounds where the truth is negative (active
    constraints, to 1e-6: an interior-point solution stays ~1e-8 inside)."""
    _bad, Y, tau = inconsistent
    ls = least_squares(Y[..., base.independent], tau)
    ls_sse = np.sum((tau - Y[..., base.independent] @ ls.theta) ** 2)
    fit = physical_least_squares(lwr, Y, tau, rotor=True, friction=True)
    sse = np.sum((tau - Y @ fit.theta) ** 2)
    assert sse >= ls_sse and sse > 1e3 * max(ls_sse, 1e-20)
    assert fit.robot.is_physically_consistent()
    assert fit.Ia[5] < 1e-6 and fit.Fv[1] < 1e-6
    assert np.all(fit.Ia >= 0) and np.all(fit.Fv >= 0) and np.all(fit.Fs >= 0)


def test_no_feasible_step_improves_the_optimum(lwr, inconsistent):
    """Optimality checked without the solver: from the estimate x, a step toward any feasible
    point y (random consistent links, random non-negative drive terms; x + e (y - x) is feasible
    by convexity) never lowers the sum of squared residuals, for e = 1e-3, 1e-2, 0.1 (to 1e-9
    relative: the solver's accuracy)."""
    _, Y, tau = inconsistent
    fit = physical_least_squares(lwr, Y, tau, rotor=True, friction=True)

    def sse(theta):
        return float(np.sum((tau - Y @ theta) ** 2))

    best = sse(fit.theta)
    rng = np.random.default_rng(13)
    for _ in range(30):
        y = np.empty_like(fit.theta)
        for i in range(lwr.n):
            L = rng.normal(0, 0.3, (4, 4))
            y[10 * i : 10 * i + 10] = standard_from_pseudo_inertia(L @ L.T + 1e-3 * np.eye(4))
        y[10 * lwr.n :] = rng.uniform(0, 2, 3 * lwr.n)
        for step in (1e-3, 1e-2, 0.1):
            assert sse(fit.theta + step * (y - fit.theta)) >= best * (1 - 1e-9)


def test_mass_bounds_and_total_mass_are_respected(lwr, base, data):
    """Bounds that exclude the true masses of links 3 and 5: the estimate sits in them (to
    1e-7 kg); a total mass equality holds to 1e-7 kg. No link mass of the LWR is a base
    parameter by itself, so these bounds only move the unseen directions: the base values stay
    the truth's (1e-6 relative plus 1e-7 of the largest: active bounds leave the interior-point
    solution a little less accurate)."""
    Y, tau = data
    m = lwr.params[:, 0]
    bounds = np.column_stack([0.5 * m, 2.0 * m])
    bounds[2] = [0.5 * m[2], 0.8 * m[2]]
    bounds[4] = [1.3 * m[4], np.inf]
    fit = physical_least_squares(lwr, Y, tau, rotor=True, friction=True, mass_bounds=bounds)
    masses = fit.params[:, 0]
    assert np.all(masses >= bounds[:, 0] - 1e-7) and np.all(masses <= bounds[:, 1] + 1e-7)
    total = physical_least_squares(lwr, Y, tau, rotor=True, friction=True, total_mass=1.1 * m.sum())
    assert abs(total.params[:, 0].sum() - 1.1 * m.sum()) < 1e-7
    true = base.values(lwr)
    for estimate in (fit, total):
        np.testing.assert_allclose(
            estimate.base_values, true, rtol=1e-6, atol=1e-7 * np.abs(true).max()
        )


def test_infeasible_bounds_raise_with_the_solver_status(lwr, data):
    """Every link at most 1 kg but 100 kg in total: no model, an error naming the status."""
    Y, tau = data
    with pytest.raises(PhysicalIdentificationError, match="infeasible") as info:
        physical_least_squares(
            lwr,
            Y,
            tau,
            rotor=True,
            friction=True,
            mass_bounds=np.tile([0.0, 1.0], (lwr.n, 1)),
            total_mass=100.0,
        )
    assert info.value.status == "infeasible"


# --------------------------------------------------------------------------- the result robot


def test_the_result_robot_is_usable(exact, data, lwr):
    """rnea of result.robot is Y @ theta (1e-9 relative); forward_dynamics inverts rnea (1e-8);
    M(q) is positive definite (Cholesky) at 500 random configurations."""
    _Y, _tau = data
    robot = exact.robot
    q, qd, qdd = states(lwr, 500, seed=21)
    tau_robot = robot.rnea(q, qd, qdd)
    Y500 = lwr.regressor(q, qd, qdd, rotor=True, friction=True)
    np.testing.assert_allclose(
        tau_robot, Y500 @ exact.theta, rtol=0, atol=1e-9 * np.abs(tau_robot).max()
    )
    np.testing.assert_allclose(robot.forward_dynamics(q, qd, tau_robot), qdd, rtol=0, atol=1e-8)
    M = robot.mass_matrix(q)
    np.linalg.cholesky(M)  # raises LinAlgError unless positive definite
    assert np.linalg.eigvalsh(M).min() > 0
    assert exact.Ia is not None and exact.Fv is not None and exact.Fs is not None
    np.testing.assert_array_equal(robot.Ia, exact.Ia)
    np.testing.assert_array_equal(robot.params, exact.params)


def test_terms_not_estimated_are_zero_in_the_result(lwr):
    """Rigid-body columns only, data of the links alone: Ia = Fv = Fs = 0 in the result robot,
    whose rnea reproduces the data (1e-7 relative)."""
    q, qd, qdd = states(lwr, T, seed=1)
    rigid = lwr.rigid_body()
    tau = rigid.rnea(q, qd, qdd)
    fit = physical_least_squares(lwr, lwr.regressor(q, qd, qdd), tau)
    assert fit.Ia is None and fit.Fv is None and fit.Fs is None
    assert not fit.robot.Ia.any() and not fit.robot.Fv.any() and not fit.robot.Fs.any()
    np.testing.assert_allclose(
        fit.robot.rnea(q, qd, qdd), tau, rtol=0, atol=1e-7 * np.abs(tau).max()
    )


def test_result_pickles_copies_and_compares(exact):
    again = pickle.loads(pickle.dumps(exact))
    assert again == exact and copy.deepcopy(exact) == exact and copy.copy(exact) == exact
    assert exact != "something else" and not (exact == 3)  # noqa: SIM201 (tests __eq__, not __ne__)
    np.testing.assert_array_equal(again.robot.params, exact.robot.params)
    q = again.robot.random_configurations(3)
    np.testing.assert_array_equal(again.robot.mass_matrix(q), exact.robot.mass_matrix(q))
    changed = copy.deepcopy(exact)
    changed.params = changed.params + 1.0
    assert changed != exact


def test_stacked_rows_and_per_row_weights_are_the_same_problem(lwr, data, exact):
    """(N, P) sample-major rows and (N,) torques give the (T, n, P) result; weights all 7 (per
    joint) or per row give the unweighted estimate (a common factor changes nothing), to the
    solver's tolerance (1e-6 of the largest base value)."""
    Y, tau = data
    P = Y.shape[2]
    flat = physical_least_squares(lwr, Y.reshape(-1, P), tau.reshape(-1), rotor=True, friction=True)
    scale = 1e-6 * np.abs(exact.base_values).max()
    np.testing.assert_allclose(flat.base_values, exact.base_values, rtol=0, atol=scale)
    for weights in (np.full(lwr.n, 7.0), np.full(tau.shape, 7.0), np.full(tau.size, 7.0)):
        weighted = physical_least_squares(lwr, Y, tau, rotor=True, friction=True, weights=weights)
        np.testing.assert_allclose(weighted.base_values, exact.base_values, rtol=0, atol=scale)


def test_zero_weights_leave_a_joint_out(lwr, base, data):
    """Joint 1's rows weighted 0 and its torques replaced by garbage: the other joints' data
    still give their base values (those of rows 2..7 are a subset; compared through the
    residual: the fit explains joints 2-7 to 1e-7 of their torques). The terms acting on joint
    1 alone (Iyy1R, Fv1, Fs1) are then unexcited: a UserWarning, rank 59 of 62."""
    Y, tau = data
    garbage = tau.copy()
    garbage[:, 0] = 1e3
    weights = np.ones(lwr.n)
    weights[0] = 0.0
    with pytest.warns(UserWarning, match="rank 59 < 62"):
        fit = physical_least_squares(lwr, Y, garbage, rotor=True, friction=True, weights=weights)
    assert fit.rank == 59 and sorted(fit.unidentified) == ["Fs1", "Fv1", "Iyy1R"]
    assert np.all(fit.residual_rms[1:] < 1e-7 * np.abs(tau).max())
    assert fit.residual_rms[0] > 100


# --------------------------------------------------------------------------- units


@pytest.mark.parametrize("weight", [1e200, 1e-200])
def test_huge_and_tiny_weights_give_the_unweighted_fit(lwr, data, exact, weight):
    """Weights 1e200 or 1e-200 on every joint (|w tau| up to ~5e201 or ~5e-199): a common
    factor, so the unweighted estimate (1e-6 of the largest base value, as for the weights 7
    above: the solver's tolerance ~1e-8 on the relative residual, amplified by the regressor's
    conditioning). Issue 22: the squared norm of w tau overflowed (resp. underflowed) and the
    fit explained zero torques (base values 70-90 % off)."""
    Y, tau = data
    weights = np.full(lwr.n, weight)
    fit = physical_least_squares(lwr, Y, tau, rotor=True, friction=True, weights=weights)
    scale = 1e-6 * np.abs(exact.base_values).max()
    np.testing.assert_allclose(fit.base_values, exact.base_values, rtol=0, atol=scale)
    assert np.all(fit.residual_rms < 1e-8 * np.abs(tau).max())  # as the unweighted fit's


@pytest.mark.parametrize(("tau_exponent", "Y_exponent"), [(600, 0), (-600, 0), (0, 600)])
def test_units_of_the_data_scale_the_estimate_by_powers_of_two(
    lwr, data, exact, tau_exponent, Y_exponent
):
    """tau * 2^b and Y * 2^a (|tau| ~ 2e182 or 2e-179, |Y| ~ 2e182), the margin in the same
    units (margin * 2^(b - a)): the estimate is the unscaled one times 2^(b - a), the residual
    RMS the unscaled one times 2^b. The solver sees the same problem (Y and tau are scaled by
    powers of two before it), so to rounding (1e-12 of the largest parameter), far below its
    tolerance. Issue 22: the solver failed on each (an error, or a margin violated by 5 %)."""
    Y, tau = data
    e = tau_exponent - Y_exponent
    fit = physical_least_squares(
        lwr,
        np.ldexp(Y, Y_exponent),
        np.ldexp(tau, tau_exponent),
        rotor=True,
        friction=True,
        margin=np.ldexp(1e-6, e),
    )
    assert fit.status == "optimal" and fit.robot.is_physically_consistent()
    np.testing.assert_allclose(
        np.ldexp(fit.theta, -e), exact.theta, rtol=0, atol=1e-12 * np.abs(exact.theta).max()
    )
    np.testing.assert_allclose(
        np.ldexp(fit.residual_rms, -tau_exponent), exact.residual_rms, rtol=1e-9, atol=1e-20
    )
    assert fit.min_eigenvalues.min() >= np.ldexp(1e-6, e) * (1 - 1e-12)  # the margin holds


@pytest.mark.parametrize("e", [600, -600])
def test_prior_and_bounds_in_the_units_of_the_data_scale_with_them(lwr, data, e):
    """The whole problem in other units: tau, the margin, the mass bounds, the total mass and
    the prior (the truth with every mass 10 % larger; all its parameters) times 2^e. The
    estimate is the one in SI units times 2^e, to rounding (1e-12 of the largest parameter:
    the solver sees the same problem), and the objective (relative) the same."""
    Y, tau = data
    prior = lwr.copy()
    prior.params = lwr.params * np.array([1.1] + [1.0] * 9)
    bounds, total = np.tile([0.1, 20.0], (lwr.n, 1)), np.array([1.0, 30.0])
    options = {"rotor": True, "friction": True, "prior_weight": 1e-4}
    si = physical_least_squares(
        lwr, Y, tau, prior=prior, mass_bounds=bounds, total_mass=total, **options
    )
    scaled_prior = prior.copy()
    scaled_prior.params = np.ldexp(prior.params, e)
    scaled_prior.Ia, scaled_prior.Fv, scaled_prior.Fs = (
        np.ldexp(x, e) for x in (prior.Ia, prior.Fv, prior.Fs)
    )
    fit = physical_least_squares(
        lwr,
        Y,
        np.ldexp(tau, e),
        prior=scaled_prior,
        mass_bounds=np.ldexp(bounds, e),
        total_mass=np.ldexp(total, e),
        margin=np.ldexp(1e-6, e),
        **options,
    )
    np.testing.assert_allclose(
        np.ldexp(fit.theta, -e), si.theta, rtol=0, atol=1e-12 * np.abs(si.theta).max()
    )
    assert fit.objective == pytest.approx(si.objective, rel=1e-9)


def test_huge_torques_with_the_default_margin_keep_the_base_values(lwr, data, exact):
    """tau * 2^600 with the default margin (1e-6, now 2^-600 times smaller relative to the
    parameters): the standard parameters the data do not see may move, the base values are the
    unscaled ones times 2^600 (1e-6 of the largest, the tolerance used above)."""
    Y, tau = data
    fit = physical_least_squares(lwr, Y, np.ldexp(tau, 600), rotor=True, friction=True)
    scale = 1e-6 * np.abs(exact.base_values).max()
    np.testing.assert_allclose(
        np.ldexp(fit.base_values, -600), exact.base_values, rtol=0, atol=scale
    )


# --------------------------------------------------------------------------- bad arguments


def _call(lwr, data, **changes):
    Y, tau = data
    kwargs = {"robot": lwr, "Y": Y, "tau": tau, "rotor": True, "friction": True}
    kwargs.update(changes)
    return physical_least_squares(**kwargs)


@pytest.mark.parametrize(
    ("changes", "name"),
    [
        ({"robot": "kuka"}, "robot"),
        ({"Y": np.zeros((10, 7, 5))}, "Y"),
        ({"Y": np.zeros((10, 5, 91))}, "Y"),
        ({"Y": np.zeros((13, 91))}, "Y"),
        ({"Y": np.zeros(91)}, "Y"),
        ({"Y": "text"}, "Y"),
        ({"tau": np.zeros((3, 7))}, "tau"),
        ({"tau": np.full((T, 7), np.nan)}, "tau"),
        ({"rotor": 1}, "rotor"),
        ({"friction": "yes"}, "friction"),
        ({"weights": -np.ones(7)}, "weights"),
        ({"weights": np.zeros(7)}, "weights"),
        ({"weights": np.ones(6)}, "weights"),
        ({"prior_weight": 1.0}, "prior_weight"),
        ({"prior_weight": -1.0, "prior": "lwr"}, "prior_weight"),
        ({"prior": "lwr"}, "prior_weight"),
        ({"prior": "planar", "prior_weight": 1.0}, "prior"),
        ({"prior": "inconsistent", "prior_weight": 1.0}, "prior"),
        ({"prior": "other frames", "prior_weight": 1.0}, "prior"),
        ({"prior": 3, "prior_weight": 1.0}, "prior"),
        ({"mass_bounds": np.ones((6, 2))}, "mass_bounds"),
        ({"mass_bounds": np.tile([2.0, 1.0], (7, 1))}, "mass_bounds"),
        ({"mass_bounds": np.tile([-1.0, 1.0], (7, 1))}, "mass_bounds"),
        ({"mass_bounds": np.tile([np.nan, 1.0], (7, 1))}, "mass_bounds"),
        ({"total_mass": -3.0}, "total_mass"),
        ({"total_mass": (5.0, 2.0)}, "total_mass"),
        ({"total_mass": (1.0, 2.0, 3.0)}, "total_mass"),
        ({"margin": 0.0}, "margin"),
        ({"margin": np.inf}, "margin"),
        ({"extra_columns": -1}, "extra_columns"),
        ({"extra_columns": 2}, "Y"),
        ({"rank_tolerance": 0.0}, "rank_tolerance"),
        ({"rank_tolerance": 1.0}, "rank_tolerance"),
    ],
)
def test_bad_arguments_raise_value_errors_naming_them(lwr, data, changes, name):
    changes = dict(changes)
    prior = changes.get("prior")
    if prior == "lwr":
        changes["prior"] = lwr
    elif prior == "planar":
        changes["prior"] = dynid.models.planar_2r()
    elif prior == "inconsistent":
        bad = lwr.copy()
        params = bad.params.copy()
        params[2, 0] = -1.0
        bad.params = params
        changes["prior"] = bad
    elif prior == "other frames":
        changes["prior"] = dynid.Robot.from_dh(lwr.dh + [[0.01, 0, 0, 0]] * 7, params=lwr.params)
    with pytest.raises(ValueError, match=f"^{name}:"):
        _call(lwr, data, **changes)


# --------------------------------------------------------------------------- logs


@pytest.fixture(scope="module")
def log(lwr):
    """A simulated log: random states, the robot's torques plus offsets, no noise."""
    q, qd, qdd = states(lwr, 200, seed=31)
    offsets = np.array([0.5, -0.4, 0.0, 0.1, -0.2, 0.3, -0.1])
    return Log(
        t=np.arange(200) * 0.005,
        q=q,
        qd=qd,
        qdd=qdd,
        tau=lwr.rnea(q, qd, qdd) + offsets,
        source="simulated",
    ), offsets


def test_identify_log_physical_saves_and_loads_the_robot(lwr, log, tmp_path):
    """identify_log(physical=True, offset=True): the result's robot is consistent and, with the
    offsets, predicts the log (1e-6 of the torques; noise-free); load_result(...).robot is the
    same robot (bit for bit) and predicts the same."""
    log, offsets = log
    result = identify_log(log, lwr, rotor=True, friction=True, offset=True, physical=True)
    assert result.physical["status"] == "optimal" and result.robot.is_physically_consistent()
    np.testing.assert_allclose(result.theta[-lwr.n :], offsets, rtol=0, atol=1e-6)
    predicted = result.predict(log)
    np.testing.assert_allclose(predicted, log.tau, rtol=0, atol=1e-6 * np.abs(log.tau).max())
    np.testing.assert_allclose(
        result.robot.rnea(log.q, log.qd, log.qdd) + offsets,
        predicted,
        rtol=0,
        atol=1e-6 * np.abs(log.tau).max(),
    )
    dynid.save_result(result, tmp_path / "result", plots=False)
    loaded = dynid.load_result(tmp_path / "result")
    np.testing.assert_array_equal(loaded.robot.params, result.robot.params)
    for key in ("Ia", "Fv", "Fs"):
        np.testing.assert_array_equal(getattr(loaded.robot, key), getattr(result.robot, key))
    assert loaded.physical == result.physical
    np.testing.assert_array_equal(loaded.predict(log), predicted)


def test_identify_log_takes_a_prior_model_file(lwr, log, tmp_path):
    log, _ = log
    path = save_model(lwr, tmp_path / "prior.json")
    result = identify_log(
        log,
        lwr,
        rotor=True,
        friction=True,
        offset=True,
        physical=True,
        prior=path,
        prior_weight=1e-4,
    )
    truth = lwr.parameter_vector(True, True)
    np.testing.assert_allclose(
        result.robot.parameter_vector(True, True), truth, rtol=0, atol=1e-5 * np.abs(truth).max()
    )
    assert result.physical["prior"] == str(path) and result.physical["prior_weight"] == 1e-4


def test_identify_log_checks_the_physical_options(lwr, log):
    log, _ = log
    with pytest.raises(ValueError, match=r"^prior:"):
        identify_log(log, lwr, prior=lwr)
    with pytest.raises(ValueError, match=r"^physical:"):
        identify_log(log, lwr, physical="yes")
    with pytest.raises(ValueError, match=r"^prior:"):
        identify_log(log, lwr, physical=True, prior=3)


def test_identify_log_physical_with_excluded_joints_and_ols(lwr, log):
    """Joint 1's rows left out (weight 0) and its torques replaced by garbage, OLS: joint 1's
    own terms (Iyy1R, Fv1, Fs1, offset) are no longer excited, a RuntimeWarning (the least
    squares would raise) and the physical fit's UserWarning; the physical fit still explains
    joints 2-7 to 1e-6 of their torques and ignores joint 1."""
    log, _offsets = log
    tau = log.tau.copy()
    tau[:, 0] = 50.0
    garbage = log.replace(tau=tau)
    with pytest.raises(dynid.RankDeficientError):
        identify_log(garbage, lwr, rotor=True, friction=True, offset=True, exclude_joints=(0,))
    excited = pytest.warns(RuntimeWarning, match="do not excite")
    with excited, pytest.warns(UserWarning, match="rank 65 < 69"):
        result = identify_log(
            garbage,
            lwr,
            rotor=True,
            friction=True,
            offset=True,
            method="ols",
            exclude_joints=(0,),
            physical=True,
        )
    assert result.excluded == (0,) and result.physical["status"] == "optimal"
    error = result.predict(garbage) - garbage.tau
    assert np.abs(error[:, 1:]).max() < 1e-6 * np.abs(log.tau).max()
    assert np.abs(error[:, 0]).max() > 1.0
