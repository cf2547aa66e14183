"""IDIM-IV and DIDIM (dynid.identification.estimators.iv, .didim) on simulated closed-loop data
whose truth is known.

The data: a planar 2R arm with viscous friction tracks a 3-harmonic reference under a PD
controller at 1 kHz (dynid.sim.simulate). In the statistical test the controller sees the
positions with white noise (1 mrad) and their backward difference as velocity, so the noise is
fed back into the torque; the log holds those noisy positions and the commanded torque plus
white measurement noise (1 N m), and identify_log differentiates the positions (low-pass 10 Hz,
decimation by 40). The regressor is then noisy and correlated with the torque error, and
OLS/WLS are biased; IDIM-IV and DIDIM, whose regressors come from the noise-free simulated loop,
are not. The exact tests compare the estimators' simulated loop with the one that made the log
(both dynid.sim.simulate, the log's made directly here, not through the estimators' options).
"""

from __future__ import annotations

import json
import types

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.identification.blocks.rigid_body import RigidBody
from dynid.identification.estimators.closed_loop_fit import adjoint_filter
from dynid.identification.estimators.closed_loop_model import plant
from dynid.identification.log_identification import identify_log
from dynid.logs import Log, save_log
from dynid.logs.reference import load_reference
from dynid.sim import PD, ComputedTorque, PDGravity, simulate

KP, KD = np.array([400.0, 200.0]), np.array([40.0, 20.0])
HARMONICS = np.array([[0.8, -0.5, 0.3], [0.9, 0.4, -0.3]])  # joint x harmonic, rad/s
W0 = 2 * np.pi * 0.25  # base frequency [rad/s]
T0 = 100.0  # the log's clock starts here (the reference is on that clock)


def truth() -> dynid.Robot:
    robot = dynid.models.planar_2r()
    robot.Fv = np.array([0.8, 0.5])
    return robot


def reference(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q_d, qd_d, qdd_d on the log's clock, in closed form."""
    s = np.asarray(t, dtype=float)[:, None] - T0
    q, qd, qdd = (np.zeros((s.shape[0], 2)) for _ in range(3))
    for k in range(1, 4):
        a = HARMONICS[:, k - 1]
        q += a * np.sin(k * W0 * s) / k
        qd += a * W0 * np.cos(k * W0 * s)
        qdd -= a * k * W0**2 * np.sin(k * W0 * s)
    return q, qd, qdd


def noisy_log(seed: int, seconds: float = 16.0, dt: float = 1e-3) -> Log:
    """PD on positions with 1 mrad of white noise; torque measured with 1 N m of noise."""
    rng = np.random.default_rng(seed)
    steps = round(seconds / dt)
    e = rng.normal(scale=1e-3, size=(steps + 1, 2))
    q_d, qd_d, _ = reference(T0 + np.arange(steps + 1) * dt)

    def pd(t, q, qd):  # a Python controller: the noise enters the loop
        k = round(t / dt)
        velocity = qd + (e[k] - e[k - 1]) / dt if k else qd
        return KP * (q_d[k] - q - e[k]) + KD * (qd_d[k] - velocity)

    run = simulate(truth(), q_d[0], qd_d[0], seconds, pd, dt=dt)
    tau = run.tau + rng.normal(scale=1.0, size=run.tau.shape)
    return Log(t=run.t + T0, q=run.q + e, tau=tau, source=f"pd-{seed}")


PREPARATION = {"cutoff": 10.0, "decimate": 40}
OPTIONS = {"controller": "pd", "kp": KP, "kd": KD, "reference": reference, "control_period": 1e-3}


@pytest.fixture(scope="module")
def z_scores():
    robot = truth()
    expected = dynid.base_parameters(robot, friction=True).values(robot)
    z: dict[str, list[np.ndarray]] = {"wls": [], "iv": [], "didim": []}
    settled = []
    for seed in range(20):
        log = noisy_log(seed)
        for method in z:
            got = identify_log(
                log,
                robot,
                friction=True,
                method=method,
                preparation=PREPARATION,
                estimator_options=None if method == "wls" else OPTIONS,
            )
            z[method].append((got.theta - expected) / got.std)
            if method != "wls":
                settled.append(got.estimator["settled"])
    # Every fit settles (some where the map jumps: Coulomb's sign, closed_loop_fit.iterate).
    assert all(settled)
    return {k: np.array(v) for k, v in z.items()}


def test_least_squares_is_biased_on_closed_loop_data(z_scores):
    """WLS: over 20 seeds the mean z-score of m2R, mx2R, my2 is 4.65, -5.29, 5.43 (of m1R
    -1.65, my1 1.31): the estimates sit 5 std away from the truth, always on the same side,
    the bias of noisy regressors correlated with the torque error."""
    bias = z_scores["wls"].mean(axis=0)
    assert np.abs(bias).max() > 4.0
    assert np.sum(np.abs(bias) > 3.0) >= 3


@pytest.mark.parametrize("method", ["iv", "didim"])
def test_iv_and_didim_are_unbiased_and_their_std_calibrated(z_scores, method):
    """Mean z-score of every coefficient within 0.7 (3 standard errors of a mean of 20), the
    RMS over seeds and coefficients in [0.7, 1.3], each coefficient's in [0.55, 1.5]
    (measured: IV 0.83-1.08, pooled 0.98, largest |mean| 0.40; DIDIM 0.80-1.18, pooled 1.05,
    largest |mean| 0.47)."""
    z = z_scores[method]
    assert np.abs(z.mean(axis=0)).max() < 0.7
    assert 0.7 <= np.sqrt(np.mean(z**2)) <= 1.3
    rms = np.sqrt(np.mean(z**2, axis=0))
    assert rms.min() >= 0.55 and rms.max() <= 1.5


def exact_log(law, seconds: float = 4.0, dt: float = 2e-3) -> Log:
    """The loop without noise under ``law(reference samples)``, started 10 mrad off the
    reference; q, qd, qdd of the simulation (qdd: under the held torque), so that tau = Y theta
    exactly. The reference is sampled for dynid.sim, whose time starts at 0 (the log's at T0)."""
    steps = round(seconds / dt)
    samples = reference(T0 + np.arange(steps + 1) * dt)
    run = simulate(truth(), samples[0][0] + 0.01, samples[1][0], seconds, law(samples), dt=dt)
    return Log(t=run.t + T0, q=run.q, tau=run.tau, qd=run.qd, qdd=run.qdd, source="exact")


def pd_law(r):
    return PD(KP, KD, r)


@pytest.mark.parametrize(
    ("controller", "options"),
    [
        ("pd", {}),
        ("pd_gravity", {}),
        ("computed_torque", {"controller_model": "planar_2r"}),
    ],
)
def test_exact_data_give_the_truth(controller, options):
    """Noise-free closed-loop data: IV and DIDIM return the true base parameters (1e-9
    relative), every controller kind, the controller's model as the identified robot or named."""
    robot = truth()
    law = {
        "pd": lambda r: PD(KP, KD, r),
        "pd_gravity": lambda r: PDGravity(robot, KP, KD, r),
        "computed_torque": lambda r: ComputedTorque(dynid.models.planar_2r(), 100.0, 20.0, r),
    }[controller]
    log = exact_log(law)
    gains = (100.0, 20.0) if controller == "computed_torque" else (KP, KD)
    given = {"controller": controller, "kp": gains[0], "kd": gains[1], "reference": reference}
    expected = dynid.base_parameters(robot, friction=True).values(robot)
    for method in ("iv", "didim"):
        got = identify_log(
            log, robot, friction=True, method=method, estimator_options={**given, **options}
        )
        scale = np.abs(expected).max()
        np.testing.assert_allclose(got.theta, expected, rtol=0, atol=1e-9 * scale)
        assert got.estimator["controller"] == controller and got.estimator["settled"]


def test_python_controller_and_reference_file(tmp_path):
    """A Python controller (on the log's clock) and a reference file (NPZ and CSV of the
    samples at the log's instants: the spline passes through them) give the exact truth."""
    robot = truth()
    log = exact_log(pd_law)
    expected = dynid.base_parameters(robot, friction=True).values(robot)
    q_d, qd_d, qdd_d = reference(log.t)
    np.savez(tmp_path / "ref.npz", t=log.t, q_d=q_d, qd_d=qd_d, qdd_d=qdd_d)
    header = ["t"] + [f"{s}{j}" for s in ("q_d", "qd_d", "qdd_d") for j in (1, 2)]
    table = np.column_stack([log.t, q_d, qd_d, qdd_d])
    lines = [",".join(header)] + [",".join(repr(float(v)) for v in row) for row in table]
    (tmp_path / "ref.csv").write_text("\n".join(lines) + "\n")

    def python_pd(t, q, qd):
        q_r, qd_r, _ = reference(np.array([t]))
        return KP * (q_r[0] - q) + KD * (qd_r[0] - qd)

    variants = [
        {"controller": python_pd},
        {"controller": "pd", "kp": KP, "kd": KD, "reference": str(tmp_path / "ref.npz")},
        {"controller": "pd", "kp": KP, "kd": KD, "reference": tmp_path / "ref.csv"},
        {
            "controller": "pd",
            "kp": KP,
            "kd": KD,
            "reference": {"t": log.t, "q_d": q_d, "qd_d": qd_d, "qdd_d": qdd_d},
        },
    ]
    for options in variants:
        got = identify_log(log, robot, friction=True, method="didim", estimator_options=options)
        np.testing.assert_allclose(got.theta, expected, rtol=0, atol=1e-9)


def test_reference_spline_is_exact_on_cubics(tmp_path):
    """A cubic q_d given by its samples only: the not-a-knot spline is that cubic, so its
    velocity and acceleration are the closed-form ones (1e-10) between the samples."""
    t = np.linspace(0.0, 2.0, 21)
    cubic = np.column_stack([t**3 - 2 * t, 0.5 * t**2 + 1])
    np.savez(tmp_path / "c.npz", t=t, q_d=cubic)
    ref = load_reference(tmp_path / "c.npz")
    s = np.linspace(0.0, 2.0, 57)
    q, qd, qdd = ref(s)
    np.testing.assert_allclose(q, np.column_stack([s**3 - 2 * s, 0.5 * s**2 + 1]), atol=1e-12)
    np.testing.assert_allclose(qd, np.column_stack([3 * s**2 - 2, s]), atol=1e-10)
    np.testing.assert_allclose(qdd, np.column_stack([6 * s, np.ones_like(s)]), atol=1e-10)
    with pytest.raises(ValueError, match="reference: covers t in"):
        ref(np.array([2.5]))


@pytest.mark.parametrize("a", [[], [0.5], [1.2, -0.5, 0.1], [1.9, -0.95]])
def test_adjoint_filter_equals_scipy_on_the_reversed_series(a):
    """The covariance's noise-model filter (closed_loop_fit.adjoint_filter, FFT of the
    truncated impulse response) against scipy.signal.lfilter of the time-reversed series
    (1e-12 relative), including a pole pair at radius 0.975."""
    from scipy.signal import lfilter

    a = np.asarray(a, dtype=float)
    x = np.random.default_rng(0).normal(size=(300, 4))
    expected = lfilter([1.0], np.concatenate([[1.0], -a]), x[::-1], axis=0)[::-1]
    got = adjoint_filter(a, x)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_plant_has_the_base_parameters_theta():
    """plant(theta): its RNEA equals the base columns times theta (1e-12) at random states,
    for random theta, with rotor and friction columns."""
    robot = dynid.models.kuka_lwr4()
    base = dynid.base_parameters(robot, rotor=True, friction=True)
    rigid = RigidBody(robot, True, True, base.independent)
    problem = types.SimpleNamespace(model=types.SimpleNamespace(rigid=rigid))
    rng = np.random.default_rng(3)
    theta = rng.normal(size=base.count)
    other = plant(problem, theta)
    np.testing.assert_allclose(base.values(other), theta, rtol=0, atol=1e-12)
    q, qd, qdd = rng.normal(size=(3, 50, robot.n))
    expected = rigid.columns(q, qd, qdd) @ theta
    np.testing.assert_allclose(other.rnea(q, qd, qdd), expected, rtol=0, atol=1e-10)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({}, "controller: the closed-loop estimators need"),
        ({"controller": "pid"}, "controller: expected one of"),
        ({"controller": 3}, "controller: expected one of"),
        ({"controller": "pd", "kd": 1.0, "reference": reference}, "kp, kd: the gains"),
        ({"controller": "pd", "kp": -1.0, "kd": 1.0, "reference": reference}, "kp: expected"),
        ({"controller": "pd", "kp": [1.0] * 3, "kd": 1.0, "reference": reference}, "kp: expected"),
        ({"controller": "pd", "kp": 1.0, "kd": 1.0}, "reference: the trajectory"),
        ({"controller": "pd", "kp": 1.0, "kd": 1.0, "reference": 5}, "reference: expected a"),
        ({"controller": "pd", "kp": 1.0, "kd": 1.0, "reference": "nope.npz"}, "reference: no such"),
        ({"controller": "pd", "kp": 1.0, "kd": 1.0, "reference": {"t": [1]}}, "reference: a map"),
        (
            {"controller": "pd", "kp": 1.0, "kd": 1.0, "reference": reference, "iterations": 0},
            "iterations: expected an integer >= 1",
        ),
        (
            {
                "controller": "pd",
                "kp": 1.0,
                "kd": 1.0,
                "reference": reference,
                "control_period": -1.0,
            },
            "control_period: expected a time > 0",
        ),
        (
            {
                "controller": "pd",
                "kp": 1.0,
                "kd": 1.0,
                "reference": reference,
                "control_period": 3e-3,
            },
            "control_period: the samples of",
        ),
        (
            {
                "controller": "pd",
                "kp": 1.0,
                "kd": 1.0,
                "reference": reference,
                "controller_model": "planar_2r",
            },
            "controller_model: only for",
        ),
        (
            {
                "controller": "pd_gravity",
                "kp": 1.0,
                "kd": 1.0,
                "reference": reference,
                "controller_model": "puma560",
            },
            "controller_model: expected a dynid.Robot",
        ),
        ({"controller": lambda t, q, qd: q, "kp": 1.0}, "kp: not used with a Python"),
    ],
)
def test_bad_options_name_the_option(options, message):
    log = exact_log(pd_law, seconds=1.0)
    for method in ("iv", "didim"):
        with pytest.raises(ValueError, match=message):
            identify_log(log, truth(), friction=True, method=method, estimator_options=options)


def test_didim_refuses_blocks_iv_takes_them():
    """DIDIM needs the simulated robot to be the whole model: offsets refused. IV takes them
    (their instruments are their own columns): on exact data with offsets the truth comes back."""
    robot = truth()
    log = exact_log(pd_law)
    offset = np.array([0.3, -0.2])
    shifted = Log(t=log.t, q=log.q, tau=log.tau + offset, qd=log.qd, qdd=log.qdd)
    options = {"controller": "pd", "kp": KP, "kd": KD, "reference": reference}
    with pytest.raises(ValueError, match="method: 'didim' simulates the robot's own dynamics"):
        identify_log(
            shifted, robot, friction=True, offset=True, method="didim", estimator_options=options
        )
    got = identify_log(
        shifted, robot, friction=True, offset=True, method="iv", estimator_options=options
    )
    expected = np.concatenate([dynid.base_parameters(robot, friction=True).values(robot), offset])
    # 1e-7: Fs1 and the offset of joint 1 are nearly collinear (qd1 changes sign twice).
    np.testing.assert_allclose(got.theta, expected, rtol=0, atol=1e-7)
    assert any("offset" in note for note in got.training["notes"])


def test_an_estimate_without_direct_dynamics_is_refused():
    """Torques of the wrong sign: the WLS start is minus the truth, a robot whose M(q) is
    negative definite, which no simulator can run: a ValueError naming the log."""
    log = exact_log(pd_law, seconds=1.0)
    flipped = Log(t=log.t, q=log.q, tau=-log.tau, qd=log.qd, qdd=log.qdd, source="flipped")
    options = {"controller": "pd", "kp": KP, "kd": KD, "reference": reference}
    for method in ("iv", "didim"):
        with pytest.raises(ValueError, match="log: the robot of the estimate has a mass matrix"):
            identify_log(flipped, truth(), friction=True, method=method, estimator_options=options)


def test_cli_identify_with_iv(tmp_path, capsys):
    """dynid identify --method iv/didim on a small NPZ log with a reference file; a flag of
    theirs with --method wls is refused with exit 2."""
    log = exact_log(pd_law, seconds=2.0)
    save_log(log, tmp_path / "log.npz")
    q_d, qd_d, qdd_d = reference(log.t)
    np.savez(tmp_path / "ref.npz", t=log.t, q_d=q_d, qd_d=qd_d, qdd_d=qdd_d)
    robot = truth()
    expected = dynid.base_parameters(robot, friction=True).values(robot)
    common = [
        str(tmp_path / "log.npz"),
        "--model",
        "planar_2r",
        "--friction",
        "--kp",
        "400,200",
        "--kd",
        "40,20",
        "--reference",
        str(tmp_path / "ref.npz"),
        "--controller",
        "pd",
    ]
    for method in ("iv", "didim"):
        out = tmp_path / method
        assert main(["identify", *common, "--method", method, "--output", str(out)]) == 0
        data = json.loads((out / "result.json").read_text())
        assert data["estimator"]["method"] == method
        assert data["estimator"]["options"]["kp"] == [400.0, 200.0]
        theta = np.array([c["value"] for c in data["coefficients"]])
        np.testing.assert_allclose(theta, expected, rtol=0, atol=1e-6)
        replay = tmp_path / f"{method}-again"
        assert main(["identify", "--config", str(out / "run.yaml"), "--output", str(replay)]) == 0
    capsys.readouterr()
    assert main(["identify", *common, "--method", "wls", "--output", str(tmp_path / "w")]) == 2
    assert "--controller: not an option of --method wls" in capsys.readouterr().err
