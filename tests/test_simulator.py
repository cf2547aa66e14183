"""Closed-loop simulation (dynid.sim.simulate; docs/uses.md, "Closed-loop simulation", issue 11 item
4).

Independent references: the total energy T + U from the link velocities and positions
(kinetic_energy / potential_energy, not from M or g) for conservation; a reference run with a
256x smaller step for the convergence orders; the Lyapunov function V = T + 1/2 e^T Kp e of PD +
gravity compensation; the closed form of the computed-torque error dynamics (error -> 0 with the
control period) and of the zero-order hold; Newton-Euler (rnea) plus the plant's friction for the
applied torque (the simulator solves M qdd = ... by CRBA and Cholesky); a NumPy PD law for the
built-in one; the encoder's quantisation formula; the C++ no-allocation proof.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.sim import (
    PD,
    ComputedTorque,
    PDGravity,
    paper_validation_trajectory,
    plant_friction,
    simulate,
)

REPO = Path(__file__).resolve().parents[1]
Q0 = np.full(7, 0.3)
QD0 = np.array([0.5, -0.4, 0.8, 1.0, -0.6, 0.3, 0.2])
KP = np.array([400.0, 800.0, 300.0, 400.0, 100.0, 100.0, 50.0])
KD = np.array([40.0, 80.0, 30.0, 40.0, 10.0, 10.0, 5.0])


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    return dynid.models.kuka_lwr4()


def frictionless(robot: dynid.Robot) -> dynid.Robot:
    """The robot with its rotor inertias but without friction."""
    other = robot.copy()
    other.Fv = other.Fs = np.zeros(robot.n)
    return other


def energy(robot: dynid.Robot, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    return robot.kinetic_energy(q, qd) + robot.potential_energy(q)


def eq33(t: np.ndarray):
    return paper_validation_trajectory(t, 7)


# --- integration: energy and convergence order ---------------------------------------------------


def test_rk4_conserves_energy_without_friction_and_torque(lwr):
    # 7-dof LWR (rotor inertias included), free motion under gravity for 1 s, h = 1e-4:
    # |E(t) - E(0)| < 1e-9 of the largest kinetic energy (measured 3.6e-11).
    run = simulate(lwr, Q0, QD0, 1.0, None, dt=1e-4, friction=False)
    assert run.q.shape == (10001, 7) and run.t[-1] == pytest.approx(1.0, abs=1e-12)
    kinetic = lwr.kinetic_energy(run.q, run.qd)
    assert kinetic.max() > 10.0  # the arm falls and swings: a real test
    drift = np.abs(energy(lwr, run.q, run.qd) - energy(lwr, Q0, QD0))
    assert drift.max() < 1e-9 * kinetic.max()
    np.testing.assert_array_equal(run.tau, 0.0)


def pendulum() -> dynid.Robot:
    """One revolute link of 2 kg in a vertical plane (M constant: a separable Hamiltonian)."""
    robot = dynid.Robot.from_dh([[0.5, 0.0, 0.0, 0.0]], "R", gravity=(0.0, -9.81, 0.0))
    params = np.zeros(10)
    params[[0, 1, 4, 7, 9]] = [2.0, 0.5, 0.01, 0.6, 0.6]
    robot.params = params
    return robot


def test_semi_implicit_euler_energy_error_is_bounded_on_a_pendulum():
    # With a constant M, semi-implicit Euler is symplectic: the energy error oscillates with a
    # bounded amplitude, the same in every tenth of a 100 s run (measured 0.0323 J each; bound:
    # within 1 % of the first tenth's), proportional to h (h / 2: ratio 2 +- 2 %), 0.12 % of T_max.
    robot = pendulum()
    amplitudes = []
    for dt in (1e-3, 5e-4):
        run = simulate(robot, [1.0], None, 100.0, None, dt=dt, method="euler")
        error = np.abs(energy(robot, run.q, run.qd) - energy(robot, run.q[0], run.qd[0]))
        tenths = error[1:].reshape(10, -1).max(axis=1)
        np.testing.assert_allclose(tenths, tenths[0], rtol=0.01)
        assert tenths[0] < 2e-3 * robot.kinetic_energy(run.q, run.qd).max()
        amplitudes.append(tenths[0])
    assert amplitudes[0] / amplitudes[1] == pytest.approx(2.0, rel=0.02)


def test_semi_implicit_euler_energy_error_on_the_arm_is_first_order(lwr):
    # On the 7-dof arm M depends on q and the velocity-first Euler is no longer exactly
    # symplectic: over 1 s the energy error is 3e-4 of T_max at h = 1e-4 (bound 1e-3) and halves
    # with h (measured 2.003, 2.002, 2.001; bound 2 +- 3 %). Over 30 s it grows slowly
    # (measured: 1.7 J, 1.6 % of T_max, at h = 1e-4) where RK4 stays at 1e-10 J.
    errors = []
    for substeps in (1, 2, 4, 8):
        run = simulate(
            lwr, Q0, QD0, 1.0, None, dt=8e-4, substeps=8 * substeps, friction=False, method="euler"
        )
        errors.append(np.abs(energy(lwr, run.q, run.qd) - energy(lwr, Q0, QD0)).max())
        if substeps == 1:
            assert errors[0] < 1e-3 * lwr.kinetic_energy(run.q, run.qd).max()
    np.testing.assert_allclose(np.array(errors[:-1]) / np.array(errors[1:]), 2.0, rtol=0.03)


@pytest.mark.parametrize(
    ("method", "substeps", "order"),
    [("rk4", (2, 4, 8, 16), 16.0), ("euler", (64, 128, 256, 512), 2.0)],
)
def test_convergence_order_free_motion(lwr, method, substeps, order):
    # Free motion for 0.5 s with control period 10 ms; errors of (q, qd) at the control instants
    # against a run with 1024 RK4 steps per period (error ~1e-16). Halving h divides the error by
    # 2^4 = 16 (RK4; measured 16.05, 16.03, 16.00) or 2 (Euler; measured 2.0002..2.00006):
    # within 6 % (RK4) and 1 % (Euler).
    reference = simulate(lwr, Q0, QD0, 0.5, None, dt=1e-2, substeps=1024, friction=False)
    exact = np.c_[reference.q, reference.qd]
    errors = []
    for k in substeps:
        run = simulate(lwr, Q0, QD0, 0.5, None, dt=1e-2, substeps=k, method=method, friction=False)
        errors.append(np.abs(np.c_[run.q, run.qd] - exact).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    tolerance = 0.06 if method == "rk4" else 0.01
    np.testing.assert_allclose(ratios, order, rtol=tolerance)


def test_rk4_order_holds_under_a_held_controller_torque(lwr):
    # PD + gravity compensation at 1 kHz: the torque is constant over each period, so the
    # substeps integrate a smooth ODE and RK4 keeps order 4 (measured ratios 15.997, 15.999,
    # 16.000), against 256 substeps; within 6 %. (With friction the tanh band's high derivatives,
    # ~Fs / band^4, delay the asymptotic regime to much smaller steps.)
    law = PDGravity(lwr, KP, KD, np.zeros(7))
    options = {"dt": 1e-3, "friction": False}
    reference = simulate(lwr, Q0, QD0, 0.5, law, substeps=256, **options)
    errors = [
        np.abs(simulate(lwr, Q0, QD0, 0.5, law, substeps=k, **options).q - reference.q).max()
        for k in (1, 2, 4, 8)
    ]
    np.testing.assert_allclose(np.array(errors[:-1]) / np.array(errors[1:]), 16.0, rtol=0.06)


# --- controllers ---------------------------------------------------------------------------------


def lyapunov(robot, run, q_d, kp):
    e = q_d - run.q
    return robot.kinetic_energy(run.q, run.qd) + 0.5 * np.einsum("ti,i,ti->t", e, kp, e)


def test_pd_gravity_converges_to_the_setpoint_and_v_decreases(lwr):
    # Takegaki-Arimoto: with the exact gravity model, dV/dt = -qd^T Kd qd <= 0 and q -> q_d.
    # The zero-order hold at 1 kHz lets V rise by at most 1e-6 V(0) per period (measured 7e-8);
    # after 4 s the error is below 1e-10 rad (measured 2e-14).
    q_d = np.array([0.5, -0.4, 0.8, 1.0, -0.6, 0.3, 0.2])
    plant = frictionless(lwr)
    run = simulate(plant, Q0, None, 4.0, PDGravity(plant, KP, KD, q_d), substeps=2)
    V = lyapunov(plant, run, q_d, KP)
    assert np.diff(V).max() <= 1e-6 * V[0]
    assert np.abs(run.q[-1] - q_d).max() < 1e-10
    assert np.abs(run.qd[-1]).max() < 1e-9


def test_pd_gravity_converges_with_friction(lwr):
    # Friction only dissipates (qd^T F(qd) >= 0), so V decreases strictly even with the zero-order
    # hold (measured max dV = -9e-18; bound 1e-12 V(0)), and q -> q_d: below 1e-6 rad after 8 s
    # with a 0.01 rad/s Coulomb band (measured 7e-9). Near rest the smoothed Coulomb term acts as a
    # viscous Fs / band, so the final approach is slower than without friction (after 1 s:
    # more than 1e-4 rad left, against 2e-4 .. 1e-10 without friction at 1 s .. 4 s).
    q_d = np.array([0.5, -0.4, 0.8, 1.0, -0.6, 0.3, 0.2])
    run = simulate(lwr, Q0, None, 8.0, PDGravity(lwr, KP, KD, q_d), substeps=2, coulomb_band=0.01)
    V = lyapunov(lwr, run, q_d, KP)
    assert np.diff(V).max() <= 1e-12 * V[0]
    assert np.abs(run.q[-1] - q_d).max() < 1e-6
    assert np.abs(run.q[1000] - q_d).max() > 1e-4


def test_computed_torque_with_the_exact_model_tracks_to_the_hold_error(lwr):
    # Eq. (33) from its start, exact model, no friction: the error dynamics edd + Kd ed + Kp e = 0
    # are driven only by the zero-order hold of the torque, an O(dt) disturbance: max error
    # 1.05e-4 rad at 1 kHz (bound 2e-4), halving with dt (measured 1.993; bound 2 +- 5 %).
    plant = frictionless(lwr)
    law = ComputedTorque(plant, 100.0, 20.0, eq33)
    q_start = eq33(np.zeros(1))[0][0]
    errors = []
    for dt in (2e-3, 1e-3):
        run = simulate(plant, q_start, None, 3.0, law, dt=dt, friction=False)
        errors.append(np.abs(eq33(run.t)[0] - run.q).max())
    assert errors[1] < 2e-4
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=0.05)


def test_computed_torque_with_a_model_mismatch_shows_a_tracking_error(lwr):
    # Controller model with all link parameters 10 % too large: the residual M~ qdd + ... acts
    # as a persistent disturbance, 0.018 rad max at 1 kHz (bound > 0.01), and does not vanish
    # with the control period (ratio 2 ms / 1 ms within 1 +- 1 %), unlike the exact model.
    plant = frictionless(lwr)
    wrong = plant.copy()
    wrong.params = 1.1 * plant.params
    law = ComputedTorque(wrong, 100.0, 20.0, eq33)
    q_start = eq33(np.zeros(1))[0][0]
    errors = []
    for dt in (2e-3, 1e-3):
        run = simulate(plant, q_start, None, 3.0, law, dt=dt, friction=False)
        errors.append(np.abs(eq33(run.t)[0] - run.q).max())
    assert errors[1] > 0.01
    assert errors[0] / errors[1] == pytest.approx(1.0, rel=0.01)


def test_python_controller_equals_the_builtin_pd(lwr):
    # The same PD law written in NumPy and called once per period gives the same run (1e-12).
    dt = 1e-3
    t = np.arange(1001) * dt
    q_d, qd_d, _ = eq33(t)
    calls = []

    def pd(time, q, qd):
        k = round(time / dt)
        calls.append(time)
        return KP * (q_d[k] - q) + KD * (qd_d[k] - qd)

    builtin = simulate(lwr, Q0, QD0, 1.0, PD(KP, KD, eq33), substeps=2)
    python = simulate(lwr, Q0, QD0, 1.0, pd, substeps=2)
    assert len(calls) == 1001  # once per control instant, t = 0 .. 1 s
    np.testing.assert_allclose(calls, t, rtol=0, atol=1e-12)
    for a, b in ((builtin.q, python.q), (builtin.qd, python.qd), (builtin.tau, python.tau)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.abs(a).max())


def test_reference_arrays_and_callable_give_the_same_run(lwr):
    t = np.arange(501) * 1e-3
    as_arrays = simulate(lwr, Q0, None, 0.5, PDGravity(lwr, KP, KD, eq33(t)))
    as_callable = simulate(lwr, Q0, None, 0.5, PDGravity(lwr, KP, KD, eq33))
    np.testing.assert_array_equal(as_arrays.q, as_callable.q)


# --- sensors and noise ---------------------------------------------------------------------------


def test_applied_torque_is_the_plant_equation_and_noise_is_seeded(lwr):
    # tau_applied = M qdd + c + g + F(qd) by Newton-Euler of the frictionless robot plus the
    # plant's friction (the simulator solves the same equation by CRBA + Cholesky). Without noise
    # it equals the command (1e-9 relative); with torque_noise = 0.05 the difference is white
    # noise of std 0.05 (7 x 2000 draws: within 3 %) and mean 0 (5 sigma), reproducible with the
    # seed and different with another seed.
    plant = frictionless(lwr)
    law = PDGravity(lwr, KP, KD, eq33)

    def applied(run):
        return plant.rnea(run.q, run.qd, run.qdd) + plant_friction(lwr, run.qd, 1e-3)

    clean = simulate(lwr, Q0, QD0, 2.0, law)
    np.testing.assert_allclose(
        applied(clean), clean.tau, rtol=0, atol=1e-9 * np.abs(clean.tau).max()
    )
    noisy = simulate(lwr, Q0, QD0, 2.0, law, torque_noise=0.05, seed=3)
    noise = applied(noisy) - noisy.tau
    assert np.std(noise) == pytest.approx(0.05, rel=0.03)
    assert abs(np.mean(noise)) < 5 * 0.05 / np.sqrt(noise.size)
    assert abs(np.corrcoef(noise[:-1, 0], noise[1:, 0])[0, 1]) < 0.1  # white
    assert np.abs(noisy.q - clean.q).max() > 1e-6  # the noise moves the robot
    again = simulate(lwr, Q0, QD0, 2.0, law, torque_noise=0.05, seed=3)
    other = simulate(lwr, Q0, QD0, 2.0, law, torque_noise=0.05, seed=4)
    np.testing.assert_array_equal(again.q, noisy.q)
    assert np.abs(other.q - noisy.q).max() > 1e-6


def test_encoder_quantises_what_the_controller_sees(lwr):
    # 4096 counts per revolution: the controller gets delta * round(q / delta), delta = 2 pi /
    # 4096 (exact), within delta / 2 of q, and as velocity the backward difference of those over
    # dt (qd0 at t = 0). Deterministic; the run differs from the one with the exact state.
    counts = 4096
    delta = 2 * np.pi / counts
    seen = []

    def recorder(t, q, qd):
        seen.append((q.copy(), qd.copy()))
        return np.zeros(7)

    run = simulate(lwr, Q0, QD0, 0.2, recorder, encoder_counts=counts)
    np.testing.assert_array_equal(run.q_measured, delta * np.round(run.q / delta))
    assert np.abs(run.q_measured - run.q).max() <= delta / 2 + 1e-15
    q_seen = np.array([s[0] for s in seen])
    qd_seen = np.array([s[1] for s in seen])
    np.testing.assert_array_equal(q_seen, run.q_measured)
    np.testing.assert_array_equal(qd_seen[0], QD0)
    np.testing.assert_allclose(
        qd_seen[1:], np.diff(run.q_measured, axis=0) / 1e-3, rtol=0, atol=1e-9
    )
    law = PDGravity(lwr, KP, KD, eq33)
    exact = simulate(lwr, Q0, None, 1.0, law)
    coarse = simulate(lwr, Q0, None, 1.0, law, encoder_counts=counts)
    again = simulate(lwr, Q0, None, 1.0, law, encoder_counts=counts)
    np.testing.assert_array_equal(coarse.q, again.q)
    assert np.abs(coarse.tau - exact.tau).max() > 0.1  # velocity steps of delta / dt = 1.5 rad/s
    np.testing.assert_array_equal(exact.q_measured, exact.q)


def test_exact_sign_friction_and_prismatic_joints_run(lwr):
    # coulomb_band = 0 uses sign(qd) (docs/conventions.md, "Drive terms and the torque model"); a
    # prismatic joint's encoder counts per metre: a 1-dof horizontal slider of mass 2 kg pushed by 1
    # N from rest moves t^2 / 4 (RK4 exact for constant acceleration, 1e-12).
    slider = dynid.Robot.from_dh([[0.0, 0.0, 0.0, 0.0]], "P", gravity=(0.0, 0.0, 0.0))
    params = np.zeros(10)
    params[0] = 2.0
    params[[4, 7, 9]] = 1e-3
    slider.params = params
    run = simulate(slider, [0.0], None, 1.0, lambda t, q, qd: np.array([1.0]), encoder_counts=1000)
    np.testing.assert_allclose(run.q[:, 0], run.t**2 / 4, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(run.q_measured, 1e-3 * np.round(run.q / 1e-3))
    signed = simulate(lwr, Q0, QD0, 0.1, PDGravity(lwr, KP, KD, np.zeros(7)), coulomb_band=0.0)
    assert np.all(np.isfinite(signed.q))


def test_builtin_controllers_run_without_the_gil(lwr):
    # While a 10 s run at h = 1e-4 (100000 periods, ~0.5-2 s of C++) goes on in a thread, the
    # main thread keeps running Python: the longest pause between its loop iterations stays below
    # half the run's duration (it would span the whole C++ run if the GIL were held).
    import threading
    import time

    done = []
    worker = threading.Thread(
        target=lambda: done.append(
            simulate(lwr, Q0, QD0, 10.0, PDGravity(lwr, KP, KD, np.zeros(7)), dt=1e-4)
        )
    )
    start = last = time.perf_counter()
    longest = 0.0
    worker.start()
    while worker.is_alive():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    worker.join()
    duration = time.perf_counter() - start
    assert done and done[0].q.shape == (100001, 7)
    assert longest < 0.5 * duration, (longest, duration)


def test_a_long_run_stops_on_keyboard_interrupt(lwr):
    # Ctrl-C (here _thread.interrupt_main from a timer, 0.2 s in) ends a 100 s run (10^5 periods
    # of 50 RK4 substeps, 2*10^7 forward dynamics: 20 s or more) within 5 s: the binding lets
    # Python handle signals every 1000 periods.
    import _thread
    import signal
    import threading
    import time

    # interrupt_main does nothing while SIGINT is ignored (pytest started in the background by a
    # non-interactive shell inherits that): Python's own handler, as in an interactive session.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.2, _thread.interrupt_main)
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            simulate(lwr, Q0, QD0, 100.0, PDGravity(lwr, KP, KD, np.zeros(7)), substeps=50)
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert time.perf_counter() - start < 5.0


# --- errors --------------------------------------------------------------------------------------


def test_python_controller_errors_propagate(lwr):
    def fails(t, q, qd):
        raise KeyError("inside the controller")

    with pytest.raises(KeyError, match="inside the controller"):
        simulate(lwr, Q0, None, 0.1, fails)
    with pytest.raises(ValueError, match=r"^controller: expected the callable to return 7"):
        simulate(lwr, Q0, None, 0.1, lambda t, q, qd: np.zeros(6))
    with pytest.raises(ValueError, match=r"^controller\b"):
        simulate(lwr, Q0, None, 0.1, lambda t, q, qd: np.full(7, np.nan))


def test_too_large_a_step_is_reported_not_returned_as_nan(lwr):
    # Kd dt / M_77 = 4000 * 0.01 / 0.07 >> 2: the sampled loop is unstable.
    with pytest.raises(RuntimeError, match="too large"):
        simulate(lwr, Q0, None, 5.0, PD(4e4, 4e3, np.zeros(7)), dt=1e-2)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"q0": np.zeros(6)}, "q0"),
        ({"q0": [0.0] * 6 + [np.nan]}, "q0"),
        ({"qd0": np.zeros((7, 1))}, "qd0"),
        ({"duration": 0.0}, "duration"),
        ({"duration": 1.0005}, "duration"),
        ({"duration": 1e7, "dt": 1e-3}, "duration"),
        ({"dt": -1e-3}, "dt"),
        ({"dt": np.inf}, "dt"),
        ({"substeps": 0}, "substeps"),
        ({"substeps": 2.0}, "substeps"),
        ({"method": "rk45"}, "method"),
        ({"friction": 1}, "friction"),
        ({"coulomb_band": -1e-3}, "coulomb_band"),
        ({"torque_noise": -0.1}, "torque_noise"),
        ({"torque_noise": np.nan}, "torque_noise"),
        ({"encoder_counts": 0}, "encoder_counts"),
        # Issue 22: a quantum of 2 pi / 1e-300 rad hid every motion from the controller.
        ({"encoder_counts": 1e-300}, "encoder_counts"),
        ({"encoder_counts": 0.5}, "encoder_counts"),
        ({"seed": -1}, "seed"),
        ({"controller": "pd"}, "controller"),
        ({"controller": PD(np.ones(6), 1.0, np.zeros(7))}, "kp"),
        ({"controller": PD(1.0, -1.0, np.zeros(7))}, "kd"),
        ({"controller": PD(1.0, 1.0, np.zeros(6))}, "reference"),
        ({"controller": PD(1.0, 1.0, (np.zeros((12, 7)),) * 3)}, "reference"),
        ({"controller": PD(1.0, 1.0, lambda t: (t,) * 3)}, "reference"),
        ({"controller": PDGravity(dynid.models.planar_2r(), 1.0, 1.0, np.zeros(7))}, "model"),
        ({"controller": ComputedTorque("robot", 1.0, 1.0, np.zeros(7))}, "model"),
        ({"robot": np.eye(7)}, "robot"),
    ],
)
def test_bad_arguments_raise_value_error_naming_them(lwr, kwargs, name):
    arguments = {"robot": lwr, "q0": Q0, "qd0": None, "duration": 0.01, "controller": None}
    arguments.update(kwargs)
    with pytest.raises(ValueError, match=rf"^{name}\b"):
        simulate(**arguments)


def test_the_documented_example_runs():
    # The python example of the simulation section of docs/uses.md runs as written; its
    # mismatched computed torque lags by more than 1 cm.
    section = "## Closed-loop simulation at the controller rate"
    text = (REPO / "docs" / "uses.md").read_text(encoding="utf-8")
    body = text.split(section, 1)[1].split("\n## ", 1)[0]
    codes = re.findall(r"^```python\n(.*?)^```", body, flags=re.MULTILINE | re.DOTALL)
    assert codes
    for code in codes:
        namespace: dict = {"__name__": "__docs__"}
        exec(compile(code, "docs", "exec"), namespace)
    assert np.abs(namespace["eq33"](namespace["run"].t)[0] - namespace["run"].q).max() > 0.01


# --- C++: no allocation per step ----------------------------------------------------------------


def test_simulator_runs_make_no_heap_allocation(cpp_tests):
    """Runs tests/cpp/test_simulator_no_allocation.cpp (built against the installed package):
    every operator new and malloc is counted during runs with each built-in controller, both
    integrators, friction, noise and an encoder; it also checks the runs (energy, tracking)."""
    output = cpp_tests.run("simulator_no_allocation")
    assert re.search(r"^allocations_during_runs=0$", output, re.MULTILINE), output
    assert re.search(r"^allocations_total=0$", output, re.MULTILINE), output
