"""Uniform time scaling (notes pp. 37-40) against inverse dynamics recomputed on the scaled motion.

The reference is independent of dynid.time_scaling: the scaled trajectory is written in closed
form as a function of its own time t' (q_s(t') = q(t' / k), derivatives by the chain rule done
by hand) and its torques come from robot.rnea on it; scale_torques only sees the stored torques
of the original motion.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.motion.time_scaling import scale_motion, scale_time, scale_torques

TOL = 1e-12  # relative to the largest torque: the scaling is exact, only rounding differs


def sinusoids(t: np.ndarray, w: float, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q = q0 + A sin(w t) + B cos(2 w t) per joint, with its exact derivatives in t."""
    j = np.arange(1, n + 1)
    q0, A, B = 0.1 * j - 0.3, 0.6 / j, 0.25 * (-1.0) ** j
    s1, c1 = np.sin(w * t)[:, None], np.cos(w * t)[:, None]
    s2, c2 = np.sin(2 * w * t)[:, None], np.cos(2 * w * t)[:, None]
    q = q0 + A * s1 + B * c2
    qd = A * w * c1 - 2 * B * w * s2
    qdd = -A * w**2 * s1 - 4 * B * w**2 * c2
    return q, qd, qdd


@pytest.mark.parametrize("k", [0.5, 0.8, 1.0, 2.0, 3.7])
@pytest.mark.parametrize("drives", ["with_drive_terms", "rigid_body"])
def test_scaled_torques_equal_inverse_dynamics_on_the_scaled_trajectory(k, drives):
    # KUKA LWR-IV with rotor inertias Ia (scale as 1/k^2), viscous Fv (1/k) and Coulomb Fs (not
    # scaled) friction; 1e-12 relative to max |tau_s|.
    robot = dynid.models.kuka_lwr4()
    if drives == "rigid_body":
        robot = robot.rigid_body()
    if drives == "with_drive_terms":
        assert robot.Ia.min() > 0 and robot.Fv.min() > 0 and robot.Fs.min() > 0
    w = 2.0
    t = np.linspace(0.0, 2 * np.pi / w, 301)
    q, qd, qdd = sinusoids(t, w, robot.n)
    tau, g = robot.rnea(q, qd, qdd), robot.gravity(q)

    t_scaled = scale_time(t, k)
    q_s, qd_s, qdd_s = sinusoids(t_scaled, w / k, robot.n)  # q_s(t') = q(t' / k)
    np.testing.assert_allclose(q_s, q, rtol=0, atol=1e-14)  # same path at the mapped instants
    expected = robot.rnea(q_s, qd_s, qdd_s)

    got = scale_torques(tau, g, k, qd=qd, robot=robot)
    np.testing.assert_allclose(got, expected, rtol=0, atol=TOL * np.abs(expected).max())
    np.testing.assert_allclose(
        np.stack(scale_motion(qd, qdd, k)), np.stack([qd_s, qdd_s]), rtol=0, atol=1e-13
    )
    # One sample (n,) gives the same as the trajectory's row.
    one = scale_torques(tau[7], g[7], k, qd=qd[7], robot=robot)
    np.testing.assert_allclose(one, expected[7], rtol=0, atol=TOL * np.abs(expected).max())


def test_each_drive_term_scales_as_stated():
    # Isolate each term on a 1-joint-like check: Ia qdd -> /k^2, Fv qd -> /k, Fs sign(qd) -> 1,
    # with the links massless so that tau is the drive terms alone (closed form, 1e-14).
    robot = dynid.models.kuka_lwr4()
    robot.params = np.zeros((robot.n, 10))
    robot.Ia, robot.Fv, robot.Fs = np.full(7, 0.3), np.full(7, 2.0), np.full(7, 0.7)
    qd, qdd, k = np.linspace(-1, 1, 7), np.linspace(2, -3, 7), 2.5
    q = np.zeros(7)
    tau = robot.rnea(q, qd, qdd)
    expected = 0.3 * qdd / k**2 + 2.0 * qd / k + 0.7 * np.sign(qd)
    got = scale_torques(tau, np.zeros(7), k, qd=qd, robot=robot)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14)


def test_without_friction_the_notes_formula_holds():
    # Notes p. 38: tau_s(kt) = (tau_d(t) - g(q_d(t))) / k^2 + g(q_d(t)), checked on the 2R.
    robot = dynid.models.planar_2r()
    t = np.linspace(0, 1, 11)
    q, qd, qdd = sinusoids(t, 3.0, 2)
    tau, g = robot.rnea(q, qd, qdd), robot.gravity(q)
    k = 3.0
    np.testing.assert_allclose(scale_torques(tau, g, k), (tau - g) / 9.0 + g, rtol=0, atol=1e-14)
    expected = robot.rnea(*sinusoids(scale_time(t, k), 1.0, 2))
    np.testing.assert_allclose(
        scale_torques(tau, g, k), expected, rtol=0, atol=TOL * np.abs(expected).max()
    )


# --- the notes' numerical example (pp. 39-40) ---------------------------------------------------

Q_START = np.array([-np.pi / 2, 0.0])  # hanging down: the equilibrium, zero gravity torque
Q_END = np.array([0.0, np.pi / 2])  # link 1 horizontal, link 2 pointing up


def cubic(t: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rest-to-rest cubic from Q_START to Q_END in time T, exact derivatives."""
    s = (np.asarray(t) / T)[:, None]
    delta = Q_END - Q_START
    return (
        Q_START + delta * (3 * s**2 - 2 * s**3),
        delta * (6 * s - 6 * s**2) / T,
        delta * (6 - 12 * s) / T**2,
    )


def test_notes_example_2r_slowed_from_half_a_second_to_one_second():
    # Notes pp. 39-40: a rest-to-rest cubic of the planar 2R under gravity, T = 0.5 s, scaled by
    # k = 2 to T' = 1 s; at t = 0.1 s joint 1 needs tau - g = 20 N m, at t' = 0.2 s the scaled
    # motion needs 20 / 2^2 = 5 N m, and the gravity component does not scale. The notes do not
    # give the link data: the notes' arm (planar_2r, l = 1 m, CoMs at mid-link) with equal link
    # masses m chosen so that the original value is 20 N m (tau - g is linear in the masses);
    # then the 5 N m come from robot.rnea on the slowed cubic. 1e-12 relative.
    T, k = 0.5, 2.0
    q1, qd1, qdd1 = cubic(np.array([0.1]), T)
    unit = dynid.models.planar_2r()
    per_kg = (unit.rnea(q1, qd1, qdd1) - unit.gravity(q1))[0, 0]
    robot = dynid.models.planar_2r(m1=20.0 / per_kg, m2=20.0 / per_kg)

    t = np.linspace(0.0, T, 51)  # 10 ms steps: t = 0.1 s is sample 10
    q, qd, qdd = cubic(t, T)
    tau, g = robot.rnea(q, qd, qdd), robot.gravity(q)
    assert tau[10, 0] - g[10, 0] == pytest.approx(20.0, rel=1e-12)
    assert np.abs(g[0]).max() < 1e-12  # starts at the equilibrium: zero gravity torque
    assert abs(tau[0, 0]) > 1.0  # "torque only due to non-zero initial acceleration"

    t_scaled = scale_time(t, k)
    assert t_scaled[-1] == pytest.approx(1.0, abs=1e-15)  # T' = k T = 1 s
    assert t_scaled[10] == pytest.approx(0.2, abs=1e-15)
    tau_s = scale_torques(tau, g, k)
    assert tau_s[10, 0] - g[10, 0] == pytest.approx(5.0, rel=1e-12)  # 20 / 2^2

    q_s, qd_s, qdd_s = cubic(t_scaled, k * T)  # the slowed cubic, from its own formula
    expected = robot.rnea(q_s, qd_s, qdd_s)
    np.testing.assert_allclose(tau_s, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    assert expected[10, 0] - robot.gravity(q_s[10])[0] == pytest.approx(5.0, rel=1e-12)
    # The gravity component is the same at the mapped instants (it does not scale); at the end
    # it is the torque that sustains the arm, and the cubic's final deceleration scales by 1/4.
    np.testing.assert_allclose(robot.gravity(q_s), g, rtol=0, atol=1e-14)
    assert abs(g[-1, 0]) > 1.0
    assert tau_s[-1, 0] - g[-1, 0] == pytest.approx((tau[-1, 0] - g[-1, 0]) / 4, rel=1e-12)


# --- bad input ----------------------------------------------------------------------------------


@pytest.mark.parametrize("k", [0.0, -1.0, np.nan, np.inf, -np.inf, True, "2", None, 1j, 10**400])
def test_bad_k_is_a_value_error_naming_k(k):
    tau = np.ones((3, 2))
    for call in (
        lambda: scale_torques(tau, tau, k),
        lambda: scale_time([0.0, 1.0], k),
        lambda: scale_motion(tau, tau, k),
    ):
        with pytest.raises(ValueError, match=r"^k: expected a finite time-scaling factor k > 0"):
            call()


def test_bad_arrays_are_value_errors_naming_the_argument():
    robot = dynid.models.planar_2r()
    tau = np.ones((4, 2))
    with pytest.raises(ValueError, match=r"^tau_gravity: expected the shape of tau"):
        scale_torques(tau, np.ones((4, 3)), 2.0)
    with pytest.raises(ValueError, match=r"^tau: contains|^tau: non-finite"):
        scale_torques(np.full((4, 2), np.nan), tau, 2.0)
    with pytest.raises(ValueError, match=r"^tau: expected shape"):
        scale_torques(np.ones((2, 2, 2)), np.ones((2, 2, 2)), 2.0)
    with pytest.raises(ValueError, match=r"^qd: the original velocities"):
        scale_torques(tau, tau, 2.0, robot=robot)
    with pytest.raises(ValueError, match=r"^qd: expected the shape of tau"):
        scale_torques(tau, tau, 2.0, qd=np.ones((3, 2)), robot=robot)
    with pytest.raises(ValueError, match=r"^robot: qd was given"):
        scale_torques(tau, tau, 2.0, qd=tau)
    with pytest.raises(ValueError, match=r"^robot: expected a dynid.Robot"):
        scale_torques(tau, tau, 2.0, qd=tau, robot="2R")
    with pytest.raises(ValueError, match=r"^tau: expected 2 joints"):
        scale_torques(np.ones((4, 3)), np.ones((4, 3)), 2.0, qd=np.ones((4, 3)), robot=robot)
    with pytest.raises(ValueError, match=r"^qdd: expected the shape of qd"):
        scale_motion(np.ones((3, 2)), np.ones((3, 3)), 2.0)
    with pytest.raises(ValueError, match=r"^t: expected real numbers"):
        scale_time(["a", "b"], 2.0)


# --- the slowest scaling needed for torque limits -----------------------------------------------


@pytest.mark.parametrize("drives", ["with_drive_terms", "rigid_body"])
def test_scaling_for_torque_limits_reaches_the_limit_exactly(drives):
    # Independent check by brute force on scale_torques' output (itself checked against rnea
    # above): at the returned k the largest |tau| / tau_max is 1 (1e-10), a 1e-6 faster motion
    # violates it, and every slower one on a grid up to 100 k respects it.
    from dynid.motion.time_scaling import scaling_for_torque_limits

    robot = dynid.models.kuka_lwr4()
    if drives == "rigid_body":
        robot = robot.rigid_body()
    t = np.linspace(0.0, 2 * np.pi / 3.0, 400)
    q, qd, qdd = sinusoids(t, 3.0, robot.n)
    tau, g = robot.rnea(q, qd, qdd), robot.gravity(q)
    tau_max = np.array([176.0, 176.0, 100.0, 100.0, 100.0, 38.0, 38.0]) / 4
    k = scaling_for_torque_limits(tau, g, tau_max, qd=qd, robot=robot)

    def ratio(k_: float) -> float:
        return float((np.abs(scale_torques(tau, g, k_, qd=qd, robot=robot)) / tau_max).max())

    assert ratio(1.0) > 1.0  # the original motion violates the limits: k > 1 needed
    assert ratio(k) == pytest.approx(1.0, abs=1e-10)
    assert ratio(k * (1 - 1e-6)) > 1.0
    assert all(ratio(x) <= 1.0 + 1e-12 for x in k * np.geomspace(1.0, 100.0, 200))


def test_scaling_for_torque_limits_on_the_notes_example_and_bad_limits():
    # The notes' 2R cubic (p. 39), frictionless: (tau - g) / k^2 + g within the limits, a
    # closed form per sample: k^2 = max (tau - g) / (+-limit - g) over the samples where the
    # limit is approached. With a 10 N m limit on joint 1 (and a loose one on joint 2) this is
    # checked against that formula (1e-12); a limit below the final gravity torque is refused.
    from dynid.motion.time_scaling import scaling_for_torque_limits

    robot = dynid.models.planar_2r(m1=0.26, m2=0.26)
    t = np.linspace(0.0, 0.5, 501)
    q, qd, qdd = cubic(t, 0.5)
    tau, g = robot.rnea(q, qd, qdd), robot.gravity(q)
    limits = np.array([10.0, 1e3])
    dyn = tau - g
    bound = np.where(dyn > 0, limits - g, -limits - g)  # the side the dynamic part pushes to
    expected = np.sqrt((dyn / bound).max())
    assert scaling_for_torque_limits(tau, g, limits) == pytest.approx(expected, rel=1e-12)
    assert scaling_for_torque_limits(tau, g, 1e4) < 1.0  # loose limits: may speed up
    with pytest.raises(ValueError, match=r"^tau_max: the gravity .* no time scaling"):
        scaling_for_torque_limits(tau, g, [0.5, 1e3])
    with pytest.raises(ValueError, match=r"^tau_max: expected a positive limit per joint"):
        scaling_for_torque_limits(tau, g, [1.0, 0.0])
    with pytest.raises(ValueError, match=r"^tau_max: expected a positive limit per joint"):
        scaling_for_torque_limits(tau, g, [1.0, 2.0, 3.0])


def test_extreme_factors_do_not_overflow():
    # k = 1e200: k^2 overflows a float; the result is the gravity torque (exact), and k = 1e-100
    # multiplies the dynamic part by 1e200 (finite here).
    tau, g = np.array([[3.0, -2.0]]), np.array([[1.0, 0.5]])
    np.testing.assert_array_equal(scale_torques(tau, g, 1e200), g)
    np.testing.assert_allclose(scale_torques(tau, g, 1e-100), (tau - g) * 1e200 + g, rtol=1e-15)
    np.testing.assert_array_equal(scale_motion(tau, tau, 1e200)[1], np.zeros((1, 2)))
    with pytest.raises(ValueError, match=r"^k: k t overflows"):
        scale_time([0.0, 1e10], 1e300)
    with pytest.raises(ValueError, match=r"^k: the scaled values overflow"):
        scale_torques(tau, g, 1e-200)
    with pytest.raises(ValueError, match=r"^k: the scaled values overflow"):
        scale_motion(tau, tau, 1e-200)
