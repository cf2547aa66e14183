"""Regressors Y, Y_g, Y_m against independent computations.

- Y(q, qd, qdd) @ pi against the library's RNEA (a second algorithm: Newton-Euler on the
  parameters, not on their columns), with the drive terms the columns leave out subtracted by hand.
- Y_g(q) @ pi and Y_m(q) @ pi against the library's gravity(q) / CRBA mass_matrix(q) and, where
  the links are physically consistent, against the pure-NumPy Jacobian model in reference_model.py.
- Linearity: rnea(pi_a) - rnea(pi_b) == Y @ (pi_a - pi_b) for random parameter sets, and each
  column k of Y (Y_g, Y_m) equals the response to the unit parameter vector e_k. These use the
  dynamics only, so they check Y without trusting it on any one parameter set.
- The block upper-triangular structure of the notes (row of joint i is zero for links j < i).

Robots: the LWR-IV and the PUMA 560 of dynid.models (standard DH) and conftest's random chains
(standard and modified DH, prismatic joints, random gravity, base and tool).

Tolerance (RTOL = 1e-10): max |got - expected| <= RTOL * max |expected| over the array, i.e.
relative to the size of the torques / inertias compared. For unit-parameter responses, whose
size is O(1) by construction, the scale is max(1, max |expected|).
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
import reference_model as ref
from conftest import SEED, make_arm, random_state

RTOL = 1e-10
T_SAMPLES = 4
CASES = ("lwr", "puma", "random_standard", "random_modified", "random_prismatic_first")
FIELDS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz")
FLAGS = [(False, False), (True, False), (False, True), (True, True)]


def build(case: str) -> tuple[dynid.Robot, ref.Arm | None]:
    """The robot under test and, when its links are physically consistent, the reference arm."""
    if case == "puma":
        return dynid.models.puma560(), None  # link 1 has m = 0: no physical form
    if case == "lwr":
        robot = dynid.models.kuka_lwr4()
        arm = make_arm("lwr")  # paper table I with the same links (conftest)
        np.testing.assert_allclose(arm.params, robot.params, rtol=0, atol=1e-12)
        arm.Ia, arm.Fv, arm.Fs = robot.Ia, robot.Fv, robot.Fs
        return robot, arm
    arm = make_arm(case)
    return arm.robot(), arm


def states(robot: dynid.Robot, count: int = T_SAMPLES):
    rng = np.random.default_rng(SEED + 17 * robot.n + len(robot.joint_types.replace("R", "")))
    return random_state(rng, robot.joint_types, count)


def assert_rel(got: np.ndarray, expected: np.ndarray, rtol: float, what: str, floor: float = 0.0):
    got = np.asarray(got, dtype=float)
    expected = np.asarray(expected, dtype=float)
    assert got.shape == expected.shape, f"{what}: shape {got.shape} != {expected.shape}"
    scale = max(floor, float(np.max(np.abs(expected), initial=0.0)))
    error = float(np.max(np.abs(got - expected), initial=0.0))
    assert error <= rtol * scale, f"{what}: max error {error:.3e} > {rtol:.0e} * {scale:.3e}"


def expected_names(n: int, rotor: bool, friction: bool) -> list[str]:
    names = [f"{field}{i}" for i in range(1, n + 1) for field in FIELDS]
    if rotor:
        names += [f"Ia{i}" for i in range(1, n + 1)]
    if friction:
        names += [f"Fv{i}" for i in range(1, n + 1)] + [f"Fs{i}" for i in range(1, n + 1)]
    return names


def set_parameters(robot: dynid.Robot, pi: np.ndarray) -> None:
    """Put a full vector (10n + Ia + Fv + Fs) on the robot."""
    n = robot.n
    robot.params = pi[: 10 * n].reshape(n, 10)
    robot.Ia = pi[10 * n : 11 * n]
    robot.Fv = pi[11 * n : 12 * n]
    robot.Fs = pi[12 * n :]


# ---- Y @ pi == rnea, Y_g @ pi == g, Y_m @ pi == M[tril] ---------------------------------------


@pytest.mark.parametrize(("rotor", "friction"), FLAGS)
@pytest.mark.parametrize("case", CASES)
def test_torque_regressor_reproduces_rnea(case: str, rotor: bool, friction: bool) -> None:
    robot, _ = build(case)
    q, qd, qdd = states(robot)
    n, P = robot.n, 10 * robot.n + rotor * robot.n + friction * 2 * robot.n
    pi = robot.parameter_vector(rotor=rotor, friction=friction)
    assert pi.shape == (P,)

    Y = robot.regressor(q, qd, qdd, rotor=rotor, friction=friction)
    assert Y.shape == (T_SAMPLES, n, P)
    tau = robot.rnea(q, qd, qdd)
    # the columns that are off: their terms leave the RNEA torque (tau of docs/conventions.md,
    # "Drive terms and the torque model"), by hand here
    if not rotor:
        tau = tau - robot.Ia * qdd
    if not friction:
        tau = tau - (robot.Fv * qd + robot.Fs * np.sign(qd))
    assert_rel(np.einsum("tnp,p->tn", Y, pi), tau, RTOL, f"{case}: Y @ pi vs rnea")

    for t in range(T_SAMPLES):
        Y_t = robot.regressor(q[t], qd[t], qdd[t], rotor=rotor, friction=friction)
        assert Y_t.shape == (n, P)
        # The batch runs the SIMD lane kernel (its own sincos, FMA): the scalar kernel's result
        # to 1e-12 of the sample's largest entry (tests/test_batch_lanes.py).
        np.testing.assert_allclose(Y[t], Y_t, rtol=0, atol=1e-12 * max(1.0, np.abs(Y_t).max()))
        assert_rel(Y_t @ pi, tau[t], RTOL, f"{case}: single-sample Y @ pi vs rnea")


@pytest.mark.parametrize("case", CASES)
def test_gravity_regressor_reproduces_gravity(case: str) -> None:
    robot, arm = build(case)
    q, _, _ = states(robot)
    n = robot.n
    pi = robot.parameter_vector()
    Y_g = robot.gravity_regressor(q)
    assert Y_g.shape == (T_SAMPLES, n, 10 * n)
    got = np.einsum("tnp,p->tn", Y_g, pi)
    assert_rel(got, robot.gravity(q), RTOL, f"{case}: Y_g @ pi vs gravity")
    if arm is not None:  # the Jacobian form g = -sum m_i Jv_i^T g0
        expected = np.array([ref.gravity(arm, q_t) for q_t in q])
        assert_rel(got, expected, RTOL, f"{case}: Y_g @ pi vs reference gravity")
    for t in range(T_SAMPLES):
        np.testing.assert_array_equal(robot.gravity_regressor(q[t]), Y_g[t])


@pytest.mark.parametrize("rotor", [False, True])
@pytest.mark.parametrize("case", CASES)
def test_inertia_regressor_reproduces_mass_matrix(case: str, rotor: bool) -> None:
    robot, arm = build(case)
    q, _, _ = states(robot)
    n = robot.n
    rows = np.tril_indices(n)
    pi = robot.parameter_vector(rotor=rotor)
    Y_m = robot.inertia_regressor(q, rotor=rotor)
    assert Y_m.shape == (T_SAMPLES, n * (n + 1) // 2, 10 * n + rotor * n)
    got = np.einsum("trp,p->tr", Y_m, pi)

    drive = np.zeros((n, n)) if rotor else np.diag(robot.Ia)  # B = M - diag(Ia)
    expected = np.array([(robot.mass_matrix(q_t) - drive)[rows] for q_t in q])
    assert_rel(got, expected, RTOL, f"{case}: Y_m @ pi vs CRBA")
    if arm is not None:  # B = sum m Jv^T Jv + Jw^T R Ic R^T Jw (+ diag(Ia))
        expected = np.array([(ref.mass_matrix(arm, q_t) - drive)[rows] for q_t in q])
        assert_rel(got, expected, RTOL, f"{case}: Y_m @ pi vs reference mass matrix")
    for t in range(T_SAMPLES):
        np.testing.assert_array_equal(robot.inertia_regressor(q[t], rotor=rotor), Y_m[t])


@pytest.mark.parametrize(("rotor", "friction"), FLAGS)
@pytest.mark.parametrize("case", ["lwr", "random_prismatic_first"])
def test_parameter_vector_and_names_match_columns(case: str, rotor: bool, friction: bool) -> None:
    robot, _ = build(case)
    n = robot.n
    names = robot.parameter_names(rotor=rotor, friction=friction)
    assert names == expected_names(n, rotor, friction)
    if case == "lwr":
        assert names[:11] == ["m1", "mx1", "my1", "mz1", "Ixx1", "Ixy1", "Ixz1", "Iyy1", "Iyz1",
                              "Izz1", "m2"]  # fmt: skip
        assert names[69] == "Izz7"
    pi = robot.parameter_vector(rotor=rotor, friction=friction)
    parts = [robot.params.reshape(-1)]
    parts += [robot.Ia] if rotor else []
    parts += [robot.Fv, robot.Fs] if friction else []
    np.testing.assert_array_equal(pi, np.concatenate(parts))
    assert robot.params.shape == (n, 10)
    q, qd, qdd = states(robot, 1)
    assert robot.regressor(q[0], qd[0], qdd[0], rotor, friction).shape == (n, len(names))
    assert robot.inertia_regressor(q[0], rotor=rotor).shape[-1] == len(
        robot.parameter_names(rotor=rotor)
    )
    assert robot.gravity_regressor(q[0]).shape[-1] == len(robot.parameter_names())


# ---- linearity in the parameters ----------------------------------------------------------------


@pytest.mark.parametrize("case", CASES)
def test_rnea_difference_is_regressor_times_parameter_difference(case: str) -> None:
    robot, _ = build(case)
    n = robot.n
    q, qd, qdd = states(robot)
    rng = np.random.default_rng(SEED + 3)
    # any finite values are accepted (docs/conventions.md, "Inertial parameters")
    pi_a, pi_b = rng.normal(size=(2, 13 * n))
    robot_a, robot_b = robot.copy(), robot.copy()
    set_parameters(robot_a, pi_a)
    set_parameters(robot_b, pi_b)
    np.testing.assert_array_equal(robot_a.parameter_vector(True, True), pi_a)

    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)
    # Y does not depend on the parameter values
    np.testing.assert_array_equal(robot_a.regressor(q, qd, qdd, rotor=True, friction=True), Y)
    got = np.einsum("tnp,p->tn", Y, pi_a - pi_b)
    expected = robot_a.rnea(q, qd, qdd) - robot_b.rnea(q, qd, qdd)
    assert_rel(got, expected, RTOL, f"{case}: Y (pi_a - pi_b) vs rnea(pi_a) - rnea(pi_b)")

    got_g = np.einsum("tnp,p->tn", robot.gravity_regressor(q), pi_a[: 10 * n] - pi_b[: 10 * n])
    expected_g = robot_a.gravity(q) - robot_b.gravity(q)
    assert_rel(got_g, expected_g, RTOL, f"{case}: Y_g (pi_a - pi_b) vs g(pi_a) - g(pi_b)")

    rows = np.tril_indices(n)
    got_m = np.einsum(
        "trp,p->tr", robot.inertia_regressor(q, rotor=True), pi_a[: 11 * n] - pi_b[: 11 * n]
    )
    expected_m = np.array(
        [(robot_a.mass_matrix(q_t) - robot_b.mass_matrix(q_t))[rows] for q_t in q]
    )
    assert_rel(got_m, expected_m, RTOL, f"{case}: Y_m (pi_a - pi_b) vs M(pi_a) - M(pi_b)")


@pytest.mark.parametrize("case", CASES)
def test_each_column_is_the_unit_parameter_response(case: str) -> None:
    """Column k == dynamics with pi = e_k minus dynamics with pi = 0 (a test-only construction)."""
    robot, _ = build(case)
    n = robot.n
    q, qd, qdd = states(robot, 3)
    rows = np.tril_indices(n)
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)
    Y_g = robot.gravity_regressor(q)
    Y_m = robot.inertia_regressor(q, rotor=True)

    unit = robot.copy()
    set_parameters(unit, np.zeros(13 * n))
    tau0, g0 = unit.rnea(q, qd, qdd), unit.gravity(q)
    m0 = np.array([unit.mass_matrix(q_t)[rows] for q_t in q])
    for k, name in enumerate(robot.parameter_names(rotor=True, friction=True)):
        e_k = np.zeros(13 * n)
        e_k[k] = 1.0
        set_parameters(unit, e_k)
        what = f"{case}: column {k} ({name})"
        assert_rel(Y[:, :, k], unit.rnea(q, qd, qdd) - tau0, RTOL, what + " of Y", floor=1.0)
        if k < 10 * n:
            assert_rel(Y_g[:, :, k], unit.gravity(q) - g0, RTOL, what + " of Y_g", floor=1.0)
        if k < 11 * n:
            m_k = np.array([unit.mass_matrix(q_t)[rows] for q_t in q]) - m0
            assert_rel(Y_m[:, :, k], m_k, RTOL, what + " of Y_m", floor=1.0)


# ---- structure ----------------------------------------------------------------------------------


@pytest.mark.parametrize("case", CASES)
def test_block_upper_triangular_structure(case: str) -> None:
    robot, _ = build(case)
    n = robot.n
    q, qd, qdd = states(robot)
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)
    Y_g = robot.gravity_regressor(q)
    Y_m = robot.inertia_regressor(q, rotor=True)
    row_of_m = np.tril_indices(n)[0]  # M[i, k] with k <= i involves only links j >= i
    for i in range(n):
        for j in range(i):  # links j < i: exact zeros
            block = slice(10 * j, 10 * j + 10)
            assert np.all(Y[:, i, block] == 0.0), f"{case}: Y row {i + 1}, link {j + 1}"
            assert np.all(Y_g[:, i, block] == 0.0), f"{case}: Y_g row {i + 1}, link {j + 1}"
            for r in np.flatnonzero(row_of_m == i):
                assert np.all(Y_m[:, r, block] == 0.0), f"{case}: Y_m row {r}, link {j + 1}"
        # not vacuous: the diagonal block of the torque regressor is not zero
        assert np.any(Y[:, i, 10 * i : 10 * i + 10] != 0.0)
    # drive-term columns are diagonal: Ia_i qdd_i, Fv_i qd_i, Fs_i sign(qd_i) in row i only
    drive = Y[:, :, 10 * n :].reshape(T_SAMPLES, n, 3, n)
    for t in range(T_SAMPLES):
        np.testing.assert_array_equal(drive[t, :, 0], np.diag(qdd[t]))
        np.testing.assert_array_equal(drive[t, :, 1], np.diag(qd[t]))
        np.testing.assert_array_equal(drive[t, :, 2], np.diag(np.sign(qd[t])))
    diagonal_rows = np.flatnonzero(np.tril_indices(n)[0] == np.tril_indices(n)[1])
    expected_ia = np.zeros((n * (n + 1) // 2, n))
    expected_ia[diagonal_rows, np.arange(n)] = 1.0
    for t in range(T_SAMPLES):
        np.testing.assert_array_equal(Y_m[t, :, 10 * n :], expected_ia)
