"""robot.linearize (docs/uses.md, "Linearization", notes p. 44-47) against independent computations.

- Central finite differences of the state function f(x, u) = [qd; forward_dynamics(q, qd, u)]
  at x = (q, qd), u = rnea(q, qd, qdd), so that the linearization is about the trajectory point
  (q, qd, qdd): step 1e-6, tolerance 1e-6 relative to the largest entry (round-off of the
  forward dynamics ~1e-10 / 1e-6 relative).
- The planar 2R of the notes at an equilibrium, in closed form: A = [[0, I], [-B^-1 G, 0]],
  B = [[0], [B^-1]] with B(q) and G = dg/dq written out (notes p. 22-24, 45); 1e-12 relative.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from conftest import ARM_CASES, make_arm, random_state

STEP = 1e-6
FD_RTOL = 1e-6


def state_function(robot: dynid.Robot, x: np.ndarray, u: np.ndarray) -> np.ndarray:
    n = robot.n
    return np.concatenate([x[n:], robot.forward_dynamics(x[:n], x[n:], u)])


def jacobians_by_finite_differences(robot, q, qd, u):
    n = robot.n
    x = np.concatenate([q, qd])
    A = np.column_stack(
        [
            (state_function(robot, x + STEP * e, u) - state_function(robot, x - STEP * e, u))
            / (2 * STEP)
            for e in np.eye(2 * n)
        ]
    )
    B = np.column_stack(
        [
            (state_function(robot, x, u + STEP * e) - state_function(robot, x, u - STEP * e))
            / (2 * STEP)
            for e in np.eye(n)
        ]
    )
    return A, B


def assert_close(actual, expected, rtol):
    np.testing.assert_allclose(
        actual, expected, rtol=0, atol=rtol * max(1.0, np.abs(expected).max())
    )


@pytest.mark.parametrize("case", ARM_CASES)
def test_along_a_trajectory_matches_finite_differences_of_the_state_function(case, rng):
    arm = make_arm(case)
    robot = arm.robot()
    for _ in range(2):
        q, qd, qdd = random_state(rng, arm)  # qd away from 0: Coulomb friction is flat there
        u = robot.rnea(q, qd, qdd)
        np.testing.assert_allclose(robot.forward_dynamics(q, qd, u), qdd, rtol=0, atol=1e-9)
        A, B = robot.linearize(q, qd, qdd)
        A_fd, B_fd = jacobians_by_finite_differences(robot, q, qd, u)
        assert A.shape == (2 * robot.n, 2 * robot.n) and B.shape == (2 * robot.n, robot.n)
        assert_close(A, A_fd, FD_RTOL)
        assert_close(B, B_fd, FD_RTOL)


def test_at_an_equilibrium_matches_finite_differences_without_coulomb():
    """qd = qdd = 0, u = g(q): Coulomb friction has no derivative at qd = 0, so the check uses
    the arm without it (Fs = 0); the viscous friction stays (A's lower-right block -M^-1 Fv)."""
    arm = make_arm("random_standard")
    robot = arm.robot()
    robot.Fs = np.zeros(robot.n)
    q, _, _ = random_state(np.random.default_rng(7), arm)
    A, B = robot.linearize(q)
    A_fd, B_fd = jacobians_by_finite_differences(robot, q, np.zeros(robot.n), robot.gravity(q))
    assert_close(A, A_fd, FD_RTOL)
    assert_close(B, B_fd, FD_RTOL)
    np.testing.assert_allclose(
        A[robot.n :, robot.n :],
        -np.linalg.solve(robot.mass_matrix(q), np.diag(robot.Fv)),
        atol=1e-12,
    )


@pytest.mark.parametrize("q", [(0.3, -0.7), (np.pi / 2, 0.0), (-2.0, 1.2)])
def test_planar_2r_equilibrium_closed_form(q):
    l1, lc1, lc2, m1, m2, I1, I2, g0 = 1.0, 0.4, 0.35, 2.0, 1.5, 0.11, 0.07, 9.81
    robot = dynid.models.planar_2r(l1=l1, l2=0.8, lc1=lc1, lc2=lc2, m1=m1, m2=m2, I1=I1, I2=I2)
    q1, q2 = q
    c2, s1, s12 = np.cos(q2), np.sin(q1), np.sin(q1 + q2)
    # notes p. 22-24: inertia matrix and gravity of the 2R in a vertical plane, and G = dg/dq
    b11 = I1 + m1 * lc1**2 + I2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2)
    b12 = I2 + m2 * (lc2**2 + l1 * lc2 * c2)
    b22 = I2 + m2 * lc2**2
    Bq = np.array([[b11, b12], [b12, b22]])
    G = -g0 * np.array(
        [
            [(m1 * lc1 + m2 * l1) * s1 + m2 * lc2 * s12, m2 * lc2 * s12],
            [m2 * lc2 * s12, m2 * lc2 * s12],
        ]
    )
    Binv = np.array([[b22, -b12], [-b12, b11]]) / (b11 * b22 - b12**2)
    A_expected = np.block([[np.zeros((2, 2)), np.eye(2)], [-Binv @ G, np.zeros((2, 2))]])
    B_expected = np.vstack([np.zeros((2, 2)), Binv])
    np.testing.assert_allclose(robot.mass_matrix(q), Bq, rtol=1e-13)
    A, B = robot.linearize(q)
    assert_close(A, A_expected, 1e-12)
    assert_close(B, B_expected, 1e-12)


def test_batch_and_defaults():
    """(T, 2n, 2n) and (T, 2n, n), each sample equal to the single call (1e-13); omitted qd and
    qdd are zeros."""
    arm = make_arm("random_modified")
    robot = arm.robot()
    q, qd, qdd = random_state(np.random.default_rng(8), arm, count=5)
    A, B = robot.linearize(q, qd, qdd)
    assert A.shape == (5, 2 * robot.n, 2 * robot.n) and B.shape == (5, 2 * robot.n, robot.n)
    for t in range(5):
        A_t, B_t = robot.linearize(q[t], qd[t], qdd[t])
        np.testing.assert_allclose(A[t], A_t, rtol=0, atol=1e-13 * np.abs(A_t).max())
        np.testing.assert_allclose(B[t], B_t, rtol=0, atol=1e-13 * np.abs(B_t).max())
    zeros = np.zeros_like(q)
    for got, want in zip(robot.linearize(q), robot.linearize(q, zeros, zeros)):
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda r: r.linearize(np.zeros(r.n + 1)), "q"),
        (lambda r: r.linearize(np.zeros(r.n), np.zeros(r.n - 1)), "qd"),
        (lambda r: r.linearize(np.zeros(r.n), None, [np.nan] * r.n), "qdd"),
        (lambda r: r.linearize("abc"), "q"),
    ],
)
def test_bad_input_names_the_argument(call, name):
    robot = make_arm("lwr").robot()
    with pytest.raises(ValueError, match=rf"^{name}:"):
        call(robot)
