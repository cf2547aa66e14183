"""The paper's identification from the controller's numeric M(q) and g(q)
(dynid.identification.from_controller).

Gaz, Flacco, De Luca, ICRA 2014, Sect. V (eqs. (17)-(26)) and Sect. VI (joint 1's gravity row
dropped, the identically zero element M_76, eq. (27), the symbolic gravity coefficients (28)).
The references are independent of the identification: the true robot's own dynamics, the NumPy
reference model of tests/reference_model.py (Jacobian sums, no recursion), the paper's eq. (28)
and its closed form of M_76 written out here, finite differences of the identified M for the
Christoffel terms, and the true base-parameter values beta @ pi.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
import reference_model as ref
from dynid.cli.demo import controller_model
from dynid.sim import VirtualController

D1, D2 = 0.4, 0.39  # the LWR's d_3 and d_5 (paper Table I)
TRUTHS = {"controller_model": controller_model, "kuka_lwr4": dynid.models.kuka_lwr4}


def identify(truth: dynid.Robot, count: int, seed: int, method: str = "ols", **noise):
    controller = VirtualController(truth, seed=seed, **noise)
    data = controller.read_static(controller.random_configurations(count))
    return dynid.identify_from_controller(
        dynid.models.kuka_lwr4(), data.q, data.g, data.M, method=method
    )


@pytest.fixture(scope="module", params=sorted(TRUTHS))
def noise_free(request):
    """(truth, identified model, fresh validation readings), 150 training configurations."""
    truth = TRUTHS[request.param]()
    ident = identify(truth, 150, seed=11)
    controller = VirtualController(truth, seed=12)
    return truth, ident, controller.read_static(controller.random_configurations(60))


# --- noise-free data: the identified model is the true one ---------------------------------------


def test_noise_free_coefficients_reproduce_g_and_M_on_a_validation_set(noise_free):
    # Tolerance 1e-9 relative to max|g| and max|M| of the validation set.
    _, ident, check = noise_free
    g_error = np.abs(ident.gravity(check.q) - check.g).max()
    M_error = np.abs(ident.mass_matrix(check.q) - check.M).max()
    assert g_error <= 1e-9 * np.abs(check.g).max(), g_error
    assert M_error <= 1e-9 * np.abs(check.M).max(), M_error


def test_noise_free_model_matches_the_independent_reference_model(noise_free):
    # M = sum m J_v^T J_v + J_w^T R I_c R^T J_w and g = -sum m J_v^T g0 (reference_model.py,
    # no drive terms), 1e-9 relative to max|M|, max|g|, on 8 fresh configurations.
    truth, ident, check = noise_free
    arm = ref.arm_of(truth)
    for q in check.q[:8]:
        M_ref, g_ref = ref.mass_matrix(arm, q), ref.gravity(arm, q)
        assert np.abs(ident.mass_matrix(q) - M_ref).max() <= 1e-9 * np.abs(M_ref).max()
        assert np.abs(ident.gravity(q) - g_ref).max() <= 1e-9 * np.abs(g_ref).max()


def test_noise_free_gravity_coefficients_are_the_true_base_values(noise_free):
    # beta @ pi of the true robot, 1e-9 relative to the largest coefficient.
    truth, ident, _ = noise_free
    true = dynid.base_parameters(truth, "gravity").values(truth)
    assert ident.gravity_base.count == 12  # paper Sect. VI: p_g = 12
    np.testing.assert_allclose(ident.pi_g, true, rtol=0, atol=1e-9 * np.abs(true).max())


def test_noise_free_gravity_coefficients_are_the_papers_eq_28(noise_free):
    # Eq. (28) written out by hand over the true standard parameters (m c = first moments).
    truth, ident, _ = noise_free
    p = dict(zip(truth.parameter_names(), truth.parameter_vector()))
    paper = np.array([
        p["my7"],
        p["mx7"],
        p["mx6"],
        p["mz6"] + p["mz7"],
        p["mz5"] - p["my6"],
        p["mx5"],
        p["my5"] + p["mz4"] + D2 * (p["m5"] + p["m6"] + p["m7"]),
        p["mx4"],
        p["my4"] + p["mz3"],
        p["mx2"],
        p["mx3"],
        p["mz2"] - p["my3"] + D1 * (p["m3"] + p["m4"] + p["m5"] + p["m6"] + p["m7"]),
    ])  # fmt: skip
    # The order of the coefficients is the library's: compare as sets (sorted values).
    assert np.min(np.diff(np.sort(paper))) > 1e-6  # distinct, so sorting pairs them uniquely
    np.testing.assert_allclose(np.sort(ident.pi_g), np.sort(paper), rtol=0, atol=1e-9)


def test_noise_free_tau_J_equals_the_rigid_robots_rnea(noise_free):
    # Eq. (26) vs the true robot's RNEA without drive terms, random states, 1e-9 relative.
    truth, ident, _ = noise_free
    rng = np.random.default_rng(3)
    q = truth.random_configurations(40, seed=4)
    qd, qdd = rng.uniform(-2, 2, q.shape), rng.uniform(-5, 5, q.shape)
    tau = truth.rigid_body().rnea(q, qd, qdd)
    error = np.abs(ident.rnea(q, qd, qdd) - tau).max()
    assert error <= 1e-9 * np.abs(tau).max(), error
    # one sample at a time as well (docs/conventions.md, "Shapes")
    np.testing.assert_allclose(
        ident.rnea(q[0], qd[0], qdd[0]), tau[0], rtol=0, atol=1e-9 * np.abs(tau).max()
    )
    # and against Lagrange's equations on the reference model (finite differences, ~1e-7)
    arm = ref.arm_of(truth)
    lagrange = ref.lagrange_torque(arm, q[1], qd[1], qdd[1])
    np.testing.assert_allclose(
        ident.rnea(q[1], qd[1], qdd[1]), lagrange, rtol=0, atol=1e-6 * np.abs(lagrange).max()
    )


def test_identified_coriolis_matrix_is_the_christoffel_one(noise_free):
    # Eqs. (15)-(16) on the identified M alone: c = S qd (1e-12), S from Christoffel symbols of
    # finite differences of M_hat (h = 1e-5, 1e-7 relative), Mdot - 2S skew-symmetric (1e-7).
    _, ident, _ = noise_free
    rng = np.random.default_rng(5)
    n, h = ident.n, 1e-5
    for q in ident.structure.random_configurations(5, seed=6):
        qd = rng.uniform(-2, 2, n)
        S = ident.coriolis_matrix(q, qd)
        c = ident.coriolis(q, qd)
        scale = np.abs(ident.mass_matrix(q)).max() * np.abs(qd).max() ** 2
        np.testing.assert_allclose(S @ qd, c, rtol=0, atol=1e-12 * scale)
        dM = np.array(
            [
                (ident.mass_matrix(q + h * e) - ident.mass_matrix(q - h * e)) / (2 * h)
                for e in np.eye(n)
            ]
        )  # dM[k] = dM/dq_k
        christoffel = 0.5 * (dM.transpose(1, 2, 0) + dM.transpose(1, 0, 2) - dM)  # [i, j, k]
        S_ref = christoffel @ qd
        np.testing.assert_allclose(S, S_ref, rtol=0, atol=1e-7 * scale / np.abs(qd).max())
        M_dot = (ident.mass_matrix(q + h * qd) - ident.mass_matrix(q - h * qd)) / (2 * h)
        N = M_dot - 2 * S
        assert np.abs(N + N.T).max() <= 1e-7 * scale / np.abs(qd).max()


def test_identified_coriolis_equals_the_true_robots(noise_free):
    truth, ident, _ = noise_free
    rng = np.random.default_rng(7)
    q = truth.random_configurations(20, seed=8)
    qd = rng.uniform(-2, 2, q.shape)
    c = truth.coriolis(q, qd)
    np.testing.assert_allclose(ident.coriolis(q, qd), c, rtol=0, atol=1e-9 * np.abs(c).max())


def test_noise_free_inertia_coefficients_are_the_true_base_values():
    # Plain kuka_lwr4 (no constraint): all p_m inertia coefficients, 1e-9 relative.
    truth = dynid.models.kuka_lwr4()
    ident = identify(truth, 150, seed=13)
    true = dynid.base_parameters(truth, "inertia").values(truth)
    np.testing.assert_allclose(ident.pi_m, true, rtol=0, atol=1e-9 * np.abs(true).max())


def test_joint_1_gravity_row_is_left_out_by_default():
    # Paper Sect. VI-1: garbage in joint 1's gravity reading must not change the estimate nor
    # its (zero, noise-free) standard deviations.
    truth = dynid.models.kuka_lwr4()
    controller = VirtualController(truth, seed=14)
    data = controller.read_static(controller.random_configurations(80))
    clean = dynid.identify_from_controller(truth, data.q, data.g, data.M)
    g = data.g.copy()
    g[:, 0] = np.random.default_rng(1).normal(scale=5.0, size=len(g))
    dirty = dynid.identify_from_controller(truth, data.q, g, data.M)
    assert clean.gravity_fit.excluded == (0,)
    np.testing.assert_allclose(dirty.pi_g, clean.pi_g, rtol=0, atol=1e-12)
    assert np.all(dirty.gravity_fit.std <= 1e-9 * np.abs(clean.pi_g).max())
    # Joint 1's regressor row is identically zero (vertical axis), so a kept garbage row cannot
    # move the estimate, but it must show up as residual noise in the standard deviations.
    kept = dynid.identify_from_controller(truth, data.q, g, data.M, exclude_gravity_joints=())
    assert kept.gravity_fit.excluded == ()
    assert np.all(kept.gravity_fit.std > 1e3 * dirty.gravity_fit.std.max())


# --- noisy data: consistency and honest standard deviations --------------------------------------


def _true_coefficients(truth):
    return (
        dynid.base_parameters(truth, "gravity").values(truth),
        dynid.base_parameters(truth, "inertia").values(truth),
    )


def test_errors_shrink_like_one_over_sqrt_N():
    # VirtualController relative model noise 1e-3; RMS coefficient error (each coefficient scaled
    # by the largest of its kind) over 6 seeds. Four times the data: error / 2 expected; accept a
    # ratio in [1.4, 2.9] at each step, so a monotone 1/sqrt(N) decrease.
    truth = dynid.models.kuka_lwr4()
    g_true, m_true = _true_coefficients(truth)
    errors = []
    for count in (50, 200, 800):
        squares = [0.0, 0.0]
        for seed in range(6):
            ident = identify(truth, count, seed=100 + seed, model_noise=1e-3)
            squares[0] += np.sum(((ident.pi_g - g_true) / np.abs(g_true).max()) ** 2)
            squares[1] += np.sum(((ident.pi_m - m_true) / np.abs(m_true).max()) ** 2)
        errors.append(np.sqrt(squares))
    errors = np.array(errors)  # (3 sizes, gravity/inertia)
    ratios = errors[:-1] / errors[1:]
    assert np.all((ratios > 1.4) & (ratios < 2.9)), (errors, ratios)


def _z_scores(truth, count, seeds, method, make_data):
    g_true, m_true = _true_coefficients(truth)
    z = []
    for seed in seeds:
        q, g, M = make_data(seed)
        ident = dynid.identify_from_controller(dynid.models.kuka_lwr4(), q, g, M, method=method)
        z += list((ident.pi_g - g_true) / ident.gravity_fit.std)
        z += list((ident.pi_m - m_true) / ident.inertia_fit.std)
    return np.abs(np.array(z))


def test_standard_deviations_are_calibrated_for_homoscedastic_noise():
    # OLS theory holds: i.i.d. noise added here to the exact readings (sigma_g = 1e-3 N m on g,
    # sigma_M = 1e-4 kg m^2 on each element of M's lower triangle, mirrored). Pooled over 8 seeds
    # x 51 coefficients: |error| < 3 std for >= 95 % (0.997 expected) and RMS(error / std) in
    # [0.8, 1.25] (1 expected), so neither too small nor too large.
    truth = dynid.models.kuka_lwr4()
    rows, cols = np.tril_indices(truth.n)

    def make_data(seed):
        controller = VirtualController(truth, seed=seed)
        data = controller.read_static(controller.random_configurations(200))
        rng = np.random.default_rng(1000 + seed)
        g = data.g + 1e-3 * rng.standard_normal(data.g.shape)
        E = np.zeros_like(data.M)
        E[:, rows, cols] = 1e-4 * rng.standard_normal((len(E), rows.size))
        E[:, cols, rows] = E[:, rows, cols]
        return data.q, g, data.M + E

    z = _z_scores(truth, 200, range(8), "ols", make_data)
    assert np.mean(z < 3) >= 0.95, np.mean(z < 3)
    assert 0.8 <= np.sqrt(np.mean(z**2)) <= 1.25, np.sqrt(np.mean(z**2))


def _virtual_data(truth, noise):
    def make_data(seed):
        controller = VirtualController(truth, seed=seed, **noise)
        data = controller.read_static(controller.random_configurations(200))
        return data.q, data.g, data.M

    return make_data


DEMO_NOISE = {"model_noise": 1e-5, "position_noise": 1e-5}  # dynid.demo.run_demo's defaults


def test_wls_standard_deviations_cover_the_error_with_virtual_controller_noise():
    # The VirtualController's relative noise (demo levels): per-joint (per-element) weights.
    # |error| < 3 std for >= 95 % of 8 seeds x 51 coefficients; RMS(error / std) in [0.5, 1.5].
    truth = dynid.models.kuka_lwr4()
    z = _z_scores(truth, 200, range(8), "wls", _virtual_data(truth, DEMO_NOISE))
    assert np.mean(z < 3) >= 0.95, np.mean(z < 3)
    assert 0.5 <= np.sqrt(np.mean(z**2)) <= 1.5, np.sqrt(np.mean(z**2))


def test_default_method_is_the_weighted_one():
    # OLS's pooled variance under-states the spread of heteroscedastic controller noise (its
    # coverage was ~88 % within 3 std in the test above run with "ols"), so the default is WLS.
    import inspect

    signature = inspect.signature(dynid.identify_from_controller)
    assert signature.parameters["method"].default == "wls"


# --- rank deficiency -----------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_same_q2_everywhere_is_reported_as_rank_deficient(method):
    # All configurations share q2: link 2's gravity coefficients (mx2 and the d1 group) enter
    # joint 2's gravity only through one fixed combination. Check independently that the stacked
    # gravity regressor (joint 1's row dropped) really has rank 11 < 12, then that the library
    # raises RankDeficientError (a ValueError) naming gravity coefficients.
    truth = controller_model()
    controller = VirtualController(truth, seed=15)
    q = controller.random_configurations(200)
    q[:, 1] = 0.7
    data = controller.read_static(q)
    base = dynid.base_parameters(truth, "gravity")
    A = base.reduce(truth.gravity_regressor(q))[:, 1:, :].reshape(-1, base.count)
    s = np.linalg.svd(A / np.linalg.norm(A, axis=0), compute_uv=False)
    assert np.sum(s > 1e-10 * s[0]) == base.count - 1
    with pytest.raises(dynid.RankDeficientError) as info:
        dynid.identify_from_controller(truth, data.q, data.g, data.M, method=method)
    assert isinstance(info.value, ValueError)
    message = str(info.value)
    assert "11" in message and "12" in message and "excite" in message  # rank 11 of 12
    assert "mx2" in message  # the unexcited direction involves link 2's coefficients
    q[:, 1] = truth.random_configurations(200, seed=16)[:, 1]  # vary q2 again: solvable
    data = controller.read_static(q)
    dynid.identify_from_controller(truth, data.q, data.g, data.M, method=method)


def test_same_q7_everywhere_is_reported_with_inertia_coefficient_names():
    # q7 fixed: the gravity coefficients stay identifiable (link 7's first moments are seen in
    # two directions) but link 7's inertia coefficients are not (only the rotation by the one q7
    # is seen). The error must name inertia coefficients of the user's model (inertia_base.names),
    # not internal column indices.
    truth = dynid.models.kuka_lwr4()
    controller = VirtualController(truth, seed=17)
    q = controller.random_configurations(200)
    q[:, 6] = -0.4
    data = controller.read_static(q)
    base = dynid.base_parameters(truth, "inertia")
    A = base.reduce(truth.inertia_regressor(q)).reshape(-1, base.count)
    s = np.linalg.svd(A / np.linalg.norm(A, axis=0), compute_uv=False)
    assert np.sum(s > 1e-10 * s[0]) < base.count  # independently: rank deficient
    names = base.names
    with pytest.raises(dynid.RankDeficientError) as info:
        dynid.identify_from_controller(truth, data.q, data.g, data.M)
    message = str(info.value)
    assert "theta[" not in message, message
    assert any(f" {name}" in message for name in names if name.endswith("7")), message


# --- identically zero elements of M (paper Sect. VI-2) -------------------------------------------


def paper_M76(params7: np.ndarray, q7: np.ndarray) -> np.ndarray:
    """M_76 of the paper (Sect. VI-2) with I_7 about link 7's origin (docs/conventions.md,
    "Inertial parameters": off-diagonal I_O = I_c - m c c^T): M_76 = -Ixz7 sin q7 - Iyz7 cos q7."""
    return -params7[6] * np.sin(q7) - params7[8] * np.cos(q7)


def test_the_papers_M76_closed_form_holds_for_the_true_robot():
    # Independent closed form, 1e-12 relative to max|M|: the premise of the zero-element check.
    truth = dynid.models.kuka_lwr4()
    q = truth.random_configurations(30, seed=18)
    M = truth.mass_matrix(q)
    np.testing.assert_allclose(
        M[:, 6, 5], paper_M76(truth.params[6], q[:, 6]), rtol=0, atol=1e-12 * np.abs(M).max()
    )
    assert np.abs(M[:, 6, 5]).max() > 1e-6  # non-zero for the plain model


@pytest.mark.parametrize("noise", [{}, DEMO_NOISE], ids=["noise-free", "demo-noise"])
def test_zero_element_M76_is_detected_and_kept_exactly_zero(noise):
    truth = controller_model()
    ident = identify(truth, 150, seed=19, **noise)
    assert [(z.row, z.column) for z in ident.zero_elements] == [(6, 5)]
    text = " ".join(ident.zero_elements[0].constraints)
    assert "Ixz7" in text and "Iyz7" in text, text
    q = truth.random_configurations(50, seed=20)
    M = ident.mass_matrix(q)
    assert np.abs(M[:, 6, 5]).max() <= 1e-12 and np.abs(M[:, 5, 6]).max() <= 1e-12
    # the constrained coefficients themselves (the base coefficients Ixz7, Iyz7 of eq. (27))
    names = ident.inertia_base.names
    for name in ("Ixz7", "Iyz7"):
        assert abs(ident.pi_m[names.index(name)]) <= 1e-12 * np.abs(ident.pi_m).max()
    # the other elements are still fitted: compare with the true M (1e-9 / demo noise 1e-4)
    tolerance = 1e-4 if noise else 1e-9
    M_true = truth.mass_matrix(q) - np.diag(truth.Ia)
    assert np.abs(M - M_true).max() <= tolerance * np.abs(M_true).max()


def test_no_zero_element_is_reported_for_the_plain_model():
    # Plain kuka_lwr4: M_76 is not zero, nothing is reported (noise-free and demo noise), and the
    # identified M_76 follows the paper's closed form (noise-free, 1e-9 relative to max|M|).
    truth = dynid.models.kuka_lwr4()
    q = truth.random_configurations(10, seed=22)
    for noise in ({}, DEMO_NOISE):
        ident = identify(truth, 150, seed=21, **noise)
        assert ident.zero_elements == []
    ident = identify(truth, 150, seed=21)
    M = ident.mass_matrix(q)
    np.testing.assert_allclose(
        M[:, 6, 5], paper_M76(truth.params[6], q[:, 6]), rtol=0, atol=1e-9 * np.abs(M).max()
    )


# --- bad input -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("q", np.zeros((5, 6))),
        ("g", np.zeros((4, 7))),
        ("M", np.zeros((5, 7, 6))),
        ("g", np.full((5, 7), np.nan)),
    ],
)
def test_bad_readings_raise_value_error_naming_them(field, value):
    truth = dynid.models.kuka_lwr4()
    data = {"q": np.zeros((5, 7)), "g": np.zeros((5, 7)), "M": np.zeros((5, 7, 7))}
    data[field] = value
    with pytest.raises(ValueError, match=rf"\b{field}\b"):
        dynid.identify_from_controller(truth, data["q"], data["g"], data["M"])
