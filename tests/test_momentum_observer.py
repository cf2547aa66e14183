"""dynid.MomentumObserver (docs/uses.md, "Collision residual"; De Luca & Mattone 2005) and
dynid.observer.

- Simulated contact: the LWR (rotor inertia, viscous friction; Coulomb friction off so that the
  RK4 integration stays fourth order) tracks a sine under PD + gravity compensation, integrated
  by fixed-step RK4 (1 ms) calling forward_dynamics, with a constant tool force F during
  [0.5 s, 1.2 s) (tau_ext = J^T F). The residual is compared with tau_ext filtered independently:
  the exact solution of r' = K (tau_ext - r) for tau_ext linear between samples (the jumps at the
  contact's start and end placed on the sample grid). Bounds: 1e-3 of max|tau_ext| during and
  after contact (the trapezoidal rule's error is ~1e-4; an explicit-Euler observer misses by
  K dt / 2 = 2.5 % at the jumps), and 1e-4 of it before contact (integration error only).
- Real LWR4+ logs (no contact): identified on measurements_1 as in test_real_data.py, run on
  measurements_2; the residual equals the model error tau_model - tau (the regressor's
  prediction, computed without the observer) through the same first-order filter, to 0.03 N m
  RMS per joint (the error itself is ~0.2 N m RMS); the residual's RMS per joint is printed.
- The trapezoidal rule is second order: the no-contact residual at 2 ms is ~4x the one at 1 ms.
- No heap allocation per update, rnea_derivatives or jacobian_dot call: tests/cpp/
  test_uses_no_allocation.cpp, compiled and run.
"""

from __future__ import annotations

import re
import threading
from pathlib import Path

import numpy as np
import pytest

import dynid
from conftest import make_arm

REPO = Path(__file__).resolve().parents[1]
DT = 1e-3
T_ON, T_OFF = 0.5, 1.2
FORCE = np.array([15.0, -10.0, 20.0, 1.0, -2.0, 0.5])  # N, N m at the tool point, world axes


def first_order_filter(
    u_right: np.ndarray, u_left: np.ndarray, gain: np.ndarray, dt: float
) -> np.ndarray:
    """Exact solution of r' = K (u - r), r(0) = 0, for u linear on each step from u_right[k]
    (its value just after t_k) to u_left[k + 1] (just before t_{k+1})."""
    decay = np.exp(-gain * dt)
    E = 1.0 - decay
    r = np.zeros_like(u_right)
    for k in range(len(r) - 1):
        a, b = u_right[k], u_left[k + 1]
        r[k + 1] = decay * r[k] + a * E + (b - a) * (1.0 - E / (gain * dt))
    return r


@pytest.fixture(scope="module")
def contact_run():
    """RK4 simulation of the LWR with a tool force during [T_ON, T_OFF): t, q, qd, tau, tau_ext."""
    robot = make_arm("lwr").robot()
    robot.Fs = np.zeros(robot.n)
    n = robot.n
    q0 = np.array([0.1, 0.5, -0.2, -1.0, 0.3, 0.6, 0.0])
    w = 2 * np.pi * 0.5

    def reference(t):
        phase = w * t + np.arange(n)
        return q0 + 0.3 * np.sin(phase), 0.3 * w * np.cos(phase)

    def control(t, q, qd):
        qr, qdr = reference(t)
        return robot.gravity(q) + 100.0 * (qr - q) + 20.0 * (qdr - qd)

    def derivative(t, x, contact):
        q, qd = x[:n], x[n:]
        external = robot.jacobian(q).T @ FORCE if contact else 0.0
        return np.concatenate([qd, robot.forward_dynamics(q, qd, control(t, q, qd) + external)])

    steps = 2000
    x = np.concatenate(reference(0.0))
    states, torques = [x], [control(0.0, x[:n], x[n:])]
    for k in range(steps):
        t = k * DT
        contact = T_ON - 1e-9 <= t < T_OFF - 1e-9  # constant over each RK4 step
        k1 = derivative(t, x, contact)
        k2 = derivative(t + DT / 2, x + DT / 2 * k1, contact)
        k3 = derivative(t + DT / 2, x + DT / 2 * k2, contact)
        k4 = derivative(t + DT, x + DT * k3, contact)
        x = x + DT / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        states.append(x)
        torques.append(control((k + 1) * DT, x[:n], x[n:]))  # the measured motor torque
    X = np.array(states)
    t = np.arange(steps + 1) * DT
    q, qd = X[:, :n], X[:, n:]
    tau_ext = np.einsum("tji,j->ti", robot.jacobian(q), FORCE)
    return robot, t, q, qd, np.array(torques), tau_ext


@pytest.mark.parametrize("gain", [50.0, np.array([20.0, 30.0, 40.0, 50.0, 60.0, 80.0, 100.0])])
def test_residual_tracks_the_external_torque_with_the_observer_time_constant(contact_run, gain):
    robot, t, q, qd, tau, tau_ext = contact_run
    observer = dynid.MomentumObserver(robot, gain, DT)
    r = observer.run(q, qd, tau)
    assert r.shape == q.shape
    eps = 1e-9
    right = np.where(((t >= T_ON - eps) & (t < T_OFF - eps))[:, None], tau_ext, 0.0)
    left = np.where(((t > T_ON + eps) & (t <= T_OFF + eps))[:, None], tau_ext, 0.0)
    expected = first_order_filter(right, left, np.broadcast_to(gain, (robot.n,)), DT)
    scale = np.abs(tau_ext).max()
    before = t < T_ON - eps
    assert np.abs(r[before]).max() < 1e-4 * scale
    np.testing.assert_allclose(r, expected, rtol=0, atol=1e-3 * scale)
    # one time constant after the contact starts: 1 - 1/e of tau_ext (slowly varying), per joint
    K = np.broadcast_to(gain, (robot.n,))
    for j in range(robot.n):
        k = round((T_ON + 1.0 / K[j]) / DT)
        np.testing.assert_allclose(r[k, j] / tau_ext[k, j], 1 - np.exp(-1), atol=0.03)


def test_update_run_reset_and_properties(contact_run):
    robot, _t, q, qd, tau, _ = contact_run
    observer = dynid.MomentumObserver(robot, 40.0, DT)
    assert observer.n == robot.n and observer.dt == DT and observer.samples == 0
    np.testing.assert_array_equal(observer.gain, np.full(robot.n, 40.0))
    batch = observer.run(q[:300], qd[:300], tau[:300])
    np.testing.assert_array_equal(batch[0], np.zeros(robot.n))  # p(0) fixed by the first sample
    observer.reset()
    single = np.array([observer.update(q[k], qd[k], tau[k]) for k in range(300)])
    np.testing.assert_array_equal(single, batch)  # the same arithmetic, sample by sample
    np.testing.assert_array_equal(observer.residual, batch[-1])
    assert observer.samples == 300
    # run continues from the current state
    rest = observer.run(q[300:400], qd[300:400], tau[300:400])
    observer.reset()
    whole = observer.run(q[:400], qd[:400], tau[:400])
    np.testing.assert_array_equal(rest, whole[300:])


def test_one_observer_shared_by_two_threads_loses_no_sample(contact_run):
    """run() releases the GIL: two threads running logs through one observer must not
    interleave their updates (issue 22: 1-12 % of the samples were lost, residuals 3e3 instead
    of 242). The calls run one after the other, so the results are those of the two runs in
    some order, exactly: the first from the fresh state, the second continuing from it."""
    robot, _t, q, qd, tau, _ = contact_run
    Q, QD, TAU = (np.tile(x, (20, 1)) for x in (q, qd, tau))  # 40k samples: the runs overlap
    serial = dynid.MomentumObserver(robot, 40.0, DT)
    first, second = serial.run(Q, QD, TAU), serial.run(Q, QD, TAU)

    shared = dynid.MomentumObserver(robot, 40.0, DT)
    start = threading.Barrier(2)
    results: list[np.ndarray] = []

    def worker() -> None:
        start.wait()
        results.append(shared.run(Q, QD, TAU))

    threads = [threading.Thread(target=worker) for _ in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert shared.samples == 2 * len(Q)
    assert len(results) == 2
    fresh = next(r for r in results if np.array_equal(r[0], np.zeros(robot.n)))
    other = next(r for r in results if r is not fresh)
    np.testing.assert_array_equal(fresh, first)
    np.testing.assert_array_equal(other, second)
    np.testing.assert_array_equal(shared.residual, second[-1])


def test_the_model_is_copied(contact_run):
    robot, _t, q, qd, tau, _ = contact_run
    robot = robot.copy()
    observer = dynid.MomentumObserver(robot, 40.0, DT)
    expected = observer.run(q[:50], qd[:50], tau[:50])
    robot.params = robot.params * 2
    observer.reset()
    np.testing.assert_array_equal(observer.run(q[:50], qd[:50], tau[:50]), expected)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda r: dynid.MomentumObserver(r, 0.0, DT), "gain"),
        (lambda r: dynid.MomentumObserver(r, np.ones(r.n - 1), DT), "gain"),
        (lambda r: dynid.MomentumObserver(r, -np.ones(r.n), DT), "gain"),
        (lambda r: dynid.MomentumObserver(r, np.nan, DT), "gain"),
        (lambda r: dynid.MomentumObserver(r, 10.0, 0.0), "dt"),
        (lambda r: dynid.MomentumObserver(r, 10.0, "1ms"), "dt"),
        (
            lambda r: dynid.MomentumObserver(r, 10.0, DT).update(
                np.zeros(r.n + 1), np.zeros(r.n), np.zeros(r.n)
            ),
            "q",
        ),
        (
            lambda r: dynid.MomentumObserver(r, 10.0, DT).update(
                np.zeros(r.n), np.zeros(r.n), np.full(r.n, np.inf)
            ),
            "tau",
        ),
        (
            lambda r: dynid.MomentumObserver(r, 10.0, DT).update(
                np.zeros((2, r.n)), np.zeros((2, r.n)), np.zeros((2, r.n))
            ),
            "q",
        ),
        (
            lambda r: dynid.MomentumObserver(r, 10.0, DT).run(
                np.zeros(r.n), np.zeros(r.n), np.zeros(r.n)
            ),
            "q",
        ),
        (
            lambda r: dynid.MomentumObserver(r, 10.0, DT).run(
                np.zeros((3, r.n)), np.zeros((2, r.n)), np.zeros((3, r.n))
            ),
            "qd",
        ),
    ],
)
def test_bad_input_raises_value_error_naming_argument(call, name):
    robot = make_arm("lwr").robot()
    with pytest.raises(ValueError, match=rf"^{name}:"):
        call(robot)


# ----------------------------------------------------------------------------- real data


def test_real_lwr_logs_residual_is_the_filtered_model_error(record_property, tmp_path):
    from dynid.export.result_files import load_result, save_result
    from dynid.identification.log_identification import identify_log
    from dynid.identification.observer import residual_from_log, robot_from_identification
    from dynid.io import load_log

    data = REPO / "tests" / "data"
    train = load_log(data / "measurements_1.npz", skip=500)
    check = load_log(data / "measurements_2.npz", skip=500)
    result = identify_log(
        train, dynid.models.kuka_lwr4(), rotor=True, friction=True, offset=True, method="wls"
    )
    robot, offsets = robot_from_identification(result)
    # the equivalent robot reproduces the identified model's prediction (regressor route)
    predicted = result.predict(check)
    np.testing.assert_allclose(
        robot.rnea(check.q, check.qd, check.qdd) + offsets, predicted, rtol=0, atol=1e-9
    )
    gain = 20.0
    residual = residual_from_log(result, check, gain)
    assert residual.r.shape == check.q.shape
    model_error = predicted - check.tau  # what the observer sees as an "external" torque
    expected = first_order_filter(model_error, model_error, np.full(check.n, gain), residual.dt)
    difference = np.sqrt(np.mean((residual.r - expected) ** 2, axis=0))
    print("residual RMS per joint [N m], measurements_2, gain 20/s:", np.round(residual.rms, 3))
    print("model error RMS per joint [N m]:", np.round(np.sqrt(np.mean(model_error**2, axis=0)), 3))
    print("RMS(residual - filtered model error) [N m]:", np.round(difference, 4))
    record_property("residual_rms", residual.rms.tolist())
    assert np.all(difference < 0.03)
    assert np.all(residual.rms < 1.1 * np.sqrt(np.mean(model_error**2, axis=0)))
    # a result read back from its files (what a CLI gets) gives the same residual
    save_result(result, tmp_path / "result")
    again = residual_from_log(load_result(tmp_path / "result"), check, gain)
    np.testing.assert_allclose(again.r, residual.r, rtol=0, atol=1e-9)


def test_residual_files_and_plot(tmp_path, contact_run):
    from dynid.identification.observer import plot_residual, residual_from_log, save_residual
    from dynid.io import Log

    robot, t, q, qd, tau, _ = contact_run
    log = Log(t=t, q=q, qd=qd, tau=tau)
    residual = residual_from_log(robot, log, 50.0)
    direct = dynid.MomentumObserver(robot, 50.0, DT).run(q, qd, tau)
    np.testing.assert_allclose(residual.r, direct, rtol=0, atol=1e-12)
    np.testing.assert_allclose(residual.rms, np.sqrt(np.mean(direct**2, axis=0)))
    saved = np.load(save_residual(residual, tmp_path / "residual.npz"))
    np.testing.assert_array_equal(saved["r"], residual.r)
    png = plot_residual(residual, tmp_path / "residual.png", threshold=1.0)
    assert png.stat().st_size > 10_000
    with pytest.raises(ValueError, match=r"^log:"):
        residual_from_log(robot, "log.npz", 50.0)
    with pytest.raises(ValueError, match=r"^model:"):
        residual_from_log("robot", log, 50.0)


@pytest.mark.parametrize("scale", [2.0**700, 2.0**-700])
def test_residual_rms_of_huge_and_tiny_torques_is_finite_and_exact(contact_run, scale):
    """Issue 22: rms = sqrt(mean(r**2)) was inf for |r| beyond ~1e154 (and 0 below ~1e-162).
    A robot and torques scaled by a power of two give a residual scaled by it exactly, and its
    RMS must be the unscaled RMS times that power."""
    from dynid.identification.observer import residual_from_log
    from dynid.io import Log

    robot, t, q, qd, tau, _ = contact_run
    plain = residual_from_log(robot, Log(t=t, q=q, qd=qd, tau=tau), 50.0)
    heavy = robot.copy()  # every dynamic parameter times the scale: the residual scales too
    heavy.params = robot.params * scale
    heavy.Ia, heavy.Fv, heavy.Fs = robot.Ia * scale, robot.Fv * scale, robot.Fs * scale
    scaled = residual_from_log(heavy, Log(t=t, q=q, qd=qd, tau=tau * scale), 50.0)
    np.testing.assert_allclose(
        scaled.r / scale, plain.r, rtol=1e-12, atol=1e-12 * plain.max_abs.max()
    )
    assert np.all(np.isfinite(scaled.rms)) and np.all(scaled.rms > 0)
    np.testing.assert_allclose(scaled.rms / scale, plain.rms, rtol=1e-12)


# ----------------------------------------------------------------------------- real time


def test_no_heap_allocation_per_update(cpp_tests):
    """Runs tests/cpp/test_uses_no_allocation.cpp (built against the installed package): it
    counts every operator new and malloc during 10^4 observer updates, rnea_derivatives and
    jacobian_dot calls, and checks their size errors name the argument."""
    output = cpp_tests.run("uses_no_allocation")
    assert re.search(r"^allocations_during_calls=0$", output, re.MULTILINE), output
    print(output)


def test_residual_without_contact_is_second_order_in_the_sample_period(contact_run):
    """The trapezoidal rule: halving dt divides the no-contact residual by ~4. The 1 ms run is
    sub-sampled to 2 ms (every other sample); the ratio of the maxima before the contact lies in
    [3, 5] (exactly 4 for a smooth integrand in the limit)."""
    robot, t, q, qd, tau, _ = contact_run
    before = t < T_ON - 0.1  # well before the contact: its 2 ms samples see no jump
    fine = dynid.MomentumObserver(robot, 50.0, DT).run(q[before], qd[before], tau[before])
    coarse = dynid.MomentumObserver(robot, 50.0, 2 * DT).run(
        q[before][::2], qd[before][::2], tau[before][::2]
    )
    ratio = np.abs(coarse).max() / np.abs(fine).max()
    print(f"no-contact residual, 2 ms / 1 ms: {ratio:.2f}")
    assert 3.0 < ratio < 5.0, ratio
