"""jacobian_dot, cartesian_inertia and cartesian_dynamics (docs/uses.md,
"Cartesian (operational-space) dynamics"; Khatib 1987; notes p. 48-49) against independent
computations:

- jacobian_dot: central finite differences of jacobian(q) along qd,
  (J(q + h qd) - J(q - h qd)) / 2h, h = 1e-6, 1e-7 relative;
- for the 6-dof PUMA 560 (square J): the coordinate-transformation formulas of the notes (p. 49)
  Lam = J^-T M J^-1, mu = J^-T c - Lam Jdot qd, p = J^-T g, 1e-9 relative (J^-1 amplifies
  round-off by its condition number, < 1e3 at the sampled configurations);
- for any arm (7-dof LWR, selected rows for n < 6): Lam xdd + mu + p = F with qdd from
  forward_dynamics under tau = J^T F + friction(qd) and xdd = J qdd + Jdot qd, 1e-9 relative.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from conftest import ARM_CASES, make_arm, random_state


def assert_close(actual, expected, rtol):
    np.testing.assert_allclose(
        actual, expected, rtol=0, atol=rtol * max(1.0, np.abs(expected).max())
    )


@pytest.mark.parametrize("case", ARM_CASES)
def test_jacobian_dot_matches_finite_differences(case, rng):
    arm = make_arm(case)
    robot = arm.robot()
    h = 1e-6
    for _ in range(3):
        q, qd, _ = random_state(rng, arm)
        expected = (robot.jacobian(q + h * qd) - robot.jacobian(q - h * qd)) / (2 * h)
        assert_close(robot.jacobian_dot(q, qd), expected, 1e-7)
    Q, QD, _ = random_state(rng, arm, count=4)
    batch = robot.jacobian_dot(Q, QD)
    assert batch.shape == (4, 6, robot.n)
    np.testing.assert_array_equal(batch[2], robot.jacobian_dot(Q[2], QD[2]))


def puma_states(count: int, seed: int):
    """PUMA configurations away from its singularities (|sin q3 - ...|, wrist q5, elbow)."""
    robot = dynid.models.puma560()
    rng = np.random.default_rng(seed)
    states = []
    while len(states) < count:
        q = rng.uniform(-2.5, 2.5, 6)
        if np.linalg.cond(robot.jacobian(q)) < 1e3:
            states.append((q, rng.uniform(-1.5, 1.5, 6)))
    return robot, states


def test_puma_matches_the_square_jacobian_formulas():
    robot, states = puma_states(5, seed=11)
    for q, qd in states:
        J = robot.jacobian(q)
        J_inv = np.linalg.inv(J)
        M = robot.mass_matrix(q)
        Lam_expected = J_inv.T @ M @ J_inv
        mu_expected = (
            J_inv.T @ robot.coriolis(q, qd) - Lam_expected @ robot.jacobian_dot(q, qd) @ qd
        )
        p_expected = J_inv.T @ robot.gravity(q)
        assert_close(robot.cartesian_inertia(q), Lam_expected, 1e-9)
        Lam, mu, p = robot.cartesian_dynamics(q, qd)
        assert_close(Lam, Lam_expected, 1e-9)
        assert_close(mu, mu_expected, 1e-9)
        assert_close(p, p_expected, 1e-9)


@pytest.mark.parametrize(
    ("robot_name", "rows"),
    [
        ("puma", None),
        ("lwr", None),
        ("lwr", "position"),
        ("lwr", "orientation"),
        ("prismatic_first", "position"),
        ("prismatic_first", (0, 2, 4)),
        ("planar", (0, 1)),
    ],
)
def test_operational_space_equation_matches_forward_dynamics(robot_name, rows):
    rng = np.random.default_rng(12)
    if robot_name == "puma":
        robot, states = puma_states(3, seed=13)
    else:
        if robot_name == "planar":
            robot = dynid.models.planar_2r()
            types = "RR"
        else:
            arm = make_arm("lwr" if robot_name == "lwr" else "random_prismatic_first")
            robot, types = arm.robot(), arm.joint_types
        states = [random_state(rng, types)[:2] for _ in range(3)]
    selected = dynid.model.operational_space.task_rows(rows)
    for q, qd in states:
        F = rng.normal(size=len(selected)) * 10
        tau = robot.jacobian(q)[selected].T @ F + robot.friction(qd)
        qdd = robot.forward_dynamics(q, qd, tau)
        xdd = robot.jacobian(q)[selected] @ qdd + robot.jacobian_dot(q, qd)[selected] @ qd
        Lam, mu, p = robot.cartesian_dynamics(q, qd, rows=rows)
        assert Lam.shape == (len(selected), len(selected))
        assert_close(Lam @ xdd + mu + p, F, 1e-9)
        np.testing.assert_allclose(Lam, Lam.T, rtol=0, atol=1e-12 * np.abs(Lam).max())


def test_batch_equals_single_samples():
    robot, states = puma_states(4, seed=14)
    Q = np.array([s[0] for s in states])
    QD = np.array([s[1] for s in states])
    Lam, mu, p = robot.cartesian_dynamics(Q, QD)
    assert Lam.shape == (4, 6, 6) and mu.shape == (4, 6) and p.shape == (4, 6)
    assert robot.cartesian_inertia(Q).shape == (4, 6, 6)
    for t in range(4):
        for got, want in zip((Lam[t], mu[t], p[t]), robot.cartesian_dynamics(Q[t], QD[t])):
            assert_close(got, want, 1e-12)


def test_singular_configurations_raise_naming_q():
    """PUMA wrist singularity q5 = 0 (axes 4 and 6 aligned); a 2R arm asked for all six rows;
    the singular sample of a batch is named. Near (1e-3 rad from) the wrist singularity the
    inertia still exists and grows like 1/q5^2."""
    puma = dynid.models.puma560()
    q = np.array([0.3, -0.5, 0.9, 0.4, 0.0, -0.2])
    with pytest.raises(ValueError, match=r"^q: singular configuration"):
        puma.cartesian_inertia(q)
    with pytest.raises(ValueError, match=r"^q: singular configuration"):
        puma.cartesian_dynamics(q, np.ones(6))
    batch = np.array([q + np.array([0, 0, 0, 0, 0.5, 0]), q])
    with pytest.raises(ValueError, match=r"^q: singular configuration at sample 1"):
        puma.cartesian_inertia(batch)
    near = [puma.cartesian_inertia(q + np.array([0, 0, 0, 0, eps, 0])) for eps in (1e-3, 2e-3)]
    ratio = np.abs(near[0]).max() / np.abs(near[1]).max()
    assert 3.5 < ratio < 4.5  # 1/eps^2
    with pytest.raises(ValueError, match=r"^q: singular configuration"):
        dynid.models.planar_2r().cartesian_inertia([0.3, 0.4])
    # position rows only: the wrist singularity does not matter
    assert np.all(np.isfinite(puma.cartesian_inertia(q, rows="position")))


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda r: r.cartesian_inertia(np.zeros(r.n + 1)), "q"),
        (lambda r: r.cartesian_dynamics(np.full(r.n, 0.3), np.zeros(r.n - 1)), "qd"),
        (lambda r: r.cartesian_inertia(np.full(r.n, 0.3), rows="speed"), "rows"),
        (lambda r: r.cartesian_inertia(np.full(r.n, 0.3), rows=(0, 0)), "rows"),
        (lambda r: r.cartesian_inertia(np.full(r.n, 0.3), rows=(6,)), "rows"),
        (lambda r: r.jacobian_dot(np.zeros(r.n), np.zeros((2, r.n))), "qd"),
    ],
)
def test_bad_input_names_the_argument(call, name):
    robot = make_arm("lwr").robot()
    with pytest.raises(ValueError, match=rf"^{name}:"):
        call(robot)
