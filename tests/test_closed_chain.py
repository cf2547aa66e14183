"""Closed chains (issue 24, part 1): the notes' parallelogram robot against its closed forms
(pp. 7-10), the general point closure against the linear one, a five-bar by finite differences
and energy, and the identification of the parallelogram's base parameters from simulated logs.

The independent simulation of the same mechanisms (a Pinocchio tree closed by Lagrange
multipliers) is in tests/test_closed_chain_pinocchio.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import dynid
from dynid.model.closed_chain import ClosedChain
from dynid.model.loop_closures import LinearClosure, PointClosure

G0 = 9.81


def random_links(rng: np.random.Generator) -> dict[str, object]:
    return {
        "masses": rng.uniform(0.5, 3.0, 4),
        "inertias": rng.uniform(0.01, 0.2, 4),
        "com_distances": rng.uniform(-0.2, 0.5, 4),
        "l1": rng.uniform(0.4, 1.0),
        "l2": rng.uniform(0.3, 0.8),
    }


def closed_form(links: dict, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> dict:
    """The notes' parallelogram model, pp. 9-10, written out here by hand."""
    m, inertia, lc = links["masses"], links["inertias"], links["com_distances"]
    l1, l2 = links["l1"], links["l2"]
    b11 = inertia[0] + m[0] * lc[0] ** 2 + inertia[2] + m[2] * lc[2] ** 2 + m[3] * l1**2
    b22 = inertia[1] + m[1] * lc[1] ** 2 + inertia[3] + m[3] * lc[3] ** 2 + m[2] * l2**2
    b12 = m[2] * l2 * lc[2] - m[3] * l1 * lc[3]
    c, s = np.cos(q[:, 1] - q[:, 0]), np.sin(q[:, 1] - q[:, 0])
    M = np.empty((q.shape[0], 2, 2))
    M[:, 0, 0], M[:, 1, 1] = b11, b22
    M[:, 0, 1] = M[:, 1, 0] = b12 * c
    g = np.stack(
        [
            G0 * (m[0] * lc[0] + m[2] * lc[2] + m[3] * l1) * np.cos(q[:, 0]),
            G0 * (m[1] * lc[1] + m[2] * l2 - m[3] * lc[3]) * np.cos(q[:, 1]),
        ],
        axis=1,
    )
    # Christoffel symbols of B (only B12 depends on q, through q2 - q1):
    # c1 = (dB12/dq2) qd2^2 = -b12 s qd2^2, c2 = (dB12/dq1) qd1^2 = b12 s qd1^2.
    coriolis = np.stack([-b12 * s * qd[:, 1] ** 2, b12 * s * qd[:, 0] ** 2], axis=1)
    tau = np.einsum("tij,tj->ti", M, qdd) + coriolis + g
    return {"M": M, "g": g, "c": coriolis, "tau": tau, "b11": b11, "b22": b22, "b12": b12}


def states(rng: np.random.Generator, count: int = 50) -> tuple[np.ndarray, ...]:
    return (
        rng.uniform(-np.pi, np.pi, (count, 2)),
        rng.normal(size=(count, 2)),
        rng.normal(size=(count, 2)),
    )


@pytest.mark.parametrize("seed", range(5))
def test_parallelogram_matches_the_notes_closed_form(seed: int) -> None:
    rng = np.random.default_rng(seed)
    links = random_links(rng)
    chain = dynid.models.planar_parallelogram(**links)
    q, qd, qdd = states(rng)
    ref = closed_form(links, q, qd, qdd)
    scale = np.abs(ref["tau"]).max()
    np.testing.assert_allclose(chain.mass_matrix(q), ref["M"], rtol=0, atol=1e-13 * ref["b11"])
    np.testing.assert_allclose(
        chain.gravity(q), ref["g"], rtol=0, atol=1e-12 * np.abs(ref["g"]).max()
    )
    np.testing.assert_allclose(chain.coriolis(q, qd), ref["c"], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(chain.rnea(q, qd, qdd), ref["tau"], rtol=0, atol=1e-12 * scale)
    # one sample in, one sample out
    np.testing.assert_allclose(chain.rnea(q[0], qd[0], qdd[0]), ref["tau"][0], atol=1e-12 * scale)
    assert chain.mass_matrix(q[0]).shape == (2, 2)
    # forward dynamics inverts the closed form
    np.testing.assert_allclose(chain.forward_dynamics(q, qd, ref["tau"]), qdd, atol=1e-10)


def test_decoupled_parallelogram_has_constant_diagonal_inertia_and_no_coriolis() -> None:
    """Notes p. 9: m3 l2 lc3 = m4 l1 lc4 makes B diagonal and constant, so c = 0; with a
    further balance (m2 lc2 + m3 l2 = m4 lc4, m1 lc1 + m3 lc3 + m4 l1 = 0) g = 0 too (p. 10)."""
    rng = np.random.default_rng(7)
    links = random_links(rng)
    m, lc, l1, l2 = links["masses"], links["com_distances"], links["l1"], links["l2"]
    lc[3] = m[2] * l2 * lc[2] / (m[3] * l1)  # the structural condition (*)
    chain = dynid.models.planar_parallelogram(**links)
    q, qd, qdd = states(rng)
    M = chain.mass_matrix(q)
    assert np.abs(M[:, 0, 1]).max() < 1e-14
    np.testing.assert_allclose(M, np.broadcast_to(M[0], M.shape), rtol=0, atol=1e-14 * M[0].max())
    assert np.abs(chain.coriolis(q, qd * 10)).max() < 1e-12
    # each joint alone: b_ii qdd_i + g_i(q_i) = u_i
    tau = chain.rnea(q, qd, qdd)
    np.testing.assert_allclose(tau, M[0].diagonal() * qdd + chain.gravity(q), atol=1e-12)
    gravity_q1 = chain.gravity(np.stack([q[:, 0], np.zeros(len(q))], axis=1))[:, 0]
    np.testing.assert_allclose(chain.gravity(q)[:, 0], gravity_q1, atol=1e-13)  # g1(q1) only

    # balanced: g == 0 (lc1 negative: a counterweight behind the pivot)
    lc[1] = (m[3] * lc[3] - m[2] * l2) / m[1]
    lc[0] = -(m[2] * lc[2] + m[3] * l1) / m[0]
    balanced = dynid.models.planar_parallelogram(**links)
    assert np.abs(balanced.gravity(q)).max() < 1e-12


def test_energy_is_conserved_without_torque() -> None:
    """Forward dynamics of the closed chain conserves T + U (notes p. 10's U from p_ci,y)."""
    links = random_links(np.random.default_rng(3))
    chain = dynid.models.planar_parallelogram(**links)

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate([x[2:], chain.forward_dynamics(x[:2], x[2:], np.zeros(2))])

    x0 = np.array([0.3, 1.9, 1.5, -2.0])
    sol = solve_ivp(
        rhs, (0.0, 2.0), x0, method="DOP853", rtol=1e-12, atol=1e-12, dense_output=False
    )
    q, qd = sol.y[:2].T, sol.y[2:].T
    energy = chain.kinetic_energy(q, qd) + chain.potential_energy(q)
    swing = np.abs(chain.potential_energy(q) - chain.potential_energy(q[0])).max()
    assert swing > 1.0  # the motion exchanges energy between T and U
    assert np.abs(energy - energy[0]).max() < 1e-8 * swing
    # and the notes' closed-form energy (T from B, U from the y-components of the p_ci)
    ref = closed_form(links, q, qd, qd)
    T = 0.5 * np.einsum("ti,tij,tj->t", qd, ref["M"], qd)
    np.testing.assert_allclose(chain.kinetic_energy(q, qd), T, rtol=1e-12)


def test_regressor_and_the_loops_own_groupings() -> None:
    rng = np.random.default_rng(11)
    links = random_links(rng)
    chain = dynid.models.planar_parallelogram(**links)
    chain.Ia, chain.Fv, chain.Fs = [0.2, 0.3], [0.5, 0.4], [1.0, 0.7]
    q, qd, qdd = states(rng)
    Y = chain.regressor(q, qd, qdd, rotor=True, friction=True)
    assert Y.shape == (50, 2, 46)
    tau = chain.rnea(q, qd, qdd)
    np.testing.assert_allclose(
        Y @ chain.parameter_vector(True, True), tau, atol=1e-12 * np.abs(tau).max()
    )
    np.testing.assert_allclose(
        chain.gravity_regressor(q) @ chain.parameter_vector(), chain.gravity(q), atol=1e-12
    )

    base = dynid.base_parameters(chain)  # the function answers for a closed chain too
    assert base is chain.base_parameters()
    # B11, B22, B12 / l2 and the gravity coefficients of p. 9-10, plus the CoMs off the link
    # axes (my_i), which the notes' model sets to zero: 8 base parameters.
    assert base.count == 8
    values = dict(zip(base.names, base.values(chain), strict=True))
    ref = closed_form(links, q, qd, qdd)
    m, lc, l1, l2 = links["masses"], links["com_distances"], links["l1"], links["l2"]
    assert values["Izz1R"] == pytest.approx(ref["b11"], rel=1e-12)
    assert values["Izz2R"] == pytest.approx(ref["b22"], rel=1e-12)
    assert values["mx3R"] * l2 == pytest.approx(ref["b12"], rel=1e-11, abs=1e-12)
    assert values["mx1R"] + values["mx3R"] == pytest.approx(
        m[0] * lc[0] + m[2] * lc[2] + m[3] * l1, rel=1e-11
    )
    assert values["mx2R"] == pytest.approx(m[1] * lc[1] + m[2] * l2 - m[3] * lc[3], rel=1e-11)
    assert all(values[f"my{i}R"] == 0.0 for i in (1, 2, 3))
    # the base columns reproduce the torque with the base values
    Yb = chain.regressor(q, qd, qdd, columns=base.independent)
    np.testing.assert_allclose(
        Yb @ base.values(chain),
        chain.rnea(q, qd, qdd) - chain.Ia * qdd - chain.Fv * qd - chain.Fs * np.sign(qd),
        atol=1e-11,
    )
    # B is constant on the diagonal, so each rotor's Ia q_i'' merges into B_ii's grouping: the
    # drive terms add Fv and Fs only (8 + 4); the identifiable sum is named Izz1R / Izz2R.
    with_drive = chain.base_parameters(rotor=True, friction=True)
    assert with_drive.count == 12
    assert "Ia1" in with_drive.expressions[with_drive.names.index("Izz1R")]
    assert dynid.base_parameters(chain, "gravity").count == 4


def test_point_closure_gives_the_linear_closures_dynamics() -> None:
    """The general single-loop closure (Newton on the loop equations, G from the constraint
    Jacobian, Gdot qd from the points' bias accelerations) on the parallelogram."""
    rng = np.random.default_rng(5)
    chain = dynid.models.planar_parallelogram(**random_links(rng))
    q, qd, qdd = states(rng)
    assembly = chain.tree_motion(np.array([0.4, 1.7])).y[0] + np.array([0.0, 0.1, 0.0, -0.1])
    general = ClosedChain(
        chain.branches,
        PointClosure(between=(0, 1), actuated=[0, 2], assembly=assembly),
        links=chain.links,
    )
    q = 0.4 + 0.5 * (q / np.pi) + np.array([0.0, 1.3])  # near the assembly, away from q1 = q2
    np.testing.assert_allclose(general.tree_motion(q).y, chain.tree_motion(q).y, atol=1e-12)
    for method, args in (
        ("rnea", (q, qd, qdd)),
        ("mass_matrix", (q,)),
        ("gravity", (q,)),
        ("regressor", (q, qd, qdd)),
    ):
        ref = getattr(chain, method)(*args)
        np.testing.assert_allclose(
            getattr(general, method)(*args), ref, atol=1e-11 * np.abs(ref).max()
        )
    assert general.base_parameters().count == chain.base_parameters().count


def five_bar() -> ClosedChain:
    """A planar five-bar (the MIT Direct Drive Mark IV's linkage, notes p. 6): pivots O1 = 0 and
    O2 = (d, 0), branches of lengths (0.5, 0.6) and (0.5, 0.6) meeting at P."""
    g = (0.0, -G0, 0.0)
    rng = np.random.default_rng(2)
    branches = []
    for base_x in (0.0, 0.4):
        base = np.eye(4)
        base[0, 3] = base_x
        tool = np.eye(4)
        tool[0, 3] = 0.6
        robot = dynid.Robot.from_dh(
            [[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, 0.0]],
            joint_types="RR",
            convention="modified",
            gravity=g,
            base=base,
            tool=tool,
        )
        for i in range(2):
            mass, izz = rng.uniform(0.5, 2.0), rng.uniform(0.01, 0.1)
            robot.set_link(
                i,
                mass,
                (rng.uniform(0.1, 0.4), rng.uniform(-0.05, 0.05), 0.0),
                np.diag([0.01 * izz, izz, izz]),
            )
        branches.append(robot)
    # elbows out: a1 at 120 deg, b1 at 60 deg, P above the middle
    a1, b1 = np.radians(120.0), np.radians(60.0)
    A = 0.5 * np.array([np.cos(a1), np.sin(a1)])
    B = np.array([0.4, 0.0]) + 0.5 * np.array([np.cos(b1), np.sin(b1)])
    half = np.linalg.norm(B - A) / 2
    P = (A + B) / 2 + np.sqrt(0.36 - half**2) * np.array([0.0, 1.0])
    a2 = np.arctan2(*(P - A)[::-1]) - a1
    b2 = np.arctan2(*(P - B)[::-1]) - b1
    closure = PointClosure(between=(0, 1), actuated=[0, 2], assembly=[a1, a2, b1, b2])
    return ClosedChain(branches, closure, name="five-bar")


def test_five_bar_closure_by_finite_differences() -> None:
    chain = five_bar()
    q0 = chain.closure.assembly[[0, 2]]
    qd, qdd = np.array([0.7, -1.1]), np.array([0.3, 0.9])
    h = 1e-5

    def y_at(t: float) -> np.ndarray:
        return chain.tree_motion(q0 + qd * t + 0.5 * qdd * t**2).y[0]

    motion = chain.tree_motion(q0, qd, qdd)
    branch_a, branch_b = chain.branches
    pa = branch_a.fkine(motion.y[0, :2])[:2, 3]
    pb = branch_b.fkine(motion.y[0, 2:])[:2, 3]
    assert np.abs(pa - pb).max() < 1e-12  # the loop closes
    yd_fd = (y_at(h) - y_at(-h)) / (2 * h)
    ydd_fd = (y_at(h) - 2 * y_at(0.0) + y_at(-h)) / h**2
    np.testing.assert_allclose(motion.yd[0], yd_fd, atol=1e-8)  # O(h^2) truncation
    np.testing.assert_allclose(motion.ydd[0], ydd_fd, atol=1e-4)  # O(h^2) + rounding / h^2


def test_five_bar_conserves_energy() -> None:
    chain = five_bar()

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate(
            [x[2:], chain.forward_dynamics(x[:2], x[2:], chain.gravity(x[:2]) * 0.8)]
        )

    # 80 % gravity compensation: a slow, conservative motion (the torque is a potential force:
    # U' = 0.2 U), near the assembly so the loop stays away from its singularities.
    x0 = np.concatenate([chain.closure.assembly[[0, 2]], [0.2, -0.1]])
    sol = solve_ivp(rhs, (0.0, 0.5), x0, method="DOP853", rtol=1e-11, atol=1e-11)
    q, qd = sol.y[:2].T, sol.y[2:].T
    energy = chain.kinetic_energy(q, qd) + 0.2 * chain.potential_energy(q)
    assert np.ptp(chain.kinetic_energy(q, qd)) > 1e-3
    assert np.abs(energy - energy[0]).max() < 1e-8


def test_point_closure_refuses_a_configuration_that_cannot_close() -> None:
    chain = five_bar()
    with pytest.raises(ValueError, match="q: the loop cannot be closed"):
        chain.rnea([np.pi, 0.0], [0.0, 0.0], [0.0, 0.0])  # the first links point apart: 1.4 m gap


def test_bad_input_is_named() -> None:
    chain = dynid.models.planar_parallelogram([1, 1, 1, 1], [0.1] * 4, [0.2] * 4, 0.5, 0.4)
    with pytest.raises(ValueError, match="qd: expected shape"):
        chain.rnea([0, 0], [0, 0, 0], [0, 0])
    with pytest.raises(ValueError, match="q: not finite"):
        chain.gravity([np.nan, 0])
    with pytest.raises(ValueError, match="qdd: 1 samples, q has 2"):
        chain.rnea(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2))
    with pytest.raises(ValueError, match="masses"):
        dynid.models.planar_parallelogram([1, 1, 1], [0.1] * 4, [0.2] * 4, 0.5, 0.4)
    with pytest.raises(ValueError, match="masses, inertias"):
        dynid.models.planar_parallelogram([1, 1, -1, 1], [0.1] * 4, [0.2] * 4, 0.5, 0.4)
    with pytest.raises(ValueError, match="l2"):
        dynid.models.planar_parallelogram([1, 1, 1, 1], [0.1] * 4, [0.2] * 4, 0.5, 0.0)
    with pytest.raises(ValueError, match="l1"):
        dynid.models.planar_parallelogram([1, 1, 1, 1], [0.1] * 4, [0.2] * 4, "long", 0.4)
    with pytest.raises(ValueError, match="gravity"):
        dynid.models.planar_parallelogram([1, 1, 1, 1], [0.1] * 4, [0.2] * 4, 0.5, 0.4, "down")
    with pytest.raises(ValueError, match="Fv"):
        chain.Fv = [1.0, -1.0]
    with pytest.raises(ValueError, match="kind"):
        chain.base_parameters("inertia")
    with pytest.raises(ValueError, match="columns"):
        chain.regressor([0, 0], [0, 0], [0, 0], columns=[0, 99])
    with pytest.raises(ValueError, match="matrix"):
        LinearClosure([[1.0, 0.0], [2.0, 0.0]])
    with pytest.raises(ValueError, match="closure"):
        ClosedChain(chain.branches, LinearClosure(np.eye(3)))
    branch = chain.branches[0].copy()
    branch.Fv = [0.1, 0.0]
    with pytest.raises(ValueError, match=r"branches\[0\]: drive terms"):
        ClosedChain([branch, chain.branches[1]], chain.closure)


def exciting_log(
    chain: ClosedChain, seconds: float, rate: float, noise: float, seed: int
) -> dynid.Log:
    """A simulated log of the motors: a sum of sinusoids per joint, the torques by the chain's
    inverse dynamics plus white noise (the true model is the chain's own parameters)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 1.0 / rate)
    w = 2 * np.pi * np.array([0.1, 0.23, 0.37, 0.51])
    amp = rng.uniform(0.2, 0.5, (2, 4))
    phase = rng.uniform(0, 2 * np.pi, (2, 4))
    arg = w * t[:, None, None] + phase  # (T, 2, 4)
    q = np.array([0.6, 2.0]) + np.sum(amp * np.sin(arg), axis=2)
    qd = np.sum(amp * w * np.cos(arg), axis=2)
    qdd = -np.sum(amp * w**2 * np.sin(arg), axis=2)
    tau = chain.rnea(q, qd, qdd) + noise * rng.normal(size=q.shape)
    return dynid.Log(t=t, q=q, tau=tau, qd=qd, qdd=qdd, source="simulated parallelogram")


def test_identification_recovers_the_base_parameters_from_a_simulated_log() -> None:
    chain = dynid.models.planar_parallelogram(
        [2.0, 1.5, 1.2, 0.8], [0.1, 0.08, 0.05, 0.03], [0.3, 0.25, 0.4, 0.1], 0.7, 0.5
    )
    chain.Ia, chain.Fv, chain.Fs = [0.05, 0.04], [0.3, 0.2], [0.6, 0.4]
    truth = chain.base_parameters(rotor=True, friction=True).values(chain)

    exact = dynid.identify_closed_chain(
        exciting_log(chain, 20.0, 200.0, 0.0, 1), chain, rotor=True, friction=True
    )
    np.testing.assert_allclose(exact.theta, truth, rtol=1e-9, atol=1e-10)

    noisy = dynid.identify_closed_chain(
        exciting_log(chain, 60.0, 200.0, 0.05, 2), chain, rotor=True, friction=True
    )
    z = (noisy.theta - truth) / noisy.std
    assert np.all(np.abs(z) < 5.0), z  # 12 parameters: |z| < 5 fails with probability ~1e-5
    assert np.all(noisy.std < 0.05 * np.maximum(np.abs(truth), 0.1))
    q = np.array([[0.5, 1.9]])
    np.testing.assert_allclose(
        noisy.predict(chain, q, q * 0.1, q * 0.2), chain.rnea(q, q * 0.1, q * 0.2), atol=0.02
    )


def test_identification_from_positions_only() -> None:
    """A log with q and tau only: qd, qdd are differentiated (and filtered) by prepare_log."""
    chain = dynid.models.planar_parallelogram(
        [2.0, 1.5, 1.2, 0.8], [0.1, 0.08, 0.05, 0.03], [0.3, 0.25, 0.4, 0.1], 0.7, 0.5
    )
    full = exciting_log(chain, 40.0, 500.0, 0.0, 3)
    log = dynid.Log(t=full.t, q=full.q, tau=full.tau, source="q and tau only")
    fit = dynid.identify_closed_chain(log, chain, cutoff=5.0)
    truth = chain.base_parameters().values(chain)
    # second differences of q at 500 Hz, then a 5 Hz zero-phase filter applied to q and tau
    # alike: the error is the filter's edge effects and O(dt^2) differencing, ~1e-4 relative
    np.testing.assert_allclose(fit.theta, truth, rtol=0, atol=2e-3 * np.abs(truth).max())
    assert any(note.startswith("qd and qdd computed") for note in fit.notes)
    with pytest.raises(ValueError, match="log: has 3 joints"):
        dynid.identify_closed_chain(
            dynid.Log(t=full.t, q=np.zeros((len(full.t), 3)), tau=np.zeros((len(full.t), 3))), chain
        )
    with pytest.raises(ValueError, match="cutof: not an option"):
        dynid.identify_closed_chain(log, chain, cutof=5.0)
    with pytest.raises(ValueError, match=r"chain: expected a dynid\.ClosedChain"):
        dynid.identify_closed_chain(log, dynid.models.planar_2r())


def test_point_closure_refuses_a_singular_configuration() -> None:
    """The parallelogram folded flat (q1 = q2): links 3 and 4 are collinear with 1 and 2, the
    passive angles are not determined by the loop."""
    chain = dynid.models.planar_parallelogram([1, 1, 1, 1], [0.1] * 4, [0.2] * 4, 0.5, 0.4)
    assembly = chain.tree_motion(np.array([0.3, 1.8])).y[0]
    general = ClosedChain(
        chain.branches,
        PointClosure(between=(0, 1), actuated=[0, 2], assembly=assembly),
        links=chain.links,
    )
    for flat in ([1.0, 1.0], [1.0, 1.0 + 1e-9]):
        with pytest.raises(ValueError, match=r"q: the loop"):
            general.gravity(flat)
    # Close to flat the solution stays on the parallelogram's branch (Newton alone, from the
    # previous step, jumped to the crossed "anti-parallelogram" there: G off by 10) ...
    near = np.array([[1.0, 1.003], [1.0, 1.0002], [2.0, 2.0001]])
    np.testing.assert_allclose(general.tree_motion(near).G, chain.tree_motion(near).G, atol=1e-10)
    # ... and a path through the flat configuration, where the two branches cross (det A_p
    # changes sign), is refused: which branch goes on is not determined by the loop.
    with pytest.raises(ValueError, match="q: the loop cannot be closed along the path"):
        general.gravity([2.0, 1.9999])


def test_the_docs_examples_run() -> None:
    """The parallelogram and the turret examples of docs/closed_chains.md, as written."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "closed_chains.md").read_text("utf-8")
    codes = re.findall(r"^```python\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL)
    for code in (codes[0], codes[2]):  # [1] sketches a five-bar, [3] needs a log
        exec(compile(code, "docs/closed_chains.md", "exec"), {})


def turret_arm(massless_loop: bool = False, seed: int = 0) -> ClosedChain:
    """An industrial arm's parallelogram (docs/closed_chains.md, "A loop on a moving link"):
    turret q1 about z, upper arm q2 about the horizontal shoulder axis, and the forearm driven by
    motor 3 at the shoulder through a crank (angle q3) and a rod parallel to the upper arm. Branch
    1 starts with a massless copy of the turret joint, tied to q1 by the closure."""
    h, upper, forearm, lever = 0.5, 0.8, 0.9, 0.25
    rng = np.random.default_rng(seed)
    g = (0.0, 0.0, -9.81)

    def tool(x: float) -> np.ndarray:
        T = np.eye(4)
        T[0, 3] = x
        return T

    rows = [[0.0, 0.0, h, 0.0], [0.0, np.pi / 2, 0.0, 0.0]]
    arm = dynid.Robot.from_dh(
        [*rows, [upper, 0.0, 0.0, 0.0]], convention="modified", gravity=g, tool=tool(-lever)
    )
    loop = dynid.Robot.from_dh(
        [*rows, [lever, 0.0, 0.0, 0.0]], convention="modified", gravity=g, tool=tool(upper)
    )

    def body(robot: dynid.Robot, i: int, mass: float, length: float) -> None:
        izz = mass * length**2 / 12
        com = (rng.uniform(0.2, 0.6) * length, rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02))
        tensor = np.diag([0.05 * izz + 1e-3, izz, izz]) + 1e-5 * (1 - np.eye(3))
        robot.set_link(i, mass, com, tensor)

    body(arm, 0, 8.0, 0.3)
    body(arm, 1, 6.0, upper)
    body(arm, 2, 4.0, forearm)
    if not massless_loop:
        body(loop, 1, 1.0, lever)
        body(loop, 2, 0.7, upper)
    # tree [turret, upper arm, elbow (rel.), turret copy, crank, rod (rel. to the crank)]:
    # the forearm points opposite the crank (theta3 = q3 - q2 - pi), the rod along the upper arm.
    closure = LinearClosure(
        [[1, 0, 0], [0, 1, 0], [0, -1, 1], [1, 0, 0], [0, 0, 1], [0, 1, -1]],
        offset=[0, 0, -np.pi, 0, 0, 0],
    )
    links = [(0, 0), (0, 1), (0, 2)] + ([] if massless_loop else [(1, 1), (1, 2)])
    return ClosedChain([arm, loop], closure, links=links, name="arm with a parallelogram")


def test_a_parallelogram_hanging_from_the_turret() -> None:
    chain = turret_arm()
    rng = np.random.default_rng(4)
    # within 0.25 rad of the assembly the rod's tip stays > 0.1 m from the turret's axis, where
    # the point closure's turret copy is undetermined (a singular A_p: it refuses to cross one)
    q = np.array([0.3, 0.9, 2.5]) + rng.uniform(-0.25, 0.25, (30, 3))
    qd, qdd = rng.normal(size=(2, 30, 3))
    # the loop closes in space
    motion = chain.tree_motion(q)
    arm, loop = chain.branches
    tip_arm = arm.fkine(motion.y[:, :3])[:, :3, 3]
    tip_loop = loop.fkine(motion.y[:, 3:])[:, :3, 3]
    assert np.abs(tip_arm - tip_loop).max() < 1e-14
    # the general closure, solving the turret copy, the elbow and the rod from the 3-D
    # coincidence of the rod's tip with the forearm's lever, gives the same dynamics
    general = ClosedChain(
        chain.branches,
        PointClosure(
            between=(0, 1),
            actuated=[0, 1, 4],
            assembly=chain.tree_motion(q[0]).y[0] + 0.05,
            components=(0, 1, 2),
        ),
        links=chain.links,
    )
    tau = chain.rnea(q, qd, qdd)
    np.testing.assert_allclose(general.rnea(q, qd, qdd), tau, atol=1e-11 * np.abs(tau).max())
    np.testing.assert_allclose(
        general.regressor(q, qd, qdd), chain.regressor(q, qd, qdd), atol=1e-11 * np.abs(tau).max()
    )
    # the massless copy brings no parameters: 5 links, 50 standard parameters
    assert len(chain.parameter_vector()) == 50
    np.testing.assert_allclose(
        chain.regressor(q, qd, qdd) @ chain.parameter_vector(), tau, atol=1e-12 * np.abs(tau).max()
    )
    with pytest.raises(ValueError, match="massless"):
        ClosedChain(chain.branches, chain.closure, links=[(0, 0), (0, 1), (0, 2), (1, 1)])


def test_a_massless_parallelogram_is_the_serial_arm_driven_through_it() -> None:
    """Without crank and rod masses the mechanism is the serial arm, with the elbow driven from
    the shoulder: tau_chain = G_s^T tau_serial(q1, q2, q3 - q2 - pi), G_s the elbow's map."""
    chain = turret_arm(massless_loop=True)
    serial = chain.branches[0]
    rng = np.random.default_rng(8)
    q = rng.uniform(-np.pi, np.pi, (30, 3))
    qd, qdd = rng.normal(size=(2, 30, 3))
    theta = np.stack([q[:, 0], q[:, 1], q[:, 2] - q[:, 1] - np.pi], axis=1)
    Gs = np.array([[1, 0, 0], [0, 1, 0], [0, -1, 1]])
    tau_serial = serial.rnea(theta, qd @ Gs.T, qdd @ Gs.T)
    np.testing.assert_allclose(
        chain.rnea(q, qd, qdd), tau_serial @ Gs, atol=1e-12 * np.abs(tau_serial).max()
    )


def test_the_turret_arm_conserves_energy() -> None:
    chain = turret_arm()

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate([x[3:], chain.forward_dynamics(x[:3], x[3:], np.zeros(3))])

    x0 = np.array([0.2, 0.8, 2.6, 1.0, -0.5, 0.8])
    sol = solve_ivp(rhs, (0.0, 0.6), x0, method="DOP853", rtol=1e-12, atol=1e-12)
    q, qd = sol.y[:3].T, sol.y[3:].T
    energy = chain.kinetic_energy(q, qd) + chain.potential_energy(q)
    swing = np.ptp(chain.potential_energy(q))
    assert swing > 1.0
    assert np.abs(energy - energy[0]).max() < 1e-8 * swing


def test_branches_and_links_are_checked() -> None:
    chain = dynid.models.planar_parallelogram([1, 1, 1, 1], [0.1] * 4, [0.2] * 4, 0.5, 0.4)
    other = chain.branches[1].copy()
    other.gravity_vector = [0.0, 0.0, -9.81]
    with pytest.raises(ValueError, match="same gravity"):
        ClosedChain([chain.branches[0], other], chain.closure)
    with pytest.raises(ValueError, match="links: expected"):
        ClosedChain(chain.branches, chain.closure, links=[("a", 0)])
    with pytest.raises(ValueError, match="links: expected distinct"):
        ClosedChain(chain.branches, chain.closure, links=[(0, 0), (0, 0), (1, 0), (1, 1)])


def test_point_closure_after_many_turns() -> None:
    """A revolute independent joint that turned 1000 times is where it was: the same passive
    angles, reached by the shortest path (not 25,000 continuation steps), converged at the
    rounding floor of angles near 6283 rad."""
    chain = five_bar()
    q0 = chain.closure.assembly[[0, 2]] + np.array([0.1, -0.05])
    turned = q0 + 2 * np.pi * np.array([1000.0, -3.0])
    near, far = chain.tree_motion(q0).y[0], chain.tree_motion(turned).y[0]
    np.testing.assert_allclose(far[[0, 2]], turned, rtol=0, atol=0)
    np.testing.assert_allclose(far[[1, 3]], near[[1, 3]], atol=1e-9)
    np.testing.assert_allclose(chain.gravity(turned), chain.gravity(q0), atol=1e-9)


def test_the_identification_example(tmp_path, capsys) -> None:
    """examples/closed_chain_identification.py: a filtered CSV of the motors, positions only;
    correlation-robust standard deviations that cover the errors (they are 5-7 times the
    independent-samples ones, which left Fv1, Fs1 5-6 of them off)."""
    import importlib.util
    import re
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "closed_chain_identification.py"
    spec = importlib.util.spec_from_file_location("closed_chain_example", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main(tmp_path)
    out = capsys.readouterr().out
    assert "the residuals are correlated in time" in out
    error, z = re.search(r"largest error: ([\d.]+)% .*largest \|z\| ([\d.]+)", out).groups()
    assert float(error) < 1.0
    assert float(z) < 3.0
    assert (tmp_path / "parallelogram_motors.csv").is_file()
