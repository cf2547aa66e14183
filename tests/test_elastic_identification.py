"""Identification of the drive side of an elastic-joint robot (issue 12, brief item 2):
dynid.identify_drives / identify_stiffness / identify_motor_side, and the link parameters from
tau_J with identify_log.

Data: the LWR (paper Table I links, a 2 kg payload) with known drives K (5e3 - 1.5e4 N m/rad),
B, Fv_m, Fs_m (ElasticRobot), following a sum-of-sines link motion (closed-form derivatives up
to the 4th) for 8 s at 1 kHz; theta, thetad, thetadd and tau come from the flat-output inverse
dynamics (no integration), tau_J = K (theta - q). Noise (seeded, white Gaussian): 0.05 N m on tau
and tau_J, 5e-7 rad on q and theta (encoders; noise on the regressor theta - q biases K down by
the factor var(noise) / var(theta - q), here < 3e-4 on the least loaded joint), and thetad,
thetadd recomputed from the noisy theta by the documented preparation (zero-phase low-pass
20 Hz, then differentiate twice) in the full test.

Tolerances: every estimate within 4 of its own standard deviations of the truth AND within a
stated relative error (K 0.5 %, B 2 %, Fv_m 5 %, Fs_m 5 %); noiseless data give the truth to
1e-8 relative (exact derivatives) — the test that proves the regression model is right.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from conftest import make_arm
from dynid.identification.elastic_identification import identify_motor_side, identify_stiffness

FS = 1000.0
DURATION = 8.0


def sum_of_sines(n: int, t: np.ndarray, seed: int = 21):
    """q_j(t) = a_j + sum_k b_jk sin(w_jk t + phi_jk), and its derivatives 1..4 (T, n) each."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(-0.5, 0.5, n)
    b = rng.uniform(0.1, 0.4, (3, n))
    w = rng.uniform(0.8, 4.0, (3, n))
    phi = rng.uniform(0.0, 2 * np.pi, (3, n))
    arg = w[None] * t[:, None, None] + phi[None]  # (T, 3, n)
    s, c = np.sin(arg), np.cos(arg)
    return (
        a + (b * s).sum(1),
        (b * w * c).sum(1),
        (-b * w**2 * s).sum(1),
        (-b * w**3 * c).sum(1),
        (b * w**4 * s).sum(1),
    )


@pytest.fixture(scope="module")
def truth():
    # a 2 kg payload off the flange axis loads the wrist joints (without it joint 7's deflection
    # is ~1e-5 rad, the size of the encoder noise)
    robot = make_arm("lwr").robot().with_payload(2.0, [0.08, -0.05, 0.1])
    n = robot.n
    rng = np.random.default_rng(22)
    elastic = dynid.ElasticRobot(
        robot,
        rng.uniform(5e3, 1.5e4, n),
        rng.uniform(0.5, 2.0, n),
        rng.uniform(5.0, 15.0, n),
        rng.uniform(0.5, 2.0, n),
    )
    t = np.arange(0.0, DURATION, 1.0 / FS)
    q, qd, qdd, qddd, qdddd = sum_of_sines(n, t)
    theta, thetad, thetadd = elastic.motor_motion(q, qd, qdd, qddd, qdddd)
    _, tau = elastic.inverse_dynamics(q, qd, qdd, qddd, qdddd)
    tau_J = elastic.elastic_torque(q, theta)
    data = {
        "t": t,
        "q": q,
        "qd": qd,
        "qdd": qdd,
        "theta": theta,
        "thetad": thetad,
        "thetadd": thetadd,
        "tau": tau,
        "tau_J": tau_J,
    }
    return elastic, data


def test_noiseless_data_give_the_truth(truth) -> None:
    elastic, d = truth
    result = dynid.identify_drives(
        d["q"], d["theta"], d["thetad"], d["thetadd"], d["tau"], d["tau_J"]
    )
    for estimate, exact in (
        (result.stiffness, elastic.K),
        (result.motor_inertia, elastic.B),
        (result.motor_viscous, elastic.Fv_m),
        (result.motor_coulomb, elastic.Fs_m),
    ):
        np.testing.assert_allclose(estimate, exact, rtol=1e-8)
    assert result.samples == len(d["t"])
    assert np.all(result.stiffness_rms < 1e-8) and np.all(result.motor_rms < 1e-8)


def noisy(d, seed=23, torque_noise=0.05, encoder_noise=5e-7):
    rng = np.random.default_rng(seed)
    out = dict(d)
    for name, sigma in (
        ("tau", torque_noise),
        ("tau_J", torque_noise),
        ("q", encoder_noise),
        ("theta", encoder_noise),
    ):
        out[name] = d[name] + rng.normal(0.0, sigma, d[name].shape)
    return out


def assert_recovered(estimate, std, exact, rtol, name):
    error = np.abs(estimate - exact)
    assert np.all(error < 4.0 * std), (name, error / std)
    assert np.all(error < rtol * np.abs(exact)), (name, error / np.abs(exact))


def test_noisy_data_with_exact_motor_derivatives(truth) -> None:
    elastic, d = truth
    m = noisy(d)
    result = dynid.identify_drives(
        m["q"], m["theta"], m["thetad"], m["thetadd"], m["tau"], m["tau_J"]
    )
    assert_recovered(result.stiffness, result.stiffness_std, elastic.K, 5e-3, "K")
    assert_recovered(result.motor_inertia, result.motor_inertia_std, elastic.B, 2e-2, "B")
    assert_recovered(result.motor_viscous, result.motor_viscous_std, elastic.Fv_m, 5e-2, "Fv_m")
    assert_recovered(result.motor_coulomb, result.motor_coulomb_std, elastic.Fs_m, 5e-2, "Fs_m")
    # the residual RMS estimates the noise: sqrt(2) * 0.05 on the motor equation (tau and tau_J)
    np.testing.assert_allclose(result.motor_rms, np.sqrt(2) * 0.05, rtol=0.1)
    robot = result.elastic_robot(elastic.link)
    assert isinstance(robot, dynid.ElasticRobot)
    np.testing.assert_array_equal(robot.K, result.stiffness)


def test_full_preparation_from_noisy_motor_positions(truth) -> None:
    """thetad, thetadd from the noisy theta: zero-phase 4th-order Butterworth at 20 Hz, then
    central differences twice (dynid.signal), 0.5 s trimmed at each end (filter transients)."""
    elastic, d = truth
    m = noisy(d, seed=24)
    theta_f = dynid.signal.lowpass(m["theta"], FS, 20.0)
    thetad = dynid.signal.differentiate(theta_f, fs=FS)
    thetadd = dynid.signal.differentiate(thetad, fs=FS)
    keep = slice(500, -500)
    result = dynid.identify_drives(
        m["q"][keep],
        m["theta"][keep],
        thetad[keep],
        thetadd[keep],
        m["tau"][keep],
        m["tau_J"][keep],
    )
    assert_recovered(result.stiffness, result.stiffness_std, elastic.K, 5e-3, "K")
    # the filter's small bias on thetad, thetadd is not in the OLS std: relative bounds only
    for estimate, exact, rtol in (
        (result.motor_inertia, elastic.B, 2e-2),
        (result.motor_viscous, elastic.Fv_m, 5e-2),
        (result.motor_coulomb, elastic.Fs_m, 5e-2),
    ):
        assert np.all(np.abs(estimate - exact) < rtol * exact), (estimate, exact)


def test_stiffness_with_a_sensor_offset(truth) -> None:
    elastic, d = truth
    offset = np.linspace(-0.5, 0.5, elastic.n)
    m = noisy(d, seed=25)
    K, K_std, o, o_std, _ = identify_stiffness(m["q"], m["theta"], m["tau_J"] + offset, offset=True)
    assert_recovered(K, K_std, elastic.K, 5e-3, "K")
    assert np.all(np.abs(o - offset) < 4 * o_std) and np.all(o_std < 0.01)
    K_plain, *_ = identify_stiffness(m["q"], m["theta"], m["tau_J"])
    np.testing.assert_allclose(
        K_plain, identify_stiffness(d["q"], d["theta"], d["tau_J"])[0], rtol=5e-3
    )


def test_link_parameters_from_the_elastic_torque(truth) -> None:
    """Paper eq. (7): identify_log on a Log whose tau is tau_J, without rotor or friction columns,
    gives the rigid body's base parameters (noiseless: 1e-6 relative to the largest); the motor
    torque tau in its place does not (the motor inertia and friction are not in the link model)."""
    elastic, d = truth
    rows = slice(None, None, 10)  # 100 Hz is plenty for an exact fit
    log = dynid.Log(
        t=d["t"][rows], q=d["q"][rows], tau=d["tau_J"][rows], qd=d["qd"][rows], qdd=d["qdd"][rows]
    )
    result = dynid.identify_log(log, elastic.link, method="ols")
    expected = result.beta @ elastic.link.parameter_vector()
    assert np.abs(result.theta - expected).max() < 1e-6 * np.abs(expected).max()
    wrong = dynid.identify_log(log.replace(tau=d["tau"][rows]), elastic.link, method="ols")
    assert np.abs(wrong.theta - expected).max() > 1e-2 * np.abs(expected).max()


def test_bad_arguments_name_the_argument(truth) -> None:
    _, d = truth
    q = d["q"][:100]
    with pytest.raises(ValueError, match=r"^theta:"):
        identify_stiffness(q, d["theta"][:99], d["tau_J"][:100])
    with pytest.raises(ValueError, match=r"^tau_J:"):
        identify_stiffness(q, d["theta"][:100], d["tau_J"][0])
    theta = d["theta"][:100].copy()
    theta[:, 2] = q[:, 2]
    with pytest.raises(ValueError, match=r"^theta: joint 2"):
        identify_stiffness(q, theta, d["tau_J"][:100])
    thetad = d["thetad"][:100].copy()
    thetad[:, 0] = 0.0
    with pytest.raises(ValueError, match=r"^thetad: joint 0"):
        identify_motor_side(thetad, d["thetadd"][:100], d["tau"][:100], d["tau_J"][:100])
    with pytest.raises(ValueError, match=r"^offset:"):
        identify_stiffness(q, d["theta"][:100], d["tau_J"][:100], offset=1)
