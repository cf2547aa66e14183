"""dynid.ElasticRobot: Spong's elastic-joint model (issue 12 items 1 and 3; paper eqs. (1)-(3),
notes p. 16), against independent computations on every reference arm (the LWR, both DH
conventions, prismatic joints; the arms' own Ia, Fv, Fs are set and must be ignored):

- inverse -> forward round trip: the (theta, tau) of ``inverse_dynamics`` for an analytic link
  motion, fed with thetad to ``forward_dynamics``, give back qdd and thetadd (1e-10 relative);
  the forward dynamics' output satisfies the link and motor equations checked with ``rnea`` of
  the rigid body (1e-10);
- theta(t) of ``inverse_dynamics`` differentiated IN TIME by 8th-order central differences equals
  ``motor_motion``'s thetad and thetadd (1e-8 relative): the exact jerk/snap derivatives enter
  correctly;
- the elastic torque K (theta - q) of the flat output equals the rigid body's rnea (the link
  equation, 1e-12);
- the rigid limit K -> inf: theta -> q and tau -> the rigid robot's rnea with Ia = B, Fv = Fv_m,
  Fs = Fs_m; the gap is B K^-1 tau_l'' + Fv_m K^-1 tau_l' exactly, so it falls as 1/K (ratio 10
  per decade within 1e-3) and is below 1e-6 relative at K = 1e8;
- energy (item 3 of the brief): along free motion (tau = 0, no motor friction) the total energy
  link kinetic + motor kinetic + gravity + spring is conserved by a fixed-step RK4 integration of
  ``forward_dynamics`` written in the test (relative drift < 1e-7 over 0.3 s at h = 5e-5 s,
  falling at least as h^4); with a constant motor torque and motor viscous friction the energy
  change equals the work int thetad^T (tau - Fv_m thetad) dt integrated alongside (1e-7
  relative);
- batches equal samples one by one; bad input raises ValueError naming the argument.
"""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import numpy as np
import pytest

import dynid
from conftest import ARM_CASES, make_arm
from test_rnea_time_derivatives import D1, D2, relative_error, sine_motion

REPO = Path(__file__).resolve().parents[1]
ROUND_TRIP_RTOL = 1e-10


def elastic_arm(case: str, stiffness: float | np.ndarray = 2.0e3) -> dynid.ElasticRobot:
    robot = make_arm(case).robot()  # with Ia, Fv, Fs: ElasticRobot must use its rigid body only
    n = robot.n
    rng = np.random.default_rng(7)
    return dynid.ElasticRobot(
        robot,
        stiffness * rng.uniform(0.5, 2.0, n),
        rng.uniform(0.2, 1.0, n),
        rng.uniform(0.5, 3.0, n),
        rng.uniform(0.1, 1.0, n),
    )


@pytest.mark.parametrize("case", ARM_CASES)
def test_inverse_then_forward_dynamics_round_trip(case: str) -> None:
    elastic = elastic_arm(case)
    motion = sine_motion(elastic.n, seed=5)
    q, qd, qdd, qddd, qdddd = motion(np.linspace(0.0, 3.0, 40))
    theta, tau = elastic.inverse_dynamics(q, qd, qdd, qddd, qdddd)
    theta2, thetad, thetadd = elastic.motor_motion(q, qd, qdd, qddd, qdddd)
    np.testing.assert_array_equal(theta, theta2)
    qdd_back, thetadd_back = elastic.forward_dynamics(q, qd, theta, thetad, tau)
    assert relative_error(qdd_back, qdd) < ROUND_TRIP_RTOL
    assert relative_error(thetadd_back, thetadd) < ROUND_TRIP_RTOL


@pytest.mark.parametrize("case", ARM_CASES)
def test_forward_dynamics_satisfies_link_and_motor_equations(case: str) -> None:
    elastic = elastic_arm(case)
    rng = np.random.default_rng(8)
    n, T = elastic.n, 30
    q = rng.uniform(-1.0, 1.0, (T, n))
    qd, thetad = rng.uniform(-2.0, 2.0, (T, n)), rng.uniform(-2.0, 2.0, (T, n))
    theta = q + rng.uniform(-0.05, 0.05, (T, n))
    tau = rng.uniform(-50.0, 50.0, (T, n))
    qdd, thetadd = elastic.forward_dynamics(q, qd, theta, thetad, tau)
    tau_J = elastic.K * (theta - q)
    links = make_arm(case).robot().rigid_body()  # built afresh: the link equation, paper eq. (1)
    assert relative_error(links.rnea(q, qd, qdd), tau_J) < ROUND_TRIP_RTOL
    motor = elastic.B * thetadd + tau_J + elastic.Fv_m * thetad + elastic.Fs_m * np.sign(thetad)
    assert relative_error(motor, tau) < ROUND_TRIP_RTOL  # the motor equation, paper eq. (2)
    for k in (0, T - 1):
        one = elastic.forward_dynamics(q[k], qd[k], theta[k], thetad[k], tau[k])
        np.testing.assert_allclose(one[0], qdd[k], rtol=0, atol=1e-12 * np.abs(qdd).max())
        np.testing.assert_array_equal(one[1], thetadd[k])


@pytest.mark.parametrize("case", ARM_CASES)
def test_motor_motion_is_the_time_derivative_of_theta(case: str) -> None:
    elastic = elastic_arm(case)
    motion = sine_motion(elastic.n, seed=6)
    t0 = 0.9
    _, thetad, thetadd = elastic.motor_motion(*motion(t0))
    for h, weights, order, exact in ((3e-3, D1, 1, thetad), (1e-2, D2, 2, thetadd)):
        theta_samples, _ = elastic.inverse_dynamics(*motion(t0 + h * np.arange(-4, 5)))
        assert relative_error(exact, weights @ theta_samples / h**order) < 1e-8


@pytest.mark.parametrize("case", ARM_CASES)
def test_elastic_torque_of_the_flat_output_is_the_link_torque(case: str) -> None:
    elastic = elastic_arm(case)
    q, qd, qdd, qddd, qdddd = sine_motion(elastic.n, seed=9)(np.linspace(0.0, 2.0, 15))
    theta, _ = elastic.inverse_dynamics(q, qd, qdd, qddd, qdddd)
    links = make_arm(case).robot().rigid_body()
    assert relative_error(elastic.elastic_torque(q, theta), links.rnea(q, qd, qdd)) < 1e-12


@pytest.mark.parametrize("case", ARM_CASES)
def test_rigid_limit(case: str) -> None:
    """K -> inf: theta -> q and tau -> rnea of the rigid robot with Ia = B, Fv = Fv_m, Fs = Fs_m."""
    robot = make_arm(case).robot()
    n = robot.n
    rng = np.random.default_rng(10)
    B, Fv_m, Fs_m = rng.uniform(0.2, 1.0, n), rng.uniform(0.5, 3.0, n), rng.uniform(0.1, 1.0, n)
    rigid = robot.rigid_body()
    rigid.Ia, rigid.Fv, rigid.Fs = B, Fv_m, Fs_m
    motion = sine_motion(n, seed=11)
    q, qd, qdd, qddd, qdddd = motion(np.linspace(0.05, 2.0, 20))
    tau_rigid = rigid.rnea(q, qd, qdd)
    gaps, deflections = [], []
    for K in (1e6, 1e7, 1e8):
        theta, tau = dynid.ElasticRobot(robot, K, B, Fv_m, Fs_m).inverse_dynamics(
            q, qd, qdd, qddd, qdddd
        )
        gaps.append(np.abs(tau - tau_rigid).max() / np.abs(tau_rigid).max())
        deflections.append(np.abs(theta - q).max())
    assert gaps[-1] < 1e-6 and deflections[-1] < 1e-5
    for coarse, fine in zip(gaps, gaps[1:]):
        assert abs(coarse / fine - 10.0) < 1e-2, gaps  # O(1/K): B K^-1 tau_l'' + Fv_m K^-1 tau_l'
    for coarse, fine in zip(deflections, deflections[1:]):
        assert abs(coarse / fine - 10.0) < 1e-6, deflections  # exactly K^-1 tau_l


# ------------------------------------------------------------------------- energy


def rk4_free_motion(elastic, x, h, steps, tau, work=False):
    """Fixed-step RK4 of x = (q, theta, qd, thetad[, W]) under a constant motor torque tau;
    with ``work``, W integrates the input power thetad^T (tau - Fv_m thetad) (a test-only loop
    over time steps: the product API's simulator is C++)."""
    n = elastic.n

    def rate(x):
        q, theta, qd, thetad = x[:n], x[n : 2 * n], x[2 * n : 3 * n], x[3 * n : 4 * n]
        qdd, thetadd = elastic.forward_dynamics(q, qd, theta, thetad, tau)
        out = [qd, thetad, qdd, thetadd]
        if work:
            out.append([thetad @ (tau - elastic.Fv_m * thetad)])
        return np.concatenate(out)

    for _ in range(steps):
        k1 = rate(x)
        k2 = rate(x + 0.5 * h * k1)
        k3 = rate(x + 0.5 * h * k2)
        k4 = rate(x + h * k3)
        x = x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


def initial_state(elastic, seed):
    rng = np.random.default_rng(seed)
    n = elastic.n
    q = rng.uniform(-1.0, 1.0, n)
    return np.concatenate(
        [q, q + rng.uniform(-0.02, 0.02, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)]
    )


def energy_of(elastic, x):
    n = elastic.n
    return elastic.energy(x[:n], x[2 * n : 3 * n], x[n : 2 * n], x[3 * n : 4 * n])


@pytest.mark.parametrize("case", ["lwr", "random_modified"])
def test_energy_is_conserved_in_free_motion(case: str) -> None:
    """RK4's energy error over 0.3 s falls with the step at least as h^4 (measured: ~h^5, the
    LWR's light wrist on springs of 500-2000 N m/rad oscillates at ~1000 rad/s) and is below
    1e-7 of the energy's scale at h = 5e-5 s: a wrong term in the model would leave a drift
    that does not vanish with h."""
    robot = make_arm(case).robot()
    n = robot.n
    elastic = dynid.ElasticRobot(robot, np.linspace(500.0, 2000.0, n), np.linspace(0.3, 0.8, n))
    x0 = initial_state(elastic, 12)
    E0 = energy_of(elastic, x0)
    # scale: kinetic + spring + |gravity| so that the zero of U_g does not matter
    scale = abs(E0) + abs(robot.rigid_body().potential_energy(x0[:n]))
    drifts = []
    for h in (1e-4, 5e-5):
        x1 = rk4_free_motion(elastic, x0, h, round(0.3 / h), np.zeros(n))
        drifts.append(abs(energy_of(elastic, x1) - E0) / scale)
    assert np.abs(x1[n : 2 * n] - x0[n : 2 * n]).max() > 1e-3  # the motors did move
    assert drifts[1] < 1e-7, drifts
    assert drifts[0] / drifts[1] > 16.0 or drifts[0] < 1e-12, drifts


def test_energy_change_equals_the_work_of_the_motor_torque() -> None:
    """dE/dt = thetad^T (tau - Fv_m thetad): the energy change over 0.3 s equals the work
    integrated alongside by the same RK4 (h = 5e-5 s), 1e-7 relative (measured 5e-9)."""
    robot = make_arm("lwr").robot()
    n = robot.n
    elastic = dynid.ElasticRobot(robot, 1.0e3, 0.5, motor_viscous=2.0)
    x0 = np.concatenate([initial_state(elastic, 13), [0.0]])
    tau = np.linspace(-5.0, 5.0, n)
    x1 = rk4_free_motion(elastic, x0, 5e-5, 6000, tau, work=True)
    change = energy_of(elastic, x1[:-1]) - energy_of(elastic, x0[:-1])
    assert abs(change) > 1.0  # the torque did work
    assert abs(change - x1[-1]) < 1e-7 * abs(change), (change, x1[-1])


def test_energy_terms() -> None:
    """energy = kinetic_energy + potential_energy of the links + 1/2 thetad^T B thetad +
    1/2 (theta - q)^T K (theta - q), batch and single (1e-12)."""
    robot = make_arm("random_standard").robot()
    elastic = dynid.ElasticRobot(robot, 3.0e3, 0.4)
    rng = np.random.default_rng(14)
    q, qd, theta, thetad = (rng.uniform(-1, 1, (5, robot.n)) for _ in range(4))
    links = robot.rigid_body()
    expected = (
        links.kinetic_energy(q, qd)
        + links.potential_energy(q)
        + 0.5 * 0.4 * np.sum(thetad**2, axis=1)
        + 0.5 * 3.0e3 * np.sum((theta - q) ** 2, axis=1)
    )
    np.testing.assert_allclose(elastic.energy(q, qd, theta, thetad), expected, rtol=1e-12)
    assert isinstance(elastic.energy(q[0], qd[0], theta[0], thetad[0]), float)


# ------------------------------------------------------------------------- input checks


def test_bad_arguments_name_the_argument() -> None:
    robot = make_arm("random_modified").robot()
    n = robot.n
    with pytest.raises(ValueError, match=r"^robot:"):
        dynid.ElasticRobot("arm", 1.0, 1.0)
    with pytest.raises(ValueError, match=r"^stiffness:"):
        dynid.ElasticRobot(robot, np.ones(n + 1), 1.0)
    with pytest.raises(ValueError, match=r"^stiffness:"):
        dynid.ElasticRobot(robot, 0.0, 1.0)
    with pytest.raises(ValueError, match=r"^motor_inertia:"):
        dynid.ElasticRobot(robot, 1.0, -1.0)
    with pytest.raises(ValueError, match=r"^motor_viscous:"):
        dynid.ElasticRobot(robot, 1.0, 1.0, motor_viscous=np.nan)
    with pytest.raises(ValueError, match=r"^motor_coulomb:"):
        dynid.ElasticRobot(robot, 1.0, 1.0, motor_coulomb=-1.0)
    elastic = dynid.ElasticRobot(robot, 1.0e3, 1.0)
    z = np.zeros(n)
    with pytest.raises(ValueError, match=r"^theta:"):
        elastic.forward_dynamics(z, z, np.zeros(n + 1), z, z)
    with pytest.raises(ValueError, match=r"^tau:"):
        elastic.forward_dynamics(z, z, z, z, np.zeros((2, n)))
    with pytest.raises(ValueError, match=r"^thetad:"):
        elastic.forward_dynamics(z, z, z, [np.nan] * n, z)
    with pytest.raises(ValueError, match=r"^qddd:"):
        elastic.inverse_dynamics(z, z, z, np.zeros(n - 1), z)
    with pytest.raises(ValueError, match=r"^q:"):
        elastic.elastic_torque(np.zeros((2, n + 1)), z)
    with pytest.raises(ValueError, match="read-only"):
        elastic.K[0] = 5.0


def test_robot_drive_terms_are_not_used_on_the_link_side() -> None:
    robot = make_arm("lwr").robot()
    assert np.any(robot.Ia > 0) and np.any(robot.Fv > 0)
    elastic = dynid.ElasticRobot(robot, 1.0e3, 0.5)
    assert (
        np.all(elastic.link.Ia == 0)
        and np.all(elastic.link.Fv == 0)
        and np.all(elastic.link.Fs == 0)
    )
    other = dynid.ElasticRobot(robot.rigid_body(), 1.0e3, 0.5)
    q, qd, qdd, qddd, qdddd = sine_motion(robot.n, seed=15)(0.5)
    for a, b in zip(
        elastic.inverse_dynamics(q, qd, qdd, qddd, qdddd),
        other.inverse_dynamics(q, qd, qdd, qddd, qdddd),
    ):
        np.testing.assert_array_equal(a, b)


def test_the_documented_example_runs() -> None:
    """docs/elastic.md's example runs and prints what the page quotes."""
    text = (REPO / "docs" / "elastic.md").read_text(encoding="utf-8")
    code = re.findall(r"^```python\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL)[-1]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "docs/elastic.md", "exec"), {"__name__": "__docs__"})
    printed = out.getvalue()
    assert printed.startswith("max deflection 4.2e-03 rad, round trip error "), printed
    assert float(printed.split()[-1]) < 1e-9, printed


# ------------------------------------------------------------------------- real time


def test_no_heap_allocation_per_call(cpp_tests):
    """Runs tests/cpp/test_elastic_no_allocation.cpp (built against the installed package): it
    counts every operator new and malloc during 10^4 rnea_time_derivatives calls and during
    elastic simulator runs under MotorPD and the KUKA-like controller, checks tau against rnea,
    and that size errors name the argument."""
    output = cpp_tests.run("elastic_no_allocation")
    assert re.search(r"^allocations_during_calls=0$", output, re.MULTILINE), output
    print(output)
