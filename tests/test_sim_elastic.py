"""dynid.sim.simulate_elastic: the elastic-joint robot in the C++ closed-loop simulator (issue 12
item 2, partly: zero torque, a motor PD with gravity compensation and Python controllers).

- Free motion without motor friction conserves the total energy (link + motor kinetic, gravity,
  spring; ElasticRobot.energy): drift over 0.3 s below 1e-7 of the energy scale at h = 5e-5 s and
  falling at least as h^4 between h = 1e-4 and 5e-5 (RK4).
- The C++ state equation agrees with an RK4 integration written in the test on
  ElasticRobot.forward_dynamics (same step): 1e-9 relative after 0.2 s.
- The motor PD with constant gravity compensation regulates q to the set-point and theta to
  theta_d = q_d + K^-1 g(q_d) (1e-6 rad after 20 s, measured 8e-8: the wrist's link-side
  oscillation is damped only through the motors); tau_J ends at g(q_d) (1e-3 N m).
- A Python controller receives tau_J = K (theta - q) and its torque is applied (the recorded tau).
- Bad arguments: ValueError naming them.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from conftest import make_arm
from dynid.sim.elastic_joints import MotorPD, simulate_elastic
from test_elastic import rk4_free_motion


def lwr_elastic(stiffness=None, **motor) -> dynid.ElasticRobot:
    """The LWR on springs of 500-2000 N m/rad (or ``stiffness``), motors of 0.3-0.8 kg m^2."""
    if stiffness is None:
        stiffness = np.linspace(500.0, 2000.0, 7)
    return dynid.ElasticRobot(make_arm("lwr").robot(), stiffness, np.linspace(0.3, 0.8, 7), **motor)


def start(elastic, seed=31):
    rng = np.random.default_rng(seed)
    n = elastic.n
    q0 = rng.uniform(-1.0, 1.0, n)
    return q0, q0 + rng.uniform(-0.02, 0.02, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)


def test_free_motion_conserves_energy() -> None:
    elastic = lwr_elastic()
    q0, theta0, qd0, thetad0 = start(elastic)
    E0 = elastic.energy(q0, qd0, theta0, thetad0)
    scale = abs(E0) + abs(elastic.link.potential_energy(q0))
    drifts = []
    for substeps in (10, 20):  # h = 1e-4, 5e-5 s
        run = simulate_elastic(
            elastic, q0, theta0, qd0, thetad0, 0.3, None, dt=1e-3, substeps=substeps
        )
        energy = elastic.energy(run.q, run.qd, run.theta, run.thetad)
        drifts.append(np.abs(energy - E0).max() / scale)
    assert np.all(run.tau == 0.0) and run.q.shape == (301, 7)
    assert drifts[1] < 1e-7, drifts
    assert drifts[0] / drifts[1] > 16.0, drifts


def test_matches_an_rk4_of_forward_dynamics() -> None:
    elastic = lwr_elastic(motor_viscous=2.0)  # no Coulomb: tanh band vs sign would differ
    q0, theta0, qd0, thetad0 = start(elastic, 32)
    run = simulate_elastic(elastic, q0, theta0, qd0, thetad0, 0.2, None, dt=1e-3, substeps=10)
    x0 = np.concatenate([q0, theta0, qd0, thetad0])
    x1 = rk4_free_motion(elastic, x0, 1e-4, 2000, np.zeros(7))
    final = np.concatenate([run.q[-1], run.theta[-1], run.qd[-1], run.thetad[-1]])
    assert np.abs(final - x1).max() < 1e-9 * np.abs(x1).max()


def test_motor_pd_with_gravity_compensation_reaches_the_set_point() -> None:
    elastic = lwr_elastic(stiffness=5.0e3, motor_viscous=1.0)
    q_d = np.array([0.3, 0.8, -0.2, -1.0, 0.4, 0.6, 0.1])
    g_d = elastic.link.gravity(q_d)
    run = simulate_elastic(
        elastic,
        np.zeros(7),
        None,
        duration=20.0,
        controller=MotorPD(kp=400.0, kd=40.0, q_d=q_d),
        dt=1e-3,
        substeps=5,
    )
    np.testing.assert_allclose(run.q[-1], q_d, rtol=0, atol=1e-6)
    np.testing.assert_allclose(run.theta[-1], q_d + g_d / elastic.K, rtol=0, atol=1e-6)
    np.testing.assert_allclose(run.tau_J[-1], g_d, rtol=0, atol=1e-3)
    np.testing.assert_allclose(run.tau_J, elastic.K * (run.theta - run.q), rtol=1e-12, atol=1e-12)


def test_python_controller_sees_the_elastic_torque() -> None:
    elastic = lwr_elastic()
    seen = []

    def controller(t, q, qd, theta, thetad, tau_J):
        seen.append(np.abs(tau_J - elastic.K * (theta - q)).max())
        return -5.0 * thetad + 0.1 * np.sin(t)

    run = simulate_elastic(elastic, np.full(7, 0.2), duration=0.05, controller=controller)
    assert len(seen) == 51 and max(seen) < 1e-12
    np.testing.assert_allclose(
        run.tau, -5.0 * run.thetad + 0.1 * np.sin(run.t)[:, None], rtol=1e-14
    )
    # theta0=None starts at the static deflection: tau_J(0) = g(q0)
    np.testing.assert_allclose(
        run.tau_J[0], elastic.link.gravity(np.full(7, 0.2)), rtol=0, atol=1e-12 * 10
    )


def test_bad_arguments_name_the_argument() -> None:
    elastic = lwr_elastic()
    with pytest.raises(ValueError, match=r"^elastic:"):
        simulate_elastic(make_arm("lwr").robot(), np.zeros(7))
    with pytest.raises(ValueError, match=r"^q0:"):
        simulate_elastic(elastic, np.zeros(6))
    with pytest.raises(ValueError, match=r"^thetad0:"):
        simulate_elastic(elastic, np.zeros(7), thetad0=[np.nan] * 7)
    with pytest.raises(ValueError, match=r"^duration:"):
        simulate_elastic(elastic, np.zeros(7), duration=0.0105)
    with pytest.raises(ValueError, match=r"^kp:"):
        simulate_elastic(elastic, np.zeros(7), controller=MotorPD(-1.0, 1.0, np.zeros(7)))
    with pytest.raises(ValueError, match=r"^controller:"):
        simulate_elastic(elastic, np.zeros(7), controller="pd")
    with pytest.raises(ValueError, match=r"^controller:"):
        simulate_elastic(elastic, np.zeros(7), duration=0.01, controller=lambda *a: np.zeros(3))


def test_a_long_run_with_a_cpp_controller_stops_on_keyboard_interrupt() -> None:
    """Issue 22: simulate_elastic ignored Ctrl-C with its C++ controllers. Ctrl-C (here
    _thread.interrupt_main from a timer, 0.2 s in) ends a 200 s run (2*10^5 periods of 20 RK4
    substeps: a minute or more) within 5 s: the binding lets Python handle signals every 1000
    periods, as the rigid simulator does."""
    import _thread
    import signal
    import threading
    import time

    # interrupt_main does nothing while SIGINT is ignored (pytest started in the background by a
    # non-interactive shell inherits that): Python's own handler, as in an interactive session.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    elastic = lwr_elastic(motor_viscous=1.0)
    timer = threading.Timer(0.2, _thread.interrupt_main)
    begin = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            simulate_elastic(
                elastic, np.zeros(7), None, duration=200.0,
                controller=MotorPD(kp=400.0, kd=40.0, q_d=np.zeros(7)), dt=1e-3, substeps=20,
            )  # fmt: skip
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert time.perf_counter() - begin < 5.0
