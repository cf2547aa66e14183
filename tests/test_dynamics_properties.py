"""Structural properties of the dynamic model, each checked by an independent computation.

Robots: dynid.models.kuka_lwr4() as shipped, and reference arms (conftest.ARM_CASES): the
paper's LWR table with the model's links, and random chains in both conventions with
prismatic joints, random links, rotor inertia, friction, gravity direction, base and tool.

Independent computations used: finite differences of energies / of M(q) / of fkine, the
Christoffel symbols of numerically differentiated M, the Jacobian-based mass matrix and
gravity of tests/reference_model.py, the Lagrangian torque, and an RK4 simulation.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
import reference_model as ref
from conftest import ARM_CASES, SEED, lwr_model, make_arm, random_state

ROBOT_CASES = ("models.kuka_lwr4", *ARM_CASES)


def build_robot(case: str) -> tuple[dynid.Robot, str]:
    """(robot, joint_types) for a case; the shipped LWR gets random drive terms too."""
    if case == "models.kuka_lwr4":
        robot = lwr_model()
        rng = np.random.default_rng(SEED + 2)
        robot.Ia = rng.uniform(0.0, 0.5, 7)
        robot.Fv = rng.uniform(0.0, 2.0, 7)
        robot.Fs = rng.uniform(0.0, 1.0, 7)
        return robot, "R" * 7
    arm = make_arm(case)
    return arm.robot(), arm.joint_types


@pytest.fixture(params=ROBOT_CASES)
def robot_and_types(request: pytest.FixtureRequest) -> tuple[dynid.Robot, str]:
    return build_robot(request.param)


def rel_err(got: np.ndarray, expected: np.ndarray) -> float:
    """max |got - expected| / max(1, max |expected|)."""
    got, expected = np.asarray(got, dtype=float), np.asarray(expected, dtype=float)
    assert got.shape == expected.shape
    return float(np.max(np.abs(got - expected)) / max(1.0, float(np.max(np.abs(expected)))))


N_STATES = 4


# ---------------------------------------------------------------- mass matrix


def test_mass_matrix_symmetric_positive_definite(robot_and_types, rng) -> None:
    robot, types = robot_and_types
    for _ in range(N_STATES):
        q, _, _ = random_state(rng, types)
        m_q = robot.mass_matrix(q)
        assert rel_err(m_q, m_q.T) <= 1e-14
        assert np.linalg.eigvalsh(m_q).min() > 0.0


def test_mass_matrix_is_hessian_of_kinetic_energy(robot_and_types, rng) -> None:
    """KE is exactly quadratic in qd, so polarization is exact up to roundoff:
    M_ii = 2 T(e_i), M_ij = T(e_i + e_j) - T(e_i) - T(e_j). Tolerance 1e-12 relative."""
    robot, types = robot_and_types
    n = len(types)
    eye = np.eye(n)
    for _ in range(N_STATES):
        q, _, _ = random_state(rng, types)
        t_single = np.array([robot.kinetic_energy(q, eye[i]) for i in range(n)])
        hess = np.empty((n, n))
        for i in range(n):
            for j in range(n):
                hess[i, j] = robot.kinetic_energy(q, eye[i] + eye[j]) - t_single[i] - t_single[j]
        assert rel_err(robot.mass_matrix(q), hess) <= 1e-12


def test_mass_matrix_and_gravity_match_jacobian_formula(arm: ref.Arm, rng) -> None:
    """M = sum m Jv^T Jv + Jw^T I Jw + diag(Ia), g = -sum m Jv^T g0 (reference_model). 1e-12 rel."""
    robot = arm.robot()
    for _ in range(N_STATES):
        q, _, _ = random_state(rng, arm)
        assert rel_err(robot.mass_matrix(q), ref.mass_matrix(arm, q)) <= 1e-12
        assert rel_err(robot.gravity(q), ref.gravity(arm, q)) <= 1e-12


def test_energies_match_link_velocities(arm: ref.Arm, rng) -> None:
    """T = 1/2 sum (m v_c^2 + w I_c w) + 1/2 sum Ia qd^2 and U = -sum m g^T p_c. 1e-12 rel."""
    robot = arm.robot()
    for _ in range(N_STATES):
        q, qd, _ = random_state(rng, arm)
        assert rel_err(robot.kinetic_energy(q, qd), ref.kinetic_energy(arm, q, qd)) <= 1e-12
        assert rel_err(robot.potential_energy(q), ref.potential_energy(arm, q)) <= 1e-12


# ---------------------------------------------------------------- gravity


def test_gravity_is_gradient_of_potential_energy(robot_and_types, rng) -> None:
    """Central differences, h = 1e-6: error ~h^2 U''' + eps U / h ~ 1e-9. Tolerance 1e-7 rel."""
    robot, types = robot_and_types
    n, h = len(types), 1e-6
    for _ in range(N_STATES):
        q, _, _ = random_state(rng, types)
        grad = np.array(
            [
                (robot.potential_energy(q + h * e) - robot.potential_energy(q - h * e)) / (2 * h)
                for e in np.eye(n)
            ]
        )
        assert rel_err(robot.gravity(q), grad) <= 1e-7


# ---------------------------------------------------------------- RNEA and its pieces


def test_rnea_equals_sum_of_terms(robot_and_types, rng) -> None:
    """rnea = M qdd + c + g + Fv qd + Fs sign(qd) (CRBA and RNEA are different algorithms).
    1e-10 rel."""
    robot, types = robot_and_types
    fv, fs = np.asarray(robot.Fv), np.asarray(robot.Fs)
    for _ in range(N_STATES):
        q, qd, qdd = random_state(rng, types)
        qd[0] = 0.0  # sign(0) = 0
        expected = (
            robot.mass_matrix(q) @ qdd
            + robot.coriolis(q, qd)
            + robot.gravity(q)
            + fv * qd
            + fs * np.sign(qd)
        )
        assert rel_err(robot.rnea(q, qd, qdd), expected) <= 1e-10


def test_friction_closed_form(robot_and_types, rng) -> None:
    robot, types = robot_and_types
    fv, fs = np.asarray(robot.Fv), np.asarray(robot.Fs)
    _, qd, _ = random_state(rng, types)
    qd[::2] = 0.0
    assert rel_err(robot.friction(qd), fv * qd + fs * np.sign(qd)) <= 1e-15


def test_rnea_matches_lagrangian_torque(arm: ref.Arm, rng) -> None:
    """Euler-Lagrange on the reference M(q) (finite differences, h = 1e-6) + g + friction.
    1e-7 rel."""
    robot = arm.robot()
    for _ in range(2):
        q, qd, qdd = random_state(rng, arm)
        assert rel_err(robot.rnea(q, qd, qdd), ref.lagrange_torque(arm, q, qd, qdd)) <= 1e-7


def test_coriolis_equals_coriolis_matrix_times_qd(robot_and_types, rng) -> None:
    robot, types = robot_and_types
    for _ in range(N_STATES):
        q, qd, _ = random_state(rng, types)
        assert rel_err(robot.coriolis(q, qd), robot.coriolis_matrix(q, qd) @ qd) <= 1e-12


def test_coriolis_is_quadratic_in_qd(robot_and_types, rng) -> None:
    """c(q, k qd) = k^2 c(q, qd) and c(q, 0) = 0. 1e-12 rel."""
    robot, types = robot_and_types
    q, qd, _ = random_state(rng, types)
    assert rel_err(robot.coriolis(q, -2.5 * qd), 6.25 * robot.coriolis(q, qd)) <= 1e-12
    assert np.all(robot.coriolis(q, np.zeros(len(types))) == 0.0)


def dm_dq(robot: dynid.Robot, q: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """dM/dq_k by central differences, stacked on axis 0: (n, n, n)."""
    return np.array(
        [
            (robot.mass_matrix(q + h * e) - robot.mass_matrix(q - h * e)) / (2 * h)
            for e in np.eye(len(q))
        ]
    )


def test_mdot_minus_2s_is_skew_symmetric(robot_and_types, rng) -> None:
    """Mdot = (M(q + h qd) - M(q - h qd)) / 2h, h = 1e-6; N = Mdot - 2S, |N + N^T| <= 1e-7 rel."""
    robot, types = robot_and_types
    h = 1e-6
    for _ in range(N_STATES):
        q, qd, _ = random_state(rng, types)
        m_dot = (robot.mass_matrix(q + h * qd) - robot.mass_matrix(q - h * qd)) / (2 * h)
        n_mat = m_dot - 2 * robot.coriolis_matrix(q, qd)
        scale = max(1.0, float(np.max(np.abs(m_dot))))
        assert float(np.max(np.abs(n_mat + n_mat.T))) / scale <= 1e-7


def test_coriolis_matrix_is_christoffel(robot_and_types, rng) -> None:
    """S_ij = sum_k 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) qd_k, dM/dq by central
    differences (h = 1e-6); diag(Ia) is constant and drops out. Tolerance 1e-7 rel."""
    robot, types = robot_and_types
    for _ in range(N_STATES):
        q, qd, _ = random_state(rng, types)
        dm = dm_dq(robot, q)  # dm[k, i, j] = dM_ij / dq_k
        christoffel = 0.5 * (
            np.einsum("kij,k->ij", dm, qd)
            + np.einsum("jik,k->ij", dm, qd)
            - np.einsum("ijk,k->ij", dm, qd)
        )
        assert rel_err(robot.coriolis_matrix(q, qd), christoffel) <= 1e-7


# ---------------------------------------------------------------- forward dynamics


def test_forward_dynamics_inverts_rnea(robot_and_types, rng) -> None:
    """forward_dynamics(q, qd, rnea(q, qd, qdd)) == qdd, 1e-9 rel."""
    robot, types = robot_and_types
    for _ in range(N_STATES):
        q, qd, qdd = random_state(rng, types)
        assert rel_err(robot.forward_dynamics(q, qd, robot.rnea(q, qd, qdd)), qdd) <= 1e-9


def test_forward_dynamics_solves_the_model(arm: ref.Arm, rng) -> None:
    """qdd = M^-1 (tau - c - g - friction) with M, g from the reference and c from Lagrange.
    1e-7 rel."""
    robot = arm.robot()
    q, qd, _ = random_state(rng, arm)
    tau = rng.uniform(-5, 5, arm.n)
    bias = ref.lagrange_torque(arm, q, qd, np.zeros(arm.n))  # c + g + friction
    expected = np.linalg.solve(ref.mass_matrix(arm, q), tau - bias)
    assert rel_err(robot.forward_dynamics(q, qd, tau), expected) <= 1e-7


def rk4(f, x0: np.ndarray, dt: float, steps: int) -> np.ndarray:
    xs = [x0]
    x = x0
    for _ in range(steps):
        k1 = f(x)
        k2 = f(x + 0.5 * dt * k1)
        k3 = f(x + 0.5 * dt * k2)
        k4 = f(x + dt * k3)
        x = x + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        xs.append(x)
    return np.array(xs)


def test_energy_is_conserved_without_friction(rng) -> None:
    """Frictionless LWR (rotor inertia kept), tau = 0, 1 s of own RK4 at dt = 1 ms.
    Drift of T + U relative to the exchanged energy scale (max T + max |U - U0|) < 1e-8."""
    robot = lwr_model()
    robot.Ia = rng.uniform(0.05, 0.5, 7)
    robot.Fv = np.zeros(7)
    robot.Fs = np.zeros(7)
    q0, qd0, _ = random_state(rng, "R" * 7)
    tau = np.zeros(7)

    def f(x: np.ndarray) -> np.ndarray:
        return np.concatenate([x[7:], robot.forward_dynamics(x[:7], x[7:], tau)])

    traj = rk4(f, np.concatenate([q0, 0.5 * qd0]), 1e-3, 1000)
    kinetic = np.array([robot.kinetic_energy(x[:7], x[7:]) for x in traj])
    potential = np.array([robot.potential_energy(x[:7]) for x in traj])
    energy = kinetic + potential
    scale = kinetic.max() + np.abs(potential - potential[0]).max()
    assert scale > 1.0  # the arm really moves and exchanges energy
    assert np.abs(energy - energy[0]).max() / scale < 1e-8


# ---------------------------------------------------------------- kinematics


def test_fkine_matches_reference(arm: ref.Arm, rng) -> None:
    """base * A_1 ... A_n * tool from explicit Rz Tz Tx Rx matrices. 1e-13 abs (poses are O(1))."""
    robot = arm.robot()
    for _ in range(N_STATES):
        q, _, _ = random_state(rng, arm)
        np.testing.assert_allclose(robot.fkine(q), ref.fkine(arm, q), rtol=0, atol=1e-13)
        assert rel_err(robot.jacobian(q), ref.jacobian(arm, q)) <= 1e-12


def test_jacobian_is_derivative_of_fkine(robot_and_types, rng) -> None:
    """Linear part: dp/dq_j; angular: vee(dR/dq_j R^T); central differences h = 1e-6. 1e-8 rel."""
    robot, types = robot_and_types
    n, h = len(types), 1e-6
    for _ in range(N_STATES):
        q, _, _ = random_state(rng, types)
        pose = robot.fkine(q)
        fd = np.zeros((6, n))
        for j, e in enumerate(np.eye(n)):
            d_pose = (robot.fkine(q + h * e) - robot.fkine(q - h * e)) / (2 * h)
            fd[:3, j] = d_pose[:3, 3]
            w = d_pose[:3, :3] @ pose[:3, :3].T
            fd[3:, j] = [w[2, 1], w[0, 2], w[1, 0]]
        assert rel_err(robot.jacobian(q), fd) <= 1e-8


def test_kuka_lwr4_model_is_the_paper_table(rng) -> None:
    """models.kuka_lwr4(): 7 R joints, paper Table I with d1 = 0.4, d2 = 0.39, consistent links;
    its fkine/M/g equal the reference on that table with its own parameters (1e-12)."""
    robot = lwr_model()
    assert robot.n == 7
    assert robot.is_physically_consistent()
    arm = make_arm("lwr")
    arm.Ia = np.asarray(robot.Ia, dtype=float)
    for _ in range(N_STATES):
        q, _, _ = random_state(rng, arm)
        np.testing.assert_allclose(robot.fkine(q), ref.fkine(arm, q), rtol=0, atol=1e-13)
        assert rel_err(robot.mass_matrix(q), ref.mass_matrix(arm, q)) <= 1e-12
        assert rel_err(robot.gravity(q), ref.gravity(arm, q)) <= 1e-12
    # zero configuration: the arm stands straight up, flange at 0.4 + 0.39 m on z (frames 0 and 7
    # as in the paper)
    np.testing.assert_allclose(robot.fkine(np.zeros(7))[:3, 3], [0.0, 0.0, 0.79], atol=1e-15)
