"""identify_drive_gains (dynid.identification.drive_gains): drive gains and base parameters from
motor currents.

The runs are exact: currents i = tau / k_true with tau from Pinocchio's RNEA of the KUKA LWR-IV
model written as URDF (plus dynid's rotor inertia and friction terms, which URDF does not carry
in full), without and with a payload on the last link, along Fourier trajectories in closed form.
The truth is k_true and the base values beta @ pi of the model's parameters.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result, save_result
from dynid.identification.drive_gains import identify_drive_gains, torques_from_currents
from dynid.identification.identify import RankDeficientError
from dynid.identification.payload_files import load_payload
from dynid.io import Log, save_log
from reference_model import physical_to_params
from test_log_identification import fourier_log

K_TRUE = np.array([10.0, 12.0, 8.0, 6.0, 5.0, 3.0, 2.5])  # N m / A
MASS, COM = 1.5, np.array([0.01, -0.02, 0.08])
INERTIA = np.array([[0.004, 0.0002, 0.0], [0.0002, 0.005, -0.0003], [0.0, -0.0003, 0.003]])
PAYLOAD = {"mass": MASS, "com": COM, "inertia": INERTIA}
METHODS = ("nls", "tls", "wls", "ols")


def pinocchio_torques(robot: dynid.Robot, log: Log) -> np.ndarray:
    """Torques of ``robot`` along ``log`` from Pinocchio (URDF of the robot), plus the drive
    terms Ia qdd + Fv qd + Fs sign(qd) of docs/conventions.md,
    "Drive terms and the torque model"."""
    model = pin.buildModelFromXML(robot.to_urdf())
    model.gravity.linear = robot.gravity_vector
    data = model.createData()
    assert log.qd is not None and log.qdd is not None
    rigid = np.array(
        [pin.rnea(model, data, q, qd, qdd) for q, qd, qdd in zip(log.q, log.qd, log.qdd)]
    )
    return rigid + robot.Ia * log.qdd + robot.Fv * log.qd + robot.Fs * np.sign(log.qd)


def current_log(log: Log, tau: np.ndarray, noise: float = 0.0, seed: int = 0) -> Log:
    """``log`` with the currents tau / k_true (+ white noise of ``noise`` times each joint's RMS
    current) in ``tau``."""
    current = tau / K_TRUE
    if noise:
        rng = np.random.default_rng(seed)
        current = current + rng.normal(size=current.shape) * noise * np.sqrt(np.mean(current**2, 0))
    return replace(log, tau=current)


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    return dynid.models.kuka_lwr4()  # with rotor inertia and friction


@pytest.fixture(scope="module")
def runs(lwr):
    """Exact current logs (Pinocchio torques): unloaded, loaded, and a third (unloaded) one."""
    loaded_arm = lwr.with_payload(MASS, COM, INERTIA)
    train, loaded, check = fourier_log(lwr, 1), fourier_log(lwr, 2), fourier_log(lwr, 3)
    return (
        current_log(train, pinocchio_torques(lwr, train)),
        current_log(loaded, pinocchio_torques(loaded_arm, loaded)),
        current_log(check, pinocchio_torques(lwr, check)),
    )


def truth(robot: dynid.Robot) -> np.ndarray:
    return dynid.base_parameters(robot, rotor=True, friction=True).values(robot)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("known", ["payload", "mass"])
def test_noise_free_runs_give_the_true_gains_and_base_parameters(lwr, runs, method, known):
    unloaded, loaded, _ = runs
    scale = {"payload": PAYLOAD} if known == "payload" else {"payload_mass": MASS}
    fit = identify_drive_gains(
        lwr, unloaded, loaded, rotor=True, friction=True, method=method, **scale
    )
    expected = truth(lwr)
    # 1e-8: exact data, the stacked system's condition number is ~2e3
    np.testing.assert_allclose(fit.gains, K_TRUE, rtol=1e-8, atol=0)
    np.testing.assert_allclose(
        fit.result.theta, expected, rtol=0, atol=1e-8 * np.abs(expected).max()
    )
    payload = physical_to_params(MASS, COM, INERTIA)  # Steiner, written out in the tests
    np.testing.assert_allclose(fit.payload, payload, rtol=0, atol=1e-8 * np.abs(payload).max())
    if known == "payload":
        assert np.all(fit.payload_std == 0)
    torque = unloaded.tau * K_TRUE
    assert np.all(fit.residual_rms < 1e-9 * np.sqrt(np.mean(torque**2, axis=0)))
    assert np.all(fit.result.training["metrics"]["relative_rms"] < 1e-9)
    assert fit.result.rank == fit.result.theta.size


def test_the_methods_agree_on_noise_free_runs(lwr, runs):
    """TLS, NLS and LS are different estimators; on exact data they meet at the one solution."""
    unloaded, loaded, _ = runs
    fits = [
        identify_drive_gains(
            lwr, unloaded, loaded, payload=PAYLOAD, rotor=True, friction=True, method=m
        )
        for m in METHODS
    ]
    for fit in fits[1:]:
        np.testing.assert_allclose(fit.estimate, fits[0].estimate, rtol=0, atol=1e-9)


def test_offsets_in_current_units_are_identified(lwr, runs):
    """A constant current offset c_j is a torque offset k_j c_j."""
    unloaded, loaded, _ = runs
    offset = np.linspace(-0.05, 0.05, lwr.n)  # A
    fit = identify_drive_gains(
        lwr,
        replace(unloaded, tau=unloaded.tau - offset),
        replace(loaded, tau=loaded.tau - offset),
        payload=PAYLOAD,
        rotor=True,
        friction=True,
        offset=True,
    )
    np.testing.assert_allclose(fit.gains, K_TRUE, rtol=1e-8)
    np.testing.assert_allclose(fit.result.theta[-lwr.n :], -K_TRUE * offset, rtol=0, atol=1e-8)


def test_arrays_and_lists_of_runs_are_accepted(lwr, runs):
    unloaded, loaded, check = runs
    kwargs = {"payload": PAYLOAD, "rotor": True, "friction": True}
    from_logs = identify_drive_gains(lwr, unloaded, loaded, **kwargs)
    arrays = [(log.q, log.qd, log.qdd, log.tau) for log in (unloaded, check, loaded)]
    from_arrays = identify_drive_gains(lwr, arrays[:2], [arrays[2]], **kwargs)
    # Two unloaded runs and one loaded: exact data, the same solution (1e-8 relative).
    np.testing.assert_allclose(from_arrays.gains, from_logs.gains, rtol=1e-8)
    assert [run["loaded"] for run in from_arrays.runs] == [False, False, True]
    assert from_arrays.residual_rms.shape == (3, lwr.n)


@pytest.mark.parametrize(("known", "noise"), [("payload", 0.02), ("mass", 0.02), ("payload", 0.05)])
def test_nls_standard_deviations_are_calibrated(lwr, known, noise):
    """With white current noise (2 or 5 % of each joint's RMS current), the z-scores
    (k - k_true) / std of the default method over 20 noise draws have mean ~0 and spread ~1
    (bounds: |mean| < 0.5, std in [0.75, 1.35]; 140 z-scores); the worst gain error stays below
    5 %."""
    loaded_arm = lwr.with_payload(MASS, COM, INERTIA)
    train, loaded = fourier_log(lwr, 1, seconds=10.0), fourier_log(lwr, 2, seconds=10.0)
    tau_u, tau_l = (
        lwr.rnea(train.q, train.qd, train.qdd),
        loaded_arm.rnea(loaded.q, loaded.qd, loaded.qdd),
    )
    scale = {"payload": PAYLOAD} if known == "payload" else {"payload_mass": MASS}
    z, errors = [], []
    for seed in range(20):
        fit = identify_drive_gains(
            lwr,
            current_log(train, tau_u, noise, seed),
            current_log(loaded, tau_l, noise, 1000 + seed),
            rotor=True,
            friction=True,
            **scale,
        )
        z.append((fit.gains - K_TRUE) / fit.gains_std)
        errors.append(np.abs(fit.gains / K_TRUE - 1).max())
    z = np.concatenate(z)
    assert abs(z.mean()) < 0.5
    assert 0.75 < z.std() < 1.35
    assert max(errors) < 0.05


def test_least_squares_shrinks_the_scale_and_tls_less(lwr):
    """The documented reason for the default: with 2 % current noise, WLS gains come out
    several standard deviations low (mean z < -3 over 10 draws); TLS stays within 10 % and NLS
    beats it (smaller RMS gain error)."""
    loaded_arm = lwr.with_payload(MASS, COM, INERTIA)
    train, loaded = fourier_log(lwr, 1, seconds=10.0), fourier_log(lwr, 2, seconds=10.0)
    tau_u = lwr.rnea(train.q, train.qd, train.qdd)
    tau_l = loaded_arm.rnea(loaded.q, loaded.qd, loaded.qdd)
    z_wls, error = [], {"tls": [], "nls": []}
    for seed in range(10):
        u = current_log(train, tau_u, 0.02, seed)
        ell = current_log(loaded, tau_l, 0.02, 1000 + seed)
        fits = {
            m: identify_drive_gains(
                lwr, u, ell, payload=PAYLOAD, rotor=True, friction=True, method=m
            )
            for m in ("wls", "tls", "nls")
        }
        z_wls.append((fits["wls"].gains - K_TRUE) / fits["wls"].gains_std)
        for m in error:
            error[m].append(fits[m].gains / K_TRUE - 1)
    assert np.mean(z_wls) < -3.0
    assert np.abs(error["tls"]).max() < 0.10
    assert np.sqrt(np.mean(np.square(error["nls"]))) < np.sqrt(np.mean(np.square(error["tls"])))


def test_without_a_loaded_run_or_payload_the_scale_is_an_error(lwr, runs):
    unloaded, loaded, _ = runs
    with pytest.raises(ValueError, match=r"loaded: no run given.*common scale"):
        identify_drive_gains(lwr, unloaded, [], payload=PAYLOAD)
    with pytest.raises(ValueError, match="payload, payload_mass: give exactly one"):
        identify_drive_gains(lwr, unloaded, loaded)
    with pytest.raises(ValueError, match="payload, payload_mass: give exactly one"):
        identify_drive_gains(lwr, unloaded, loaded, payload=PAYLOAD, payload_mass=MASS)


def test_coupled_drives_are_refused(lwr, runs):
    """tau_j = k_j i_j assumes one motor per joint: a coupled transmission is a ValueError naming
    the robot, not gains fitted to the wrong model."""
    unloaded, loaded, _ = runs
    coupled = lwr.copy()
    T = np.eye(7)
    T[5, 4] = 0.2
    coupled.transmission = T
    with pytest.raises(ValueError, match=r"^robot: its drives are coupled"):
        identify_drive_gains(coupled, unloaded, loaded, payload=PAYLOAD)


def test_a_loaded_run_without_the_payload_effect_is_rank_deficient(lwr, runs):
    """The 'loaded' run was recorded without the payload: its currents satisfy the homogeneous
    equations, so (theta, k) has a free scale again: RankDeficientError naming the gains."""
    unloaded, _, check = runs
    with pytest.raises(RankDeficientError, match=r"(?s)do not excite.*k\d.*payload alone"):
        identify_drive_gains(lwr, unloaded, check, payload=PAYLOAD, rotor=True, friction=True)


def test_a_payload_too_light_for_the_noise_is_an_error(lwr):
    """10 g at the flange against 2 % current noise (5 s runs): the likelihood has no finite
    optimum along the scale; 50 g is enough (gains within 4 std, relative std ~5 %)."""
    for mass, enough in ((0.01, False), (0.05, True)):
        arm = lwr.with_payload(mass, COM, None)
        train, loaded = fourier_log(lwr, 1), fourier_log(lwr, 2)
        u = current_log(train, lwr.rnea(train.q, train.qd, train.qdd), 0.02, 0)
        ell = current_log(loaded, arm.rnea(loaded.q, loaded.qd, loaded.qdd), 0.02, 1)
        kwargs = {"payload": {"mass": mass, "com": COM}, "rotor": True, "friction": True}
        if enough:
            fit = identify_drive_gains(lwr, u, ell, **kwargs)
            assert np.all(np.abs(fit.gains - K_TRUE) < 4 * fit.gains_std)
        else:
            with pytest.raises(RankDeficientError, match="too small against the noise"):
                identify_drive_gains(lwr, u, ell, **kwargs)


def test_a_mass_the_structure_cannot_see_is_an_error():
    """One joint about the vertical: the link's mass enters no torque, nor the payload's."""
    arm = dynid.Robot.from_dh([[0.5, 0.0, 0.0, 0.0]], joint_types="R")
    t = np.linspace(0, 1, 50)[:, None]
    q, qd, qdd = np.sin(3 * t), 3 * np.cos(3 * t), -9 * np.sin(3 * t)
    run = (q, qd, qdd, np.zeros_like(q))
    with pytest.raises(ValueError, match="payload_mass: on this structure"):
        identify_drive_gains(arm, run, run, payload_mass=1.0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"payload": np.ones(9)}, "payload: expected the 10 standard parameters"),
        ({"payload": np.r_[0.0, np.ones(9)]}, "payload: expected a positive mass"),
        ({"payload_mass": -1.0}, "payload_mass: expected a positive mass"),
        ({"payload": {"mass": 1.0}}, "payload: expected a mapping with mass, com"),
        (
            {"payload": {"mass": 1.0, "com": COM, "inertia": -np.eye(3)}},
            "payload.inertia: the payload is not physically possible",
        ),
        ({"payload": PAYLOAD, "method": "svd"}, "method: expected one of"),
        ({"payload": PAYLOAD, "rotor": "yes"}, "rotor: expected True or False"),
    ],
)
def test_bad_arguments_name_themselves(lwr, runs, kwargs, match):
    unloaded, loaded, _ = runs
    with pytest.raises(ValueError, match=match):
        identify_drive_gains(lwr, unloaded, loaded, **kwargs)


def test_bad_runs_name_themselves(lwr, runs):
    unloaded, loaded, _ = runs
    with pytest.raises(ValueError, match=r"unloaded\[0\]: .*has 2 joints"):
        identify_drive_gains(lwr, fourier_log(dynid.models.planar_2r(), 1), loaded, payload=PAYLOAD)
    arrays = (unloaded.q, unloaded.qd, unloaded.qdd, unloaded.tau)
    with pytest.raises(ValueError, match="preparation: needs time stamps"):
        identify_drive_gains(lwr, arrays, loaded, payload=PAYLOAD, preparation={"cutoff": 5.0})
    with pytest.raises(ValueError, match=r"loaded: expected a dynid\.Log"):
        identify_drive_gains(lwr, unloaded, "loaded.npz", payload=PAYLOAD)


def test_saved_result_keeps_the_gains_and_validates_a_current_log(lwr, runs, tmp_path):
    unloaded, loaded, check = runs
    fit = identify_drive_gains(lwr, unloaded, loaded, payload=PAYLOAD, rotor=True, friction=True)
    save_result(fit.result, tmp_path / "result")
    back = load_result(tmp_path / "result")
    assert back.drive_gains is not None
    np.testing.assert_array_equal(back.drive_gains["gains"], fit.gains)
    assert back.drive_gains["method"] == "nls" and back.drive_gains["payload_known"] == "all"
    torques = torques_from_currents(back, check)
    np.testing.assert_allclose(torques.tau, check.tau * fit.gains, rtol=1e-15)
    # The model predicts the third run's torques (and currents) to the data's exactness.
    metrics = dynid.validate_log(back, torques)
    assert np.all(metrics["relative_rms"] < 1e-8)
    np.testing.assert_allclose(fit.predict_currents(check), check.tau, rtol=0, atol=1e-9)
    plain = dynid.identify_log(torques, lwr)
    with pytest.raises(ValueError, match="result: holds no drive gains"):
        torques_from_currents(plain, check)


def test_a_point_mass_payload_is_its_standard_parameters():
    """mass and com without inertia: a point mass (Steiner in the tests' reference model)."""
    from dynid.identification.drive_gain_system import payload_vector

    known, estimated = payload_vector({"mass": 2.0, "com": COM}, None)
    np.testing.assert_allclose(
        known, physical_to_params(2.0, COM, np.zeros((3, 3))), rtol=0, atol=1e-15
    )
    assert estimated == []


def test_payload_specs(tmp_path):
    (tmp_path / "p.json").write_text(json.dumps({"mass": 1.5, "com": [0, 0, 0.1]}))
    assert load_payload(tmp_path / "p.json") == {"mass": 1.5, "com": [0, 0, 0.1]}
    (tmp_path / "q.json").write_text(json.dumps({"parameters": list(range(1, 11))}))
    np.testing.assert_array_equal(load_payload(tmp_path / "q.json"), np.arange(1.0, 11.0))
    np.testing.assert_array_equal(
        load_payload("1,0,0,0.1,0,0,0,0,0,0"), np.r_[1, 0, 0, 0.1, [0] * 6]
    )
    with pytest.raises(ValueError, match="neither a file nor 10 comma-separated numbers"):
        load_payload("1,2,3")
    (tmp_path / "r.json").write_text(json.dumps({"mass": 1.5, "colour": "red"}))
    with pytest.raises(ValueError, match=r"payload: .*r\.json: expected an object with mass"):
        load_payload(tmp_path / "r.json")


# --------------------------------------------------------------------------- command line


@pytest.fixture(scope="module")
def files(runs, tmp_path_factory):
    folder = tmp_path_factory.mktemp("currents")
    unloaded, loaded, check = runs
    save_log(unloaded, folder / "unloaded.npz")
    save_log(loaded, folder / "loaded.npz")
    save_log(check, folder / "check.csv")
    (folder / "payload.json").write_text(
        json.dumps({"mass": MASS, "com": COM.tolist(), "inertia": INERTIA.tolist()})
    )
    return folder


@pytest.mark.parametrize("known", ["payload", "mass"])
def test_cli_identify_current_and_validate(files, tmp_path, capsys, lwr, known):
    out, check = tmp_path / "ident", tmp_path / "check"
    scale = (
        ["--payload", str(files / "payload.json")]
        if known == "payload"
        else ["--payload-mass", str(MASS)]
    )
    argv = ["identify", str(files / "unloaded.npz"), "--current", "--rotor", "--friction"]
    argv += ["--payload-log", str(files / "loaded.npz"), *scale, "--output", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "[5/5] wrote" in printed and "drive gains (NLS" in printed
    result = load_result(out)
    np.testing.assert_allclose(result.drive_gains["gains"], K_TRUE, rtol=1e-8)
    np.testing.assert_allclose(
        result.theta, truth(lwr), rtol=0, atol=1e-8 * np.abs(truth(lwr)).max()
    )
    assert (out / "torques.png").is_file()
    argv = ["validate", str(out), str(files / "check.csv"), "--current", "--output", str(check)]
    assert main(argv) == 0
    report = json.loads((check / "validation.json").read_text())
    assert max(report["metrics"]["relative_rms"]) < 1e-8
    capsys.readouterr()
    argv = ["validate", str(out), str(files / "check.csv"), "--output", str(tmp_path / "raw")]
    assert main(argv) == 0  # currents compared as torques: allowed, with a note
    assert "note: the result was identified from motor currents" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--current"], "--current: needs --payload-log"),
        (["--current", "--payload-log", "L"], "--current: give exactly one of --payload"),
        (["--payload-mass", "1"], "--payload-log, --payload, --payload-mass: only with --current"),
        (["--method", "nls"], "--method nls: only with --current"),
        (["--current", "--physical"], "--current: not with --physical"),
        (["--current", "--prior", "lwr"], "--current: not with --physical or --prior"),
        (
            ["--current", "--friction", "--asymmetric-friction"],
            "--friction, --asymmetric-friction: choose one friction model",
        ),
        (["--current", "--payload-log", "L", "--payload", "1,2"], "neither a file nor 10"),
    ],
)
def test_cli_current_errors_are_one_line(files, tmp_path, capsys, extra, message):
    argv = ["identify", str(files / "unloaded.npz"), *extra, "--output", str(tmp_path / "o")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_cli_validate_current_needs_gains(files, tmp_path, capsys):
    out = tmp_path / "plain"
    assert main(["identify", str(files / "check.csv"), "--output", str(out)]) == 0
    argv = [
        "validate",
        str(out),
        str(files / "check.csv"),
        "--current",
        "--output",
        str(tmp_path / "v"),
    ]
    assert main(argv) == 2
    assert "holds no drive gains" in capsys.readouterr().err


def test_a_model_that_misses_a_term_is_an_error_not_a_huge_gain(lwr, runs):
    """The runs hold friction, the model has none: the nonlinear fit runs away towards an
    infinite scale (gains of 1e9 and more before this check); a RankDeficientError says so."""
    unloaded, loaded, _ = runs
    with pytest.raises(RankDeficientError, match="does not converge from its WLS and TLS starts"):
        identify_drive_gains(lwr, unloaded, loaded, payload=PAYLOAD, rotor=True)


def test_no_silent_wrong_gains_with_the_mass_alone_at_high_noise(lwr):
    """With the payload's mass alone and 5 % current noise the likelihood has competing optima
    (wrist gains of the other sign, docs/drive_gains.md): every fit whose gains are off by more
    than 20 % must come with the RuntimeWarning (3 draws)."""
    loaded_arm = lwr.with_payload(MASS, COM, INERTIA)
    train, loaded = fourier_log(lwr, 1, seconds=10.0), fourier_log(lwr, 2, seconds=10.0)
    tau_u = lwr.rnea(train.q, train.qd, train.qdd)
    tau_l = loaded_arm.rnea(loaded.q, loaded.qd, loaded.qdd)
    for seed in range(3):
        u = current_log(train, tau_u, 0.05, seed)
        ell = current_log(loaded, tau_l, 0.05, 1000 + seed)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                fit = identify_drive_gains(
                    lwr, u, ell, payload_mass=MASS, rotor=True, friction=True
                )
            except RankDeficientError:
                continue  # an error is not silent either
        warned = any("other sign" in str(w.message) for w in caught)
        assert warned or np.abs(fit.gains / K_TRUE - 1).max() < 0.2
