"""Exact time derivatives of inverse dynamics, ``Robot.rnea_time_derivatives`` (issue 12 item 1,
the jerk/snap Newton-Euler recursion), against independent computations on every reference arm
(the LWR, both DH conventions, prismatic joints, random base, tool, gravity and drive terms):

- tau equals ``rnea`` (1e-12 relative to max|tau|);
- along the analytic motion q_i(t) = a_i + b_i sin(w_i t + phi_i), whose derivatives up to the
  fourth are known in closed form, tau_dot and tau_ddot match 8th-order central differences IN
  TIME of ``rnea`` evaluated on the motion (9 points; step 3e-3 s for the first derivative, 1e-2 s
  for the second: truncation ~(w h)^8 < 1e-12, round-off ~1e-13 and ~1e-12 relative). Tolerance
  1e-9 relative to the largest entry (measured: < 2e-12 and < 5e-12);
- tau_dot equals the chain rule dtau/dq qd + dtau/dqd qdd + M qddd with ``rnea_derivatives``
  (checked against Pinocchio in test_rnea_derivatives.py) and ``mass_matrix``, 1e-12 relative;
- a batch (T, n) equals its samples one by one (exactly), and bad arguments raise ValueError
  naming them. No allocation per call and the C++ size checks: tests/cpp/
  test_elastic_no_allocation.cpp (compiled in test_elastic.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import ARM_CASES, make_arm

# 8th-order central-difference weights for the first and second derivative (points -4..4).
D1 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
D2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])
FD_RTOL = 1e-9
EXACT_RTOL = 1e-12


def sine_motion(n: int, seed: int = 1):
    """q(t) = a + b sin(w t + phi) per joint and its derivatives 1..4, in closed form."""
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-1.0, 1.0, n), rng.uniform(0.3, 1.0, n)
    w, phi = rng.uniform(1.0, 3.0, n), rng.uniform(0.0, 2 * np.pi, n)

    def at(t):
        t = np.asarray(t, dtype=float)[..., None]
        s, c = np.sin(w * t + phi), np.cos(w * t + phi)
        return a + b * s, b * w * c, -b * w**2 * s, -b * w**3 * c, b * w**4 * s

    return at


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    return float(np.abs(actual - expected).max() / max(1.0, np.abs(expected).max()))


@pytest.mark.parametrize("case", ARM_CASES)
@pytest.mark.parametrize("rigid", [False, True], ids=["with_drive_terms", "rigid_body"])
def test_time_derivatives_match_finite_differences_in_time(case: str, rigid: bool) -> None:
    robot = make_arm(case).robot()
    if rigid:
        robot = robot.rigid_body()
    motion = sine_motion(robot.n)
    for t0 in (0.3, 1.7):
        tau, tau_dot, tau_ddot = robot.rnea_time_derivatives(*motion(t0))
        assert tau.shape == tau_dot.shape == tau_ddot.shape == (robot.n,)
        assert relative_error(tau, robot.rnea(*motion(t0)[:3])) < EXACT_RTOL
        for h, weights, order, exact in ((3e-3, D1, 1, tau_dot), (1e-2, D2, 2, tau_ddot)):
            q, qd, qdd, _, _ = motion(t0 + h * np.arange(-4, 5))
            samples = robot.rnea(q, qd, qdd)  # (9, n): tau along the motion
            finite_difference = weights @ samples / h**order
            error = relative_error(exact, finite_difference)
            assert error < FD_RTOL, (case, order, error)


@pytest.mark.parametrize("case", ARM_CASES)
def test_first_derivative_is_the_chain_rule_of_rnea_derivatives(case: str) -> None:
    robot = make_arm(case).robot()  # drive terms: Fv in dtau/dqd, Ia in M, on both sides
    motion = sine_motion(robot.n, seed=2)
    for t0 in (0.0, 0.8, 2.5):
        q, qd, qdd, qddd, qdddd = motion(t0)
        _, tau_dot, _ = robot.rnea_time_derivatives(q, qd, qdd, qddd, qdddd)
        dtau_dq, dtau_dqd = robot.rnea_derivatives(q, qd, qdd)
        chain_rule = dtau_dq @ qd + dtau_dqd @ qdd + robot.mass_matrix(q) @ qddd
        assert relative_error(tau_dot, chain_rule) < EXACT_RTOL


def test_drive_terms_enter_as_documented() -> None:
    """With and without drive terms the derivatives differ by exactly Ia qddd + Fv qdd and
    Ia qdddd + Fv qddd (1e-12 relative)."""
    robot = make_arm("random_standard").robot()
    motion = sine_motion(robot.n, seed=3)
    q, qd, qdd, qddd, qdddd = motion(0.4)
    full = robot.rnea_time_derivatives(q, qd, qdd, qddd, qdddd)
    links = robot.rigid_body().rnea_time_derivatives(q, qd, qdd, qddd, qdddd)
    Ia, Fv, Fs = robot.Ia, robot.Fv, robot.Fs
    expected = (Ia * qdd + Fv * qd + Fs * np.sign(qd), Ia * qddd + Fv * qdd, Ia * qdddd + Fv * qddd)
    for a, b, e in zip(full, links, expected):
        assert relative_error(a - b, e) < EXACT_RTOL


def test_batch_equals_samples_one_by_one() -> None:
    robot = make_arm("lwr").robot()
    motion = sine_motion(robot.n, seed=4)
    batch = motion(np.linspace(0.0, 2.0, 25))
    tau, tau_dot, tau_ddot = robot.rnea_time_derivatives(*batch)
    assert tau.shape == tau_dot.shape == tau_ddot.shape == (25, robot.n)
    for k in (0, 11, 24):
        single = robot.rnea_time_derivatives(*(x[k] for x in batch))
        for many, one in zip((tau, tau_dot, tau_ddot), single):
            np.testing.assert_array_equal(many[k], one)


def test_bad_arguments_name_the_argument() -> None:
    robot = make_arm("random_modified").robot()
    n = robot.n
    good = [np.zeros(n)] * 5
    names = ("q", "qd", "qdd", "qddd", "qdddd")
    for k, name in enumerate(names):
        bad = list(good)
        bad[k] = np.zeros(n + 1)
        with pytest.raises(ValueError, match=rf"^{name}:"):
            robot.rnea_time_derivatives(*bad)
        bad[k] = np.full(n, np.nan)
        with pytest.raises(ValueError, match=rf"^{name}:"):
            robot.rnea_time_derivatives(*bad)
    with pytest.raises(ValueError, match=r"^qdddd:"):
        robot.rnea_time_derivatives(*good[:4], np.zeros((3, n)))
