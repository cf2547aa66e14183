"""Several logs in one identification (issue 20.3): each prepared separately, their rows stacked
through the streaming least squares; checked against NumPy's least squares of the two
regressors stacked by hand, and the per-log errors against their definition."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result
from dynid.identification.log_identification import identify_log
from dynid.logs import Log, load_log, save_log
from dynid.model.model_files import save_model
from test_log_identification import fourier_log


def _arm() -> dynid.Robot:
    robot = dynid.models.planar_2r()
    robot.Fv = np.array([0.3, 0.2])
    robot.Fs = np.array([0.4, 0.1])
    return robot


def _noisy(log: Log, seed: int, scale: tuple[float, float]) -> Log:
    """The log with torque noise of a different level per joint (so OLS and WLS differ and the
    fit is not the exact model, which any stacking would recover)."""
    rng = np.random.default_rng(seed)
    tau = log.tau + rng.normal(size=log.tau.shape) * np.asarray(scale)
    return Log(t=log.t, q=log.q, tau=tau, qd=log.qd, qdd=log.qdd, source=log.source)


@pytest.fixture(scope="module")
def two_logs(tmp_path_factory):
    """Two runs of different trajectories and lengths: one NPZ, one CSV."""
    folder = tmp_path_factory.mktemp("several")
    arm = _arm()
    save_log(_noisy(fourier_log(arm, 3, seconds=4.0), 10, (0.05, 0.01)), folder / "a.npz")
    save_log(_noisy(fourier_log(arm, 4, seconds=3.0), 11, (0.05, 0.01)), folder / "b.csv")
    save_model(dynid.models.planar_2r(), folder / "arm.json")
    return folder


def _by_hand(robot, logs, method):
    """theta of the stacked system by np.linalg.lstsq, as docs/identification.md defines OLS and
    WLS (sigma_j^2 = ||r_j||^2 / (N_j (N - p) / N) from the OLS residuals, rows / sigma_j)."""
    base = dynid.base_parameters(robot, friction=True)
    Ys = [robot.regressor(g.q, g.qd, g.qdd, friction=True)[:, :, base.independent] for g in logs]
    Y = np.concatenate(Ys)  # (T, n, p)
    tau = np.concatenate([g.tau for g in logs])
    T, n, p = Y.shape
    theta = np.linalg.lstsq(Y.reshape(T * n, p), tau.reshape(T * n), rcond=None)[0]
    if method == "wls":
        residual = tau - Y @ theta
        dof = T * n - p
        sigma2 = np.sum(residual**2, axis=0) / (T * dof / (T * n))
        w = 1.0 / np.sqrt(sigma2)
        Yw, tauw = Y * w[None, :, None], tau * w[None, :]
        theta = np.linalg.lstsq(Yw.reshape(T * n, p), tauw.reshape(T * n), rcond=None)[0]
    return theta, Ys


def _rms(x):
    return np.sqrt(np.mean(x**2, axis=0))


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_two_logs_of_different_formats_equal_the_stacked_least_squares(two_logs, method):
    robot = _arm()
    paths = [two_logs / "a.npz", two_logs / "b.csv"]
    result = identify_log(paths, robot, friction=True, method=method)
    logs = [load_log(path) for path in paths]
    theta, Ys = _by_hand(robot, logs, method)
    np.testing.assert_allclose(result.theta, theta, rtol=0, atol=1e-10 * np.abs(theta).max())
    # Each log's errors: its own torques against its own prediction.
    entries = result.training["logs"]
    assert [e["source"] for e in entries] == [str(p) for p in paths]
    for entry, log, Y in zip(entries, logs, Ys):
        error = Y @ theta - log.tau
        assert entry["samples"] == log.T
        np.testing.assert_allclose(entry["metrics"]["rms"], _rms(error), rtol=1e-9)
        np.testing.assert_allclose(
            entry["metrics"]["relative_rms"], _rms(error) / _rms(log.tau), rtol=1e-9
        )
        np.testing.assert_allclose(
            entry["metrics"]["max_abs"], np.abs(error).max(axis=0), rtol=1e-9
        )
    everything = np.concatenate([Y @ theta - g.tau for Y, g in zip(Ys, logs)])
    np.testing.assert_allclose(result.training["metrics"]["rms"], _rms(everything), rtol=1e-9)
    assert result.training["samples"] == sum(g.T for g in logs)
    # Mixed Log objects and paths give the same fit; the prepared logs are kept in order.
    mixed = identify_log([logs[0], paths[1]], robot, friction=True, method=method)
    np.testing.assert_array_equal(mixed.theta, result.theta)
    assert [g.T for g in result.logs] == [g.T for g in logs]


def test_one_log_in_a_list_is_the_single_log_fit(two_logs):
    robot = _arm()
    log = load_log(two_logs / "a.npz")
    single = identify_log(log, robot, friction=True)
    listed = identify_log([log], robot, friction=True)
    assert single == listed and "logs" not in single.training
    np.testing.assert_array_equal(single.fitted, listed.fitted)


def test_each_log_is_prepared_separately(two_logs):
    """A filter applied per log equals the logs filtered one by one and then stacked."""
    robot = _arm()
    logs = [load_log(two_logs / "a.npz"), load_log(two_logs / "b.csv")]
    options = {"cutoff": 10.0}
    result = identify_log(logs, robot, friction=True, method="ols", preparation=options)
    prepared = [dynid.prepare_log(g, **options) for g in logs]
    theta, _ = _by_hand(robot, prepared, "ols")
    np.testing.assert_allclose(result.theta, theta, rtol=0, atol=1e-10 * np.abs(theta).max())


def test_bad_logs_are_value_errors_naming_the_argument():
    robot = _arm()
    with pytest.raises(ValueError, match=r"log: .*none"):
        identify_log([], robot)
    with pytest.raises(ValueError, match=r"log\[1\]: expected a dynid.Log"):
        identify_log([fourier_log(robot, 1), 3], robot)
    with pytest.raises(ValueError, match=r"log: expected a dynid\.Log"):
        identify_log(3, robot)


def test_cli_identify_several_logs(two_logs, tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["identify", str(two_logs / "a.npz"), str(two_logs / "b.csv")]
    argv += ["--model", str(two_logs / "arm.json"), "--friction", "--output", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "fit on the 2 training logs" in printed and "fit on log 2" in printed
    data = json.loads((out / "result.json").read_text())
    assert [e["source"] for e in data["training"]["logs"]] == [argv[1], argv[2]]
    result = load_result(out)
    theta, _ = _by_hand(_arm(), [load_log(two_logs / "a.npz"), load_log(two_logs / "b.csv")], "wls")
    np.testing.assert_allclose(result.theta, theta, rtol=0, atol=1e-10 * np.abs(theta).max())
    assert isinstance(result.training["logs"][1]["metrics"]["rms"], np.ndarray)
    for name in ("torques.png", "residuals.png", "torques_2.png", "residuals_2.png", "run.yaml"):
        assert (out / name).is_file()


@pytest.mark.parametrize("physical", [False, True])
def test_two_logs_equal_their_rows_in_one_log(two_logs, physical):
    """Unprepared logs (qd, qdd given): stacking two logs is the fit on one log holding both
    runs' samples (a second path: one log, one chunk), for least squares and the physically
    consistent fit (whose SDP gets the stacked standard columns)."""
    robot = _arm()
    a, b = load_log(two_logs / "a.npz"), load_log(two_logs / "b.csv")
    joined = Log(
        t=np.concatenate([a.t, b.t + a.t[-1] + 1.0]),
        **{k: np.concatenate([getattr(a, k), getattr(b, k)]) for k in ("q", "qd", "qdd", "tau")},
    )
    options = {"friction": True, "physical": physical}
    both, one = identify_log([a, b], robot, **options), identify_log(joined, robot, **options)
    scale = np.abs(one.theta).max()
    tolerance = 1e-6 if physical else 1e-12  # the SDP solver's tolerance; exact LS otherwise
    np.testing.assert_allclose(both.theta, one.theta, rtol=0, atol=tolerance * scale)
    np.testing.assert_allclose(
        np.concatenate(both.fitted_logs),
        one.fitted,
        rtol=0,
        atol=tolerance * np.abs(one.fitted).max(),
    )


def test_min_velocity_leaves_out_rows_of_each_log(two_logs):
    """min_velocity per joint and per log: the rows of joint j where |qd_j| < v left out of
    each log, as a hand-built stacked OLS without those rows."""
    robot = _arm()
    logs = [load_log(two_logs / "a.npz"), load_log(two_logs / "b.csv")]
    v = 0.3
    result = identify_log(logs, robot, friction=True, method="ols", preparation={"min_velocity": v})
    base = dynid.base_parameters(robot, friction=True)
    A, b = [], []
    for g in logs:
        Y = robot.regressor(g.q, g.qd, g.qdd, friction=True)[:, :, base.independent]
        keep = np.abs(g.qd) >= v
        A.append(Y[keep])  # (rows kept, p)
        b.append(g.tau[keep])
    theta = np.linalg.lstsq(np.concatenate(A), np.concatenate(b), rcond=None)[0]
    np.testing.assert_allclose(result.theta, theta, rtol=0, atol=1e-10 * np.abs(theta).max())
    for entry, g in zip(result.training["logs"], logs):
        keep = np.abs(g.qd) >= v
        Y = robot.regressor(g.q, g.qd, g.qdd, friction=True)[:, :, base.independent]
        error = Y @ theta - g.tau
        rms = [np.sqrt(np.mean(error[keep[:, j], j] ** 2)) for j in range(robot.n)]
        np.testing.assert_allclose(entry["metrics"]["rms"], rms, rtol=1e-9)
        assert any("left out the rows of joint j" in note for note in entry["notes"])
