"""Transmission coupling (issue 12 item 4; notes p. 11-13; docs/transmission.md) against
independent computations.

Motor velocities theta_dot = T qd; the rotors add T^T diag(Ia) T to M, the motor friction
reaches the joints as T^T (Fv T qd + Fs sign(T qd)). References, with their tolerances:

- T = diag(t) is the decoupled robot with Ia t^2, Fv t^2, Fs |t| (Coulomb: t Fs sign(t qd) =
  |t| Fs sign(qd)), every dynamics call, to 1e-12 relative;
- the planar 2R of the notes with motor 2 on the base driving joint 2 through a belt
  (theta_dot_2 = qd_1 + qd_2): M, c, g, friction and energy written by hand, to 1e-12 relative;
- a PUMA 560 with a coupled wrist (T_wrist below: my coupling ratios, chosen large enough to
  matter; the PUMA's published ratios are not in puma560()'s references): M - B = T^T diag(Ia) T
  with B from Pinocchio (1e-10), Y pi == rnea (1e-10), central finite differences of the kinetic
  energy (1e-7), Mdot - 2S skew (1e-6, Mdot by finite differences), rnea_derivatives and
  rnea_time_derivatives against finite differences (1e-7 / 1e-5), forward dynamics after rnea
  (1e-10), energy conserved by the simulator without friction or torque (1e-8 of the kinetic
  energy), base parameters (Y_b beta == rnea, 1e-10);
- batches equal single calls bit for bit on every batch path (coupled models run the scalar
  kernels), and no heap allocation per call (tests/cpp/test_transmission_no_allocation.cpp).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin  # the test extra's "pin"
import pytest

import dynid
from conftest import ARM_CASES, make_arm, random_state
from coupled_robots import coupled_puma
from dynid import _core

# bench/pinocchio_arm.py: the Pinocchio model of a dynid DH arm, built without dynid's code
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
from pinocchio_arm import build_model

# PUMA-like coupled wrist: motor 5 turns with joint 4, motor 6 with joints 4 and 5.


def scale(expected: np.ndarray) -> float:
    return max(1.0, float(np.abs(expected).max()))


def assert_close(actual, expected, rtol: float) -> None:
    expected = np.asarray(expected)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rtol * scale(expected))


def puma_state(rng: np.random.Generator, count: int | None = None):
    shape = (6,) if count is None else (count, 6)
    q = rng.uniform(-1.5, 1.5, shape)
    qd = rng.uniform(0.3, 1.5, shape) * rng.choice([-1.0, 1.0], shape)
    qdd = rng.normal(size=shape)
    return q, qd, qdd


# ------------------------------------------------------------------- T = diag(t): decoupled


@pytest.mark.parametrize("case", ARM_CASES)
def test_diagonal_transmission_is_the_decoupled_robot_with_scaled_drives(case, rng) -> None:
    """T = diag(t) (signs mixed) against the decoupled robot with Ia t^2, Fv t^2, Fs |t|, 1e-12
    relative, on every call that carries drive terms."""
    arm = make_arm(case)
    coupled = arm.robot()
    n = coupled.n
    coupled.Ia = rng.uniform(0.05, 0.5, n)
    coupled.Fv = rng.uniform(0.1, 1.0, n)
    coupled.Fs = rng.uniform(0.1, 1.0, n)
    t = rng.uniform(0.5, 2.0, n) * rng.choice([-1.0, 1.0], n)
    coupled.transmission = np.diag(t)
    decoupled = coupled.copy()
    decoupled.transmission = None
    decoupled.Ia, decoupled.Fv, decoupled.Fs = (
        coupled.Ia * t**2,
        coupled.Fv * t**2,
        coupled.Fs * abs(t),
    )
    for _ in range(3):
        q, qd, qdd = random_state(rng, arm)  # qd away from 0 (Coulomb)
        qddd, qdddd = rng.normal(size=(2, n))
        tau = decoupled.rnea(q, qd, qdd)
        assert_close(coupled.rnea(q, qd, qdd), tau, 1e-12)
        assert_close(coupled.mass_matrix(q), decoupled.mass_matrix(q), 1e-12)
        assert_close(coupled.friction(qd), decoupled.friction(qd), 1e-12)
        assert_close(coupled.forward_dynamics(q, qd, tau), qdd, 1e-10)
        assert_close(coupled.kinetic_energy(q, qd), decoupled.kinetic_energy(q, qd), 1e-12)
        for mine, theirs in zip(
            coupled.rnea_derivatives(q, qd, qdd), decoupled.rnea_derivatives(q, qd, qdd)
        ):
            assert_close(mine, theirs, 1e-12)
        for mine, theirs in zip(
            coupled.rnea_time_derivatives(q, qd, qdd, qddd, qdddd),
            decoupled.rnea_time_derivatives(q, qd, qdd, qddd, qdddd),
        ):
            assert_close(mine, theirs, 1e-12)
        # Regressor: the drive columns scale by t^2 (Ia, Fv) and |t| (Fs); the links' are equal.
        Yc = coupled.regressor(q, qd, qdd, rotor=True, friction=True)
        Yd = decoupled.regressor(q, qd, qdd, rotor=True, friction=True)
        factor = np.concatenate([np.ones(10 * n), t**2, t**2, abs(t)])
        assert_close(Yc, Yd * factor, 1e-12)
        Ymc = coupled.inertia_regressor(q, rotor=True)
        Ymd = decoupled.inertia_regressor(q, rotor=True)
        assert_close(Ymc, Ymd * factor[: 11 * n], 1e-12)


def test_identity_transmission_is_the_decoupled_model_bit_for_bit(rng) -> None:
    """Setting T = I (or None) after a coupled T gives exactly the untouched robot's results,
    single and batch (the decoupled path, lanes included)."""
    robot = dynid.models.puma560()
    other = robot.copy()
    other.transmission = coupled_puma().transmission
    other.transmission = np.eye(6)
    assert np.array_equal(other.transmission, np.eye(6))
    for q, qd, qdd in (puma_state(rng), puma_state(rng, 37)):
        for name, args in (
            ("rnea", (q, qd, qdd)),
            ("mass_matrix", (q,)),
            ("friction", (qd,)),
            ("forward_dynamics", (q, qd, qdd)),
            ("kinetic_energy", (q, qd)),
            ("rnea_derivatives", (q, qd, qdd)),
            ("rnea_time_derivatives", (q, qd, qdd, qdd, qd)),
            ("inertia_regressor", (q, True)),
        ):
            mine, theirs = getattr(other, name)(*args), getattr(robot, name)(*args)
            for a, b in zip(np.atleast_1d(mine), np.atleast_1d(theirs)):
                assert np.array_equal(a, b), name
        assert np.array_equal(
            other.regressor(q, qd, qdd, rotor=True, friction=True),
            robot.regressor(q, qd, qdd, rotor=True, friction=True),
        )
    other.transmission = None
    assert other == robot


# ---------------------------------------------------------- planar 2R with a belt: closed form

L1, L2, D1, D2, M1, M2, I1, I2, G0 = 1.0, 0.8, 0.45, 0.35, 3.0, 2.0, 0.25, 0.11, 9.81
IA = np.array([0.4, 0.15])  # motor 1 on joint 1, motor 2 on the base (belt to joint 2)
FV = np.array([0.7, 0.3])
FS = np.array([0.5, 0.2])
BELT = np.array([[1.0, 0.0], [1.0, 1.0]])  # theta_dot_2 = qd_1 + qd_2


def belt_2r() -> dynid.Robot:
    robot = dynid.models.planar_2r(l1=L1, l2=L2, lc1=D1, lc2=D2, m1=M1, m2=M2, I1=I1, I2=I2)
    robot.Ia, robot.Fv, robot.Fs = IA, FV, FS
    robot.transmission = BELT
    return robot


def belt_2r_closed_form(q, qd, qdd):
    """M, tau and the kinetic energy of the belt-driven 2R written out by hand (notes p. 22-24
    for the links; rotor energy 1/2 (Ia1 qd1^2 + Ia2 (qd1 + qd2)^2); Coulomb per motor)."""
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    c1, c12 = np.cos(q[0]), np.cos(q[0] + q[1])
    b11 = I1 + M1 * D1**2 + I2 + M2 * (L1**2 + D2**2 + 2 * L1 * D2 * c2)
    b12 = I2 + M2 * (D2**2 + L1 * D2 * c2)
    b22 = I2 + M2 * D2**2
    M = np.array(
        [[b11 + IA[0] + IA[1], b12 + IA[1]], [b12 + IA[1], b22 + IA[1]]]
    )  # B + [[Ia1 + Ia2, Ia2], [Ia2, Ia2]]
    h = M2 * L1 * D2 * s2
    c = np.array([-h * (qd[1] ** 2 + 2 * qd[0] * qd[1]), h * qd[0] ** 2])
    g = G0 * np.array([(M1 * D1 + M2 * L1) * c1 + M2 * D2 * c12, M2 * D2 * c12])
    w1, w2 = qd[0], qd[0] + qd[1]  # motor velocities
    f1 = FV[0] * w1 + FS[0] * np.sign(w1)
    f2 = FV[1] * w2 + FS[1] * np.sign(w2)
    friction = np.array([f1 + f2, f2])  # T^T (f1, f2)
    tau = M @ qdd + c + g + friction
    energy = 0.5 * qd @ M @ qd
    return M, tau, friction, energy


def test_belt_driven_2r_matches_the_closed_form(rng) -> None:
    """rnea, mass_matrix, friction, kinetic energy and forward dynamics, 1e-12 relative."""
    robot = belt_2r()
    for _ in range(20):
        q = rng.uniform(-np.pi, np.pi, 2)
        qd = rng.uniform(0.2, 2.0, 2) * rng.choice([-1.0, 1.0], 2)
        qdd = rng.normal(size=2)
        M, tau, friction, energy = belt_2r_closed_form(q, qd, qdd)
        assert_close(robot.mass_matrix(q), M, 1e-12)
        assert_close(robot.rnea(q, qd, qdd), tau, 1e-12)
        assert_close(robot.friction(qd), friction, 1e-12)
        assert_close(robot.kinetic_energy(q, qd), energy, 1e-12)
        assert_close(robot.forward_dynamics(q, qd, tau), qdd, 1e-10)
        Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)
        assert_close(Y @ robot.parameter_vector(rotor=True, friction=True), tau, 1e-12)


def test_belt_driven_2r_motor_friction_opposes_the_motor_not_the_joint() -> None:
    """qd = (1, -1): motor 2 stands still (theta_dot_2 = 0), so only motor 1 rubs: friction
    (Fv1 + Fs1, 0), although joint 2 moves."""
    robot = belt_2r()
    np.testing.assert_array_equal(robot.friction([1.0, -1.0]), [FV[0] + FS[0], 0.0])


# ------------------------------------------------------------------ PUMA 560, coupled wrist


def test_puma_wrist_rotor_inertia_is_t_transpose_ia_t(rng) -> None:
    """M - B = T^T diag(Ia) T with B(q) from Pinocchio's CRBA (links only), 1e-10 relative."""
    robot = coupled_puma()
    # Corke's link 1 is massless, which Pinocchio's inertia (a centre of mass h / m) cannot take.
    robot.set_link(0, 1.0, np.zeros(3), 0.35 * np.eye(3))
    model = build_model(robot.rigid_body(), pin)  # armature 0: the links alone
    data = model.createData()
    T = robot.transmission
    expected_drive = T.T @ np.diag(robot.Ia) @ T
    for _ in range(5):
        q = rng.uniform(-1.5, 1.5, 6)
        B = pin.crba(model, data, q)
        B = np.triu(B) + np.triu(B, 1).T
        assert_close(robot.mass_matrix(q) - B, expected_drive, 1e-10)


def test_puma_regressor_and_base_parameters_reproduce_rnea(rng) -> None:
    """Y pi == rnea and Y_b beta == rnea (base parameters recomputed for the coupled robot),
    1e-10 relative; the coupled rotor and friction columns are T^T e_k (T x)_k."""
    robot = coupled_puma()
    T = robot.transmission
    q, qd, qdd = puma_state(rng, 50)
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True)
    tau = robot.rnea(q, qd, qdd)
    assert_close(np.einsum("tip,p->ti", Y, robot.parameter_vector(True, True)), tau, 1e-10)
    w, a = qd @ T.T, qdd @ T.T  # motor velocities and accelerations
    assert_close(Y[:, :, 60:66], np.einsum("ki,tk->tik", T, a), 1e-12)
    assert_close(Y[:, :, 66:72], np.einsum("ki,tk->tik", T, w), 1e-12)
    assert_close(Y[:, :, 72:78], np.einsum("ki,tk->tik", T, np.sign(w)), 1e-12)
    base = dynid.base_parameters(robot, rotor=True, friction=True)
    assert base is not dynid.base_parameters(dynid.models.puma560(), rotor=True, friction=True)
    Yb = robot.regressor(q, qd, qdd, rotor=True, friction=True, columns=base.independent)
    assert_close(np.einsum("tip,p->ti", Yb, base.values(robot)), tau, 1e-10)
    # The inertia regressor with rotor columns stacks the lower triangle of the full M.
    Ym = robot.inertia_regressor(q[0], rotor=True)
    rows, cols = np.tril_indices(6)
    lower = robot.mass_matrix(q[0])[rows, cols]
    order = np.lexsort((cols, rows))  # row-major lower triangle (i, k <= i)
    assert_close(Ym @ robot.parameter_vector(rotor=True), lower[order], 1e-10)


def test_puma_kinetic_energy_gradient_is_m_qd(rng) -> None:
    """Central differences of the kinetic energy in qd (exact for a quadratic up to rounding)
    give M qd, 1e-7 relative."""
    robot = coupled_puma()
    q, qd, _ = puma_state(rng)
    h = 1e-5
    gradient = np.array(
        [
            (robot.kinetic_energy(q, qd + h * e) - robot.kinetic_energy(q, qd - h * e)) / (2 * h)
            for e in np.eye(6)
        ]
    )
    assert_close(gradient, robot.mass_matrix(q) @ qd, 1e-7)


def test_puma_mdot_minus_2s_is_skew_symmetric(rng) -> None:
    """Mdot by central differences along qd (step 1e-6), S = coriolis_matrix (T constant adds no
    Coriolis term): N = Mdot - 2S satisfies N + N^T = 0 to 1e-6 relative, and c = S qd equals
    rnea(q, qd, 0) - g - friction (1e-10)."""
    robot = coupled_puma()
    q, qd, _ = puma_state(rng)
    h = 1e-6
    Mdot = (robot.mass_matrix(q + h * qd) - robot.mass_matrix(q - h * qd)) / (2 * h)
    N = Mdot - 2 * robot.coriolis_matrix(q, qd)
    assert_close(N + N.T, np.zeros((6, 6)), 1e-6 * scale(Mdot))
    c = robot.rnea(q, qd, np.zeros(6)) - robot.gravity(q) - robot.friction(qd)
    assert_close(robot.coriolis_matrix(q, qd) @ qd, c, 1e-10)


def test_puma_rnea_derivatives_match_finite_differences(rng) -> None:
    """dtau/dq, dtau/dqd (friction: T^T diag(Fv) T) against central differences of rnea, step
    1e-6, 1e-7 relative (motor velocities away from zero: Coulomb is flat there)."""
    robot = coupled_puma()
    q, qd, qdd = puma_state(rng)
    assert np.abs(robot.transmission @ qd).min() > 1e-3
    dq, dqd = robot.rnea_derivatives(q, qd, qdd)
    h = 1e-6
    fd_q = np.array(
        [
            (robot.rnea(q + h * e, qd, qdd) - robot.rnea(q - h * e, qd, qdd)) / (2 * h)
            for e in np.eye(6)
        ]
    ).T
    fd_qd = np.array(
        [
            (robot.rnea(q, qd + h * e, qdd) - robot.rnea(q, qd - h * e, qdd)) / (2 * h)
            for e in np.eye(6)
        ]
    ).T
    assert_close(dq, fd_q, 1e-7)
    assert_close(dqd, fd_qd, 1e-7)


def test_puma_rnea_time_derivatives_match_finite_differences(rng) -> None:
    """tau_dot and tau_ddot of rnea along q(t) = q + qd t + qdd t^2/2 + qddd t^3/6 +
    qdddd t^4/24 by central differences (step 1e-4: truncation ~1e-8, rounding ~1e-6), 1e-5
    relative; tau itself equals rnea exactly up to 1e-12."""
    robot = coupled_puma()
    q, qd, qdd = puma_state(rng)
    qddd, qdddd = rng.normal(size=(2, 6))

    def torque(t: float) -> np.ndarray:
        return robot.rnea(
            q + qd * t + qdd * t**2 / 2 + qddd * t**3 / 6 + qdddd * t**4 / 24,
            qd + qdd * t + qddd * t**2 / 2 + qdddd * t**3 / 6,
            qdd + qddd * t + qdddd * t**2 / 2,
        )

    tau, tau_dot, tau_ddot = robot.rnea_time_derivatives(q, qd, qdd, qddd, qdddd)
    h = 1e-4
    assert_close(tau, torque(0.0), 1e-12)
    assert_close(tau_dot, (torque(h) - torque(-h)) / (2 * h), 1e-5)
    assert_close(tau_ddot, (torque(h) - 2 * torque(0.0) + torque(-h)) / h**2, 1e-5)


def test_puma_forward_dynamics_inverts_rnea(rng) -> None:
    """forward_dynamics(q, qd, rnea(q, qd, qdd)) == qdd, 1e-10 relative, single and batch."""
    robot = coupled_puma()
    q, qd, qdd = puma_state(rng, 20)
    assert_close(robot.forward_dynamics(q, qd, robot.rnea(q, qd, qdd)), qdd, 1e-10)


def test_puma_simulation_conserves_energy_without_friction_and_torque() -> None:
    """RK4, 1 s at 1 ms with 2 substeps, free motion: |E(t) - E(0)| < 1e-8 of the largest
    kinetic energy, E = kinetic (links and coupled rotors) + potential."""
    robot = coupled_puma()
    q0 = np.array([0.3, -0.6, 0.4, 0.8, -0.5, 0.2])
    qd0 = np.array([0.5, -0.4, 0.6, 1.5, -1.2, 2.0])
    run = dynid.sim.simulate(robot, q0, qd0, duration=1.0, substeps=2, friction=False)
    kinetic = robot.kinetic_energy(run.q, run.qd)
    energy = kinetic + robot.potential_energy(run.q)
    drift = np.abs(energy - energy[0]).max()
    print(f"energy drift {drift / kinetic.max():.2e} of the largest kinetic energy")
    assert drift < 1e-8 * kinetic.max()
    # The run feels the coupling: the decoupled robot drifts apart from it.
    plain = dynid.sim.simulate(
        dynid.models.puma560(), q0, qd0, duration=1.0, substeps=2, friction=False
    )
    assert np.abs(plain.q[-1] - run.q[-1]).max() > 1e-3


def test_plant_friction_acts_on_the_motor_velocities(rng) -> None:
    """sim.plant_friction: band 0 equals robot.friction; a band gives T^T (Fv w + Fs tanh(w /
    band)), w = T qd, written out here (1e-12)."""
    robot = coupled_puma()
    _, qd, _ = puma_state(rng, 10)
    np.testing.assert_allclose(
        dynid.sim.plant_friction(robot, qd, 0.0), robot.friction(qd), rtol=0, atol=1e-12
    )
    T = robot.transmission
    w = qd @ T.T
    expected = (robot.Fv * w + robot.Fs * np.tanh(w / 0.05)) @ T
    assert_close(dynid.sim.plant_friction(robot, qd, 0.05), expected, 1e-12)


# ---------------------------------------------------------------- batches, real time, errors


@pytest.mark.parametrize("isa", _core._supported_batch_isas())
def test_coupled_batches_equal_single_calls_on_every_batch_path(isa, rng) -> None:
    """Coupled models run the scalar kernels whatever the selected path; the decoupled lane
    kernels would miss the coupling. Bit-for-bit equal to one call per sample."""
    robot = coupled_puma()
    q, qd, qdd = puma_state(rng, 41)
    before = _core._batch_isa()
    _core._set_batch_isa(isa)
    try:
        batches = {
            "rnea": robot.rnea(q, qd, qdd),
            "mass_matrix": robot.mass_matrix(q),
            "regressor": robot.regressor(q, qd, qdd, rotor=True, friction=True),
        }
    finally:
        _core._set_batch_isa(before)
    for t in range(len(q)):
        assert np.array_equal(batches["rnea"][t], robot.rnea(q[t], qd[t], qdd[t]))
        assert np.array_equal(batches["mass_matrix"][t], robot.mass_matrix(q[t]))
        assert np.array_equal(
            batches["regressor"][t],
            robot.regressor(q[t], qd[t], qdd[t], rotor=True, friction=True),
        )


def test_no_heap_allocation_per_call_with_a_coupled_transmission(cpp_tests) -> None:
    """Runs tests/cpp/test_transmission_no_allocation.cpp (built against the installed package):
    10^4 calls of every algorithm with drive terms on a coupled arm, no allocation; bad
    transmissions are std::invalid_argument naming it."""
    output = cpp_tests.run("transmission_no_allocation")
    assert re.search(r"^allocations_during_calls=0$", output, re.MULTILINE), output


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (np.eye(5), r"expected shape \(6, 6\)"),
        (np.eye(6)[:, :5], r"expected shape \(6, 6\)"),
        (np.ones(6), r"expected shape \(6, 6\)"),
        (np.full((6, 6), np.nan), "NaN"),
        (np.diag([1, 1, 1, 1, 1, np.inf]), "NaN or inf"),
        (np.zeros((6, 6)), "invertible"),
        (np.ones((6, 6)), "invertible"),
        (np.diag([1, 1, 1, 1, 1, 1e-13]), "invertible"),
        ("coupled", "transmission"),
    ],
)
def test_bad_transmission_is_a_value_error_naming_it(value, message) -> None:
    robot = dynid.models.puma560()
    with pytest.raises(ValueError, match=r"^transmission:") as error:
        robot.transmission = value
    assert re.search(message, str(error.value)), str(error.value)
    assert np.array_equal(robot.transmission, np.eye(6))  # unchanged
    with pytest.raises(ValueError, match=r"^transmission:"):
        dynid.Robot.from_dh(np.zeros((6, 4)), transmission=value)


def test_a_well_conditioned_scaling_is_accepted() -> None:
    """The tolerance is on sigma_min / sigma_max (1e-12), not on the size of T."""
    robot = dynid.models.puma560()
    robot.transmission = np.diag([1, 1, 1, 1, 1, 1e-11])
    robot.transmission = 1e-8 * np.eye(6)
    robot.transmission = 1e8 * np.eye(6)
    assert robot.transmission[0, 0] == 1e8
