"""identify_log / validate_log / save and load (dynid.identification.log_identification,
dynid.export.result_files).

The synthetic logs are exact: torques from the robot's RNEA (rigid body, rotor inertia, viscous
and Coulomb friction), positions, velocities and accelerations from a Fourier series in closed
form. Identification must then return the base values beta @ pi of the true parameters, and the
identified model must predict RNEA on another trajectory.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import dynid
from dynid.export.result_files import load_result, save_result
from dynid.identification.identify import RankDeficientError
from dynid.identification.log_identification import identify_log, validate_log
from dynid.logs import Log

PNG = b"\x89PNG\r\n\x1a\n"


def fourier_log(
    robot: dynid.Robot,
    seed: int,
    seconds: float = 5.0,
    fs: float = 100.0,
    offset: np.ndarray | None = None,
) -> Log:
    """A periodic 3-harmonic trajectory per joint (base frequency 0.2 Hz) and its exact torque."""
    rng = np.random.default_rng(seed)
    n, w = robot.n, 2 * np.pi * 0.2
    t = np.arange(0.0, seconds, 1.0 / fs)[:, None]
    q, qd, qdd = (np.zeros((t.size, n)) for _ in range(3))
    for k in range(1, 4):
        a, b = rng.normal(scale=0.5 / k, size=(2, n))
        s, c = np.sin(k * w * t), np.cos(k * w * t)
        q += (a * s - b * c) / (k * w)
        qd += a * c + b * s
        qdd += k * w * (b * c - a * s)
    tau = robot.rnea(q, qd, qdd) + (0.0 if offset is None else offset)
    return Log(t=t[:, 0], q=q, tau=tau, qd=qd, qdd=qdd, source=f"fourier-{seed}")


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    return dynid.models.kuka_lwr4()  # with non-zero Ia, Fv, Fs


@pytest.fixture(scope="module")
def lwr_result(lwr):
    return identify_log(
        fourier_log(lwr, 1), lwr, rotor=True, friction=True, offset=True, method="wls"
    )


@pytest.mark.parametrize("method", ["ols", "wls"])
@pytest.mark.parametrize(("rotor", "friction"), [(False, False), (True, True)])
def test_exact_log_gives_the_true_base_parameters(lwr, method, rotor, friction):
    truth = lwr.copy()
    if not rotor:
        truth.Ia = np.zeros(truth.n)
    if not friction:
        truth.Fv, truth.Fs = np.zeros(truth.n), np.zeros(truth.n)
    result = identify_log(fourier_log(truth, 1), lwr, rotor=rotor, friction=friction, method=method)
    expected = dynid.base_parameters(truth, rotor=rotor, friction=friction).values(truth)
    assert result.rank == expected.size == result.theta.size
    np.testing.assert_allclose(result.theta, expected, rtol=0, atol=1e-8 * np.abs(expected).max())
    assert np.all(result.training["metrics"]["relative_rms"] < 1e-9)


def test_offsets_are_recovered_with_the_base_parameters(lwr, lwr_result):
    offset = np.linspace(-0.6, 0.6, lwr.n)
    result = identify_log(
        fourier_log(lwr, 1, offset=offset),
        lwr,
        rotor=True,
        friction=True,
        offset=True,
        method="ols",
    )
    expected = dynid.base_parameters(lwr, rotor=True, friction=True).values(lwr)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(result.theta[: -lwr.n], expected, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(result.theta[-lwr.n :], offset, rtol=0, atol=1e-8 * scale)
    assert result.names[-lwr.n :] == [f"off{j}" for j in range(1, lwr.n + 1)]
    np.testing.assert_allclose(lwr_result.theta[-lwr.n :], 0.0, atol=1e-8 * scale)


def test_prediction_on_another_trajectory_is_rnea(lwr, lwr_result, monkeypatch):
    other = fourier_log(lwr, 7, seconds=3.0)
    robot = lwr_result.robot
    calls = []

    def counted(*args, **kwargs):
        calls.append(np.shape(args[0]))
        return type(robot).regressor(robot, *args, **kwargs)

    monkeypatch.setattr(robot, "regressor", counted, raising=False)
    predicted = lwr_result.predict(other)
    assert calls == [(other.T, lwr.n)]  # one batch call for all samples, no loop over them
    scale = np.abs(other.tau).max()
    np.testing.assert_allclose(predicted, other.tau, rtol=0, atol=1e-8 * scale)


def test_validate_log_reports_the_added_noise(lwr, lwr_result):
    """The model is exact, so the errors on a log with added torque noise are the noise's."""
    clean = fourier_log(lwr, 3, seconds=3.0)
    noise = np.random.default_rng(5).normal(scale=0.05, size=clean.tau.shape)
    metrics = validate_log(lwr_result, clean.replace(tau=clean.tau + noise))
    np.testing.assert_allclose(metrics["rms"], np.sqrt(np.mean(noise**2, axis=0)), rtol=1e-6)
    np.testing.assert_allclose(metrics["max_abs"], np.abs(noise).max(axis=0), rtol=1e-6)
    rms_tau = np.sqrt(np.mean((clean.tau + noise) ** 2, axis=0))
    np.testing.assert_allclose(metrics["relative_rms"], metrics["rms"] / rms_tau, rtol=1e-12)
    assert set(metrics) >= {"rms", "relative_rms", "max_abs", "r2"}


def test_preparation_is_applied_and_recorded(lwr):
    log = fourier_log(lwr, 2)
    result = identify_log(
        log.replace(qd=None, qdd=None), lwr, preparation={"decimate": np.int64(2), "cutoff": None}
    )
    # the anti-alias filter's edge transients are trimmed at both ends (issue 20), 15 samples
    # at the decimated rate for a factor of 2 (test_preparation_edges.py)
    assert result.training["samples"] == (log.T + 1) // 2 - 2 * 15
    assert result.training["preparation"] == {"decimate": 2}
    json.dumps(result.training["preparation"])  # plain Python numbers
    notes = " ".join(result.training["notes"])
    assert "computed by second-order central differences" in notes and "decimat" in notes
    assert result.log is not None and result.training["samples"] == result.log.T


def test_save_and_load_round_trip(lwr, lwr_result, tmp_path):
    path = save_result(lwr_result, tmp_path / "out")
    assert path == tmp_path / "out" / "result.json"
    for name in ("torques.png", "residuals.png"):
        assert (tmp_path / "out" / name).read_bytes()[:8] == PNG
    for source in (tmp_path / "out", path):
        loaded = load_result(source)
        for key in ("theta", "std", "relative_std", "beta", "independent"):
            np.testing.assert_array_equal(getattr(loaded, key), getattr(lwr_result, key))
        for key in (
            "names",
            "expressions",
            "parameter_names",
            "rank",
            "condition_number",
            "rotor",
            "friction",
            "offset",
            "method",
            "excluded",
            "model",
        ):
            assert getattr(loaded, key) == getattr(lwr_result, key), key
        assert "params" not in loaded.model  # the prior parameters are not part of the result
        other = fourier_log(lwr, 4, seconds=1.0)
        np.testing.assert_array_equal(loaded.predict(other), lwr_result.predict(other))
        assert loaded.summary() == lwr_result.summary()


def _corrupt(key, value):
    def change(data):
        data[key] = value

    return change


CORRUPT = [
    (_corrupt("format", "something"), "format: expected 'dynid-identification'"),
    (lambda d: d.pop("coefficients"), "coefficients: missing"),
    (lambda d: d["coefficients"].pop(), "coefficients: expected a list of 69 entries"),
    (lambda d: d["model"].pop("rows"), "model: rows: missing"),
    (lambda d: d["options"].update(friction=False), "parameter_names: do not match"),
    (lambda d: d["options"].update(rotor="yes"), "options.rotor: expected true or false"),
    (lambda d: d["base_parameters"]["beta"].pop(), "base_parameters.beta: expected shape"),
    (lambda d: d["coefficients"][3].update(value="x"), "coefficients[].value: expected numbers"),
    (lambda d: d["coefficients"][0].pop("expression"), "coefficients[0].expression: missing"),
]


@pytest.mark.parametrize(("change", "message"), CORRUPT)
def test_malformed_result_files_name_the_field(lwr_result, tmp_path, change, message):
    path = save_result(lwr_result, tmp_path, plots=False)
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=re.escape(message)) as info:
        load_result(tmp_path)
    assert message in str(info.value) and str(path) in str(info.value)


def test_result_file_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        load_result(tmp_path / "nothing")
    (tmp_path / "result.json").write_text("{")
    with pytest.raises(ValueError, match="not valid JSON"):
        load_result(tmp_path)


def test_bad_input(lwr, lwr_result):
    log = fourier_log(lwr, 2, seconds=2.0)
    with pytest.raises(ValueError, match="log: has 7 joints, but the model 'PUMA 560' has 6"):
        identify_log(log, dynid.models.puma560())
    with pytest.raises(ValueError, match=r"log: expected a dynid.Log"):
        identify_log(log.q, lwr)
    with pytest.raises(ValueError, match="method"):
        identify_log(log, lwr, method="lasso")
    with pytest.raises(ValueError, match=r"preparation: unknown option\(s\) \['skip'\]"):
        identify_log(log, lwr, preparation={"skip": 10})
    six = Log(t=log.t, q=log.q[:, :6], tau=log.tau[:, :6])
    with pytest.raises(ValueError, match="log: has 6 joints"):
        lwr_result.predict(six)
    still = log.replace(
        q=np.column_stack([log.q[:, :6], np.zeros(log.T)]),
        qd=np.column_stack([log.qd[:, :6], np.zeros(log.T)]),
        qdd=np.column_stack([log.qdd[:, :6], np.zeros(log.T)]),
    )
    with pytest.raises(RankDeficientError):  # joint 7 never moves: its parameters are unseen
        identify_log(still, lwr, rotor=True)


def test_summary_lists_every_coefficient(lwr_result):
    text = lwr_result.summary()
    assert "condition number" in text and "rank 69/69" in text
    for name, expression in zip(lwr_result.names, lwr_result.expressions):
        assert f"  {name} " in text and expression in text
    assert "J7" in text  # the per-joint fit table


def test_summary_shows_a_dash_where_there_is_no_standard_deviation(lwr_result):
    """A physical fit has no standard deviations (std = inf): issue 22 found "inf inf%" printed
    for every coefficient. The values themselves are printed as before."""
    import copy

    physical = copy.copy(lwr_result)
    physical.std = np.full(lwr_result.theta.size, np.inf)
    physical.relative_std = np.full(lwr_result.theta.size, np.inf)
    text = physical.summary()
    assert "inf" not in text
    for name, value in zip(lwr_result.names, lwr_result.theta):
        row = next(line for line in text.splitlines() if line.startswith(f"  {name} "))
        assert row.split()[1:4] == [f"{value:.5g}", "-", "-"], row


def test_excluded_joint_rows_are_left_out(lwr):
    """Joint 1's rows are the only ones holding Iyy1R (joint 1's inertia about its axis)."""
    with pytest.raises(RankDeficientError, match="Iyy1R"):
        identify_log(fourier_log(lwr, 1), lwr, exclude_joints=(0,), method="ols")
