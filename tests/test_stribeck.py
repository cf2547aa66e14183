"""The smooth Stribeck friction block (friction="stribeck") and the separable least squares that
estimates its velocity scales (dynid.identification.separable; docs/identification.md,
"Friction models").

The law is written out here sample by sample from its definition (Olsson et al. 1998, eq. (7),
with tanh(w / vc) for sign(w) and a coefficient per direction):

    tau_f = [Fc + (Fst - Fc) exp(-(w / vs)^2)] tanh(w / vc) + Fv w,   w = T qd,
    joint torque T^T tau_f,

and the simulated logs are the RNEA of a robot without drive friction plus this torque, so the
block's columns, its derivatives and the estimate are checked against an independent
computation. Tolerances: the columns 1e-14 of their scale (the same floating-point operations
in another order); derivatives against central differences 1e-7 relative (the difference's
truncation error ~h^2 with h = 1e-5); an exact log's velocity scales and coefficients 1e-6
relative (the estimate reaches ~1e-13; the bound leaves room for other BLAS).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from coupled_robots import coupled_puma
from dynid.cli import main
from dynid.export.result_files import load_result, save_result
from dynid.identification.blocks.base import Context
from dynid.identification.blocks.stribeck import StribeckFriction
from dynid.identification.drive_gains import identify_drive_gains
from dynid.identification.log_identification import identify_log, validate_log
from dynid.logs import Log, save_log
from dynid.model.model_files import save_model
from test_log_identification import fourier_log


def without_drive_friction(robot: dynid.Robot) -> dynid.Robot:
    robot = robot.copy()
    robot.Fv = np.zeros(robot.n)
    robot.Fs = np.zeros(robot.n)
    return robot


def truth(n: int, seed: int) -> dict[str, np.ndarray]:
    """Per-direction levels with a clear Stribeck peak (Fst > Fc) and per-drive scales."""
    rng = np.random.default_rng(seed)
    fc_up, fc_down = rng.uniform(0.3, 1.0, (2, n))
    return {
        "vc": rng.uniform(0.008, 0.03, n),
        "vs": rng.uniform(0.07, 0.2, n),
        "Fc+": fc_up,
        "Fc-": fc_down,
        "Fst+": fc_up * rng.uniform(1.3, 1.8, n),
        "Fst-": fc_down * rng.uniform(1.3, 1.8, n),
        "Fv+": rng.uniform(0.1, 0.5, n),
        "Fv-": rng.uniform(0.1, 0.5, n),
    }


def stribeck_torque(qd: np.ndarray, law: dict[str, np.ndarray], T: np.ndarray) -> np.ndarray:
    """The joint torque T^T tau_f(T qd), element by element from the definition."""
    w = qd @ T.T
    tau_f = np.zeros_like(w)
    for (t, k), v in np.ndenumerate(w):
        side = "+" if v > 0 else "-"
        fc, fst, fv = law["Fc" + side][k], law["Fst" + side][k], law["Fv" + side][k]
        level = fc + (fst - fc) * np.exp(-((v / law["vs"][k]) ** 2))
        tau_f[t, k] = level * np.tanh(v / law["vc"][k]) + fv * v
    return tau_f @ T


def coefficients(law: dict[str, np.ndarray]) -> np.ndarray:
    """The block's coefficients in its column order (without offsets)."""
    return np.concatenate([law[k] for k in ("Fc+", "Fc-", "Fst+", "Fst-", "Fv+", "Fv-")])


def stribeck_log(robot: dynid.Robot, law: dict[str, np.ndarray], seed: int, **kw) -> Log:
    log = fourier_log(robot, seed, **kw)
    tau = log.tau + stribeck_torque(log.qd, law, robot.transmission)
    return Log(t=log.t, q=log.q, tau=tau, qd=log.qd, qdd=log.qdd, source=f"stribeck-{seed}")


def block_at(robot: dynid.Robot, law: dict[str, np.ndarray], offset: bool = False):
    block = StribeckFriction.build(Context(robot, True, "stribeck", offset, False))
    assert block is not None
    return block.with_parameters(np.concatenate([law["vc"], law["vs"]]), np.zeros(2 * robot.n))


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    return without_drive_friction(dynid.models.kuka_lwr4())


@pytest.mark.parametrize("coupled", [False, True])
def test_the_columns_are_the_law(coupled):
    """columns(q, qd) @ coefficients is the law written out (decoupled LWR and the coupled
    PUMA wrist, joint torque T^T tau_f(T qd)); with offsets, equal levels per direction."""
    robot = without_drive_friction(coupled_puma() if coupled else dynid.models.kuka_lwr4())
    law = truth(robot.n, 3)
    rng = np.random.default_rng(0)
    qd = rng.normal(scale=0.1, size=(400, robot.n))
    qd[::17] = 0.0  # at rest: the law gives 0
    q = np.zeros_like(qd)
    expected = stribeck_torque(qd, law, robot.transmission)
    block = block_at(robot, law)
    got = block.columns(q, qd) @ coefficients(law)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14 * np.abs(expected).max())
    assert np.all(got[::17] == 0.0)
    symmetric = dict(law, **{"Fc-": law["Fc+"], "Fst-": law["Fst+"]})
    with_offset = block_at(robot, law, offset=True)
    theta = np.concatenate([law["Fc+"], law["Fst+"], law["Fv+"], law["Fv-"]])
    expected = stribeck_torque(qd, symmetric, robot.transmission)
    np.testing.assert_allclose(
        with_offset.columns(q, qd) @ theta, expected, rtol=0, atol=1e-14 * np.abs(expected).max()
    )
    assert with_offset.names()[: robot.n] == [f"Fc{j}" for j in range(1, robot.n + 1)]


@pytest.mark.parametrize("coupled", [False, True])
def test_the_torque_derivatives_are_those_of_the_law(coupled):
    """d tau_f / d log v (v = vc_k, vs_k) against central differences of the law written out."""
    robot = without_drive_friction(coupled_puma() if coupled else dynid.models.kuka_lwr4())
    law = truth(robot.n, 5)
    qd = np.random.default_rng(1).normal(scale=0.1, size=(300, robot.n))
    block = block_at(robot, law)
    got = block.torque_derivatives(np.zeros_like(qd), qd, coefficients(law))
    assert got.shape == (2 * robot.n, 300, robot.n)
    h = 1e-5
    for i in range(2 * robot.n):
        key, k = ("vc", i) if i < robot.n else ("vs", i - robot.n)
        up, down = dict(law), dict(law)
        up[key] = law[key].copy()
        down[key] = law[key].copy()
        up[key][k] *= np.exp(h)
        down[key][k] *= np.exp(-h)
        T = robot.transmission
        numeric = (stribeck_torque(qd, up, T) - stribeck_torque(qd, down, T)) / (2 * h)
        scale = np.abs(numeric).max()
        np.testing.assert_allclose(got[i], numeric, rtol=0, atol=1e-7 * scale)


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_an_exact_log_gives_the_velocity_scales_and_the_coefficients(lwr, method):
    """Noise-free torques with a known Stribeck friction: vc, vs and every coefficient to 1e-6
    relative, the base values to 1e-6 of the largest; the velocity scales recorded as estimated
    with (tiny) standard deviations."""
    law = truth(lwr.n, 11)
    result = identify_log(
        stribeck_log(lwr, law, 1, seconds=6.0), lwr, rotor=True, friction="stribeck", method=method
    )
    block = result.blocks[0]
    assert isinstance(block, StribeckFriction) and block.estimated
    np.testing.assert_allclose(block.vc, law["vc"], rtol=1e-6)
    np.testing.assert_allclose(block.vs, law["vs"], rtol=1e-6)
    where = result.identification_model.slice("stribeck_friction")
    np.testing.assert_allclose(result.theta[where], coefficients(law), rtol=1e-6)
    true_base = dynid.base_parameters(lwr, rotor=True, friction=False).values(lwr)
    np.testing.assert_allclose(
        result.theta[: result.count], true_base, rtol=0, atol=1e-6 * np.abs(true_base).max()
    )
    assert np.all(np.isfinite(block.vc_std)) and max(block.vc_std) < 1e-6 * min(block.vc)
    assert any("separable least squares" in note for note in result.training["notes"])


def test_a_coupled_wrist_is_identified_on_the_drives_velocities():
    """The coupled PUMA (motor velocities w = T qd): the scales and levels of each drive."""
    robot = without_drive_friction(coupled_puma())
    law = truth(robot.n, 13)
    result = identify_log(
        stribeck_log(robot, law, 2, seconds=6.0),
        robot,
        rotor=True,
        friction="stribeck",
        method="ols",
    )
    block = result.blocks[0]
    np.testing.assert_allclose(block.vc, law["vc"], rtol=1e-6)
    np.testing.assert_allclose(block.vs, law["vs"], rtol=1e-6)
    where = result.identification_model.slice("stribeck_friction")
    np.testing.assert_allclose(result.theta[where], coefficients(law), rtol=1e-6)


def test_the_standard_deviations_are_calibrated():
    """Planar 2R arm, torque noise of known sigma per joint, 20 seeds: the errors of the
    velocity scales and of the friction coefficients over their reported std (WLS, the
    linear ones' covariance widened by the scales' own uncertainty) have an RMS in [0.7, 1.3]
    (measured with 40 seeds: 1.08 and 1.02; without the widening the coefficients' RMS is 1.26,
    Fc1+ 1.78)."""
    robot = dynid.models.planar_2r()
    law = truth(2, 17)
    sigma = np.array([0.02, 0.01])
    base = fourier_log(robot, 7, seconds=20.0, fs=50.0)
    exact = base.tau + stribeck_torque(base.qd, law, np.eye(2))
    rng = np.random.default_rng(2024)
    z_rho, z_theta = [], []
    for _ in range(20):
        tau = exact + rng.normal(size=exact.shape) * sigma
        log = Log(t=base.t, q=base.q, tau=tau, qd=base.qd, qdd=base.qdd, source="noisy")
        result = identify_log(log, robot, friction="stribeck", method="wls")
        block = result.blocks[0]
        rho = np.concatenate([block.vc, block.vs])
        z_rho.append((rho - np.concatenate([law["vc"], law["vs"]])) / (block.vc_std + block.vs_std))
        where = result.identification_model.slice("stribeck_friction")
        z_theta.append((result.theta[where] - coefficients(law)) / result.std[where])
    rms_rho = np.sqrt(np.mean(np.square(z_rho)))
    rms_theta = np.sqrt(np.mean(np.square(z_theta)))
    assert 0.7 <= rms_rho <= 1.3, rms_rho
    assert 0.7 <= rms_theta <= 1.3, rms_theta


def test_saved_loaded_and_validated(lwr, tmp_path):
    """result.json records the velocity scales (options.stribeck) and format version 3; the
    loaded result is equal and predicts another exact log to 1e-9 relative RMS."""
    law = truth(lwr.n, 19)
    result = identify_log(
        stribeck_log(lwr, law, 1, seconds=6.0),
        lwr,
        rotor=True,
        friction="stribeck",
        offset=True,
        method="ols",
    )
    path = save_result(result, tmp_path / "ident", plots=False)
    data = json.loads(path.read_text())
    assert data["version"] == 3 and data["options"]["friction_model"] == "stribeck"
    recorded = data["options"]["stribeck"]
    assert recorded["vc"] == list(result.blocks[0].vc) and recorded["estimated"] is True
    loaded = load_result(path)
    assert loaded == result
    # Offsets present: Fc, Fst one per drive, so the per-direction truth is not in the model;
    # validate on a log whose friction is symmetric.
    symmetric = dict(law, **{"Fc-": law["Fc+"], "Fst-": law["Fst+"]})
    again = identify_log(
        stribeck_log(lwr, symmetric, 1, seconds=6.0),
        lwr,
        rotor=True,
        friction="stribeck",
        offset=True,
        method="ols",
    )
    check = stribeck_log(lwr, symmetric, 4, seconds=6.0)
    metrics = validate_log(load_result(save_result(again, tmp_path / "sym", plots=False)), check)
    assert metrics["relative_rms"].max() < 1e-9


def test_the_physical_fit_keeps_friction_nonnegative_with_the_scales_fixed(lwr):
    """A negative Coulomb level on joint 1 (friction that feeds energy in): least squares
    returns it, the physical fit puts it on 0 while every coefficient stays >= 0, with the same
    velocity scales as the unconstrained estimate."""
    pytest.importorskip("cvxpy")
    law = truth(lwr.n, 23)
    law["Fc+"][0] = -0.5
    log = stribeck_log(lwr, law, 1, seconds=6.0)
    free = identify_log(log, lwr, rotor=True, friction="stribeck", method="wls")
    physical = identify_log(log, lwr, rotor=True, friction="stribeck", physical=True)
    where = free.identification_model.slice("stribeck_friction")
    assert free.theta[where][0] == pytest.approx(-0.5, rel=1e-6)
    constrained = physical.theta[where]  # on the bound to the SDP solver's tolerance (~1e-6)
    assert constrained.min() >= -1e-5
    assert constrained[0] <= 1e-5
    assert physical.blocks[0].vc == free.blocks[0].vc
    assert physical.blocks[0].vs == free.blocks[0].vs


def test_bad_options_are_named(lwr, tmp_path):
    law = truth(lwr.n, 29)
    log = stribeck_log(lwr, law, 1, seconds=2.0)
    with pytest.raises(ValueError, match=r"friction: .*'stribeck'.*got 'stribek'"):
        identify_log(log, lwr, friction="stribek")
    with pytest.raises(ValueError, match="friction: the 'stribeck' model has nonlinear"):
        identify_drive_gains(lwr, log, log, payload_mass=1.0, friction="stribeck")
    block = block_at(lwr, law)
    with pytest.raises(ValueError, match=r"values: expected velocity scales in"):
        block.with_parameters(np.full(14, 5.0), np.zeros(14))
    with pytest.raises(ValueError, match=r"values, std: expected 14"):
        block.with_parameters(np.full(3, 0.1), np.zeros(3))
    with pytest.raises(ValueError, match=r"coefficients: expected 42"):
        block.torque_derivatives(log.q, log.qd, np.zeros(3))
    record = block.record()
    options = {"friction_model": "stribeck", **record}
    assert StribeckFriction.from_record(options, lwr.n) == block
    for key, value, message in (
        ("vc", [0.1] * 3, r"options\.stribeck\.vc: expected a list of 7"),
        ("vs", [0.1] * 6 + [50.0], r"options\.stribeck\.vs: expected values in"),
        ("vc_std", ["x"] * 7, r"options\.stribeck\.vc_std: expected a list of 7"),
        ("transmission", [[1.0]], r"options\.stribeck\.transmission: expected 7 rows"),
    ):
        bad = {"friction_model": "stribeck", "stribeck": dict(record["stribeck"], **{key: value})}
        with pytest.raises(ValueError, match=message):
            StribeckFriction.from_record(bad, lwr.n)
    with pytest.raises(ValueError, match=r"options\.stribeck: expected"):
        StribeckFriction.from_record({"friction_model": "stribeck"}, lwr.n)


def test_the_command_line(lwr, tmp_path, capsys):
    """dynid identify --stribeck-friction, then dynid validate; two friction flags: exit 2."""
    model = tmp_path / "lwr.json"
    save_model(lwr, model)
    law = truth(lwr.n, 31)
    save_log(stribeck_log(lwr, law, 1, seconds=6.0), tmp_path / "train.npz")
    save_log(stribeck_log(lwr, law, 4, seconds=6.0), tmp_path / "check.npz")
    out = tmp_path / "out"
    argv = ["identify", str(tmp_path / "train.npz"), "--model", str(model), "--rotor"]
    assert main([*argv, "--stribeck-friction", "--method", "ols", "--output", str(out)]) == 0
    result = load_result(out)
    np.testing.assert_allclose(result.blocks[0].vc, law["vc"], rtol=1e-6)
    validation = tmp_path / "val"
    assert (
        main(["validate", str(out), str(tmp_path / "check.npz"), "--output", str(validation)]) == 0
    )
    report = json.loads((validation / "validation.json").read_text())
    assert max(report["metrics"]["relative_rms"]) < 1e-9
    capsys.readouterr()
    both = [*argv, "--stribeck-friction", "--friction", "--output", str(tmp_path / "x")]
    assert main(both) == 2
    err = capsys.readouterr().err
    assert "--friction, --stribeck-friction: choose one friction model" in err
    assert not Path(tmp_path / "x").exists()


def test_the_logs_regressor_is_computed_once(lwr, monkeypatch):
    """A spy on dynid.Robot.regressor: one call on the training log's samples, shared by the
    separable estimate of the scales and the least squares that follows."""
    law = truth(lwr.n, 37)
    log = stribeck_log(lwr, law, 1, seconds=3.0)
    calls: list[int] = []
    original = dynid.Robot.regressor

    def counted(self, q, *args, **kwargs):
        calls.append(np.shape(q)[0])
        return original(self, q, *args, **kwargs)

    monkeypatch.setattr(dynid.Robot, "regressor", counted)
    result = identify_log(log, lwr, rotor=True, friction="stribeck", method="ols")
    assert calls.count(log.T) == 1
    monkeypatch.setattr(dynid.Robot, "regressor", original)
    expected = identify_log(log, lwr, rotor=True, friction="stribeck", method="ols")
    np.testing.assert_array_equal(
        result.fitted, result.regressor(log.q, log.qd, log.qdd) @ result.theta
    )
    assert result == expected
