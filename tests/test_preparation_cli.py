"""Preparation in identify and validate (issue 20, item 2): --min-velocity as a per-joint row
mask, the implausible time base as an error, validate applying the recorded preparation."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.identification.log_identification import identify_log, validate_log
from dynid.logs import Log, save_log
from test_log_identification import fourier_log


@pytest.fixture(scope="module")
def arm() -> dynid.Robot:
    robot = dynid.models.planar_2r()
    robot.Fv = np.array([0.3, 0.2])
    robot.Fs = np.array([0.4, 0.1])
    return robot


@pytest.fixture(scope="module")
def noisy(arm) -> Log:
    log = fourier_log(arm, 1, seconds=10.0)
    rng = np.random.default_rng(7)
    return log.replace(tau=log.tau + rng.normal(0.0, 0.05, log.tau.shape))


def test_min_velocity_leaves_out_rows_per_joint(arm, noisy) -> None:
    """OLS on the rows of joint j with |qd_j| >= v, stacked and solved here with numpy's lstsq:
    the same theta (1e-10) and the same per-joint errors on the rows kept; more rows are kept
    than whole samples would be."""
    v = 0.3
    result = identify_log(noisy, arm, friction=True, method="ols", preparation={"min_velocity": v})
    Y = result.regressor(noisy.q, noisy.qd, noisy.qdd)  # (T, n, p)
    keep = np.abs(noisy.qd) >= v
    A = np.concatenate([Y[keep[:, j], j, :] for j in range(arm.n)])
    b = np.concatenate([noisy.tau[keep[:, j], j] for j in range(arm.n)])
    theta = np.linalg.lstsq(A, b, rcond=None)[0]
    np.testing.assert_allclose(result.theta, theta, rtol=0, atol=1e-10 * np.abs(theta).max())
    assert keep.sum() > arm.n * np.all(keep, axis=1).sum()  # rows, not whole samples
    for j in range(arm.n):
        error = (Y[keep[:, j], j, :] @ theta) - noisy.tau[keep[:, j], j]
        rms = np.sqrt(np.mean(error**2))
        relative = rms / np.sqrt(np.mean(noisy.tau[keep[:, j], j] ** 2))
        assert result.training["metrics"]["rms"][j] == pytest.approx(rms, rel=1e-9)
        assert result.training["metrics"]["relative_rms"][j] == pytest.approx(relative, rel=1e-9)
    assert result.training["samples"] == noisy.T  # no sample dropped
    assert any("left out the rows of joint j" in note for note in result.training["notes"])

    # validate: the same rows of another log, the errors on them
    other = fourier_log(arm, 2, seconds=5.0)
    metrics = validate_log(result, other, preparation={"min_velocity": v})
    keep = np.abs(other.qd) >= v
    predicted = result.predict(other)
    for j in range(arm.n):
        error = predicted[keep[:, j], j] - other.tau[keep[:, j], j]
        assert metrics["rms"][j] == pytest.approx(np.sqrt(np.mean(error**2)), rel=1e-9)


def test_min_velocity_rows_with_wls_weigh_each_joint_by_its_own_rows(arm, noisy) -> None:
    """WLS: sigma_j^2 from joint j's kept rows (N_j - p N_j / N degrees of freedom), then OLS
    on the rows divided by sigma_j, done here by hand."""
    v = 0.3
    result = identify_log(noisy, arm, friction=True, method="wls", preparation={"min_velocity": v})
    Y = result.regressor(noisy.q, noisy.qd, noisy.qdd)
    keep = np.abs(noisy.qd) >= v
    A = [Y[keep[:, j], j, :] for j in range(arm.n)]
    b = [noisy.tau[keep[:, j], j] for j in range(arm.n)]
    first = np.linalg.lstsq(np.concatenate(A), np.concatenate(b), rcond=None)[0]
    N, p = sum(a.shape[0] for a in A), first.size
    sigma = [
        np.sqrt(np.sum((a @ first - y) ** 2) / (a.shape[0] * (N - p) / N)) for a, y in zip(A, b)
    ]
    weighted = np.linalg.lstsq(
        np.concatenate([a / s for a, s in zip(A, sigma)]),
        np.concatenate([y / s for y, s in zip(b, sigma)]),
        rcond=None,
    )[0]
    np.testing.assert_allclose(result.theta, weighted, rtol=0, atol=1e-9 * np.abs(weighted).max())


def test_implausible_time_base_is_exit_2_unless_the_unit_is_given(arm, tmp_path, capsys) -> None:
    log = fourier_log(arm, 1, seconds=2.0)
    save_log(log.replace(t=log.t * 1e9), tmp_path / "ns.npz")  # nanoseconds, read as seconds
    argv = ["identify", str(tmp_path / "ns.npz"), "--model", "planar_2r", "--output"]
    assert main([*argv, str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "dynid identify: error:" in err
    assert "sampling rate is 1e-07 Hz" in err and "--time-unit" in err and "'ns'" in err
    assert not (tmp_path / "a" / "result.json").exists()
    assert main([*argv, str(tmp_path / "b"), "--time-unit", "ns"]) == 0
    assert (tmp_path / "b" / "result.json").exists()


def test_validate_applies_the_recorded_preparation(arm, noisy, tmp_path, capsys) -> None:
    save_log(noisy, tmp_path / "train.npz")
    save_log(fourier_log(arm, 2, seconds=6.0), tmp_path / "check.npz")
    ident = tmp_path / "ident"
    argv = ["identify", str(tmp_path / "train.npz"), "--model", "planar_2r", "--friction"]
    assert main([*argv, "--cutoff", "5", "--min-velocity", "0.2", "--output", str(ident)]) == 0
    capsys.readouterr()

    def validate(name: str, *extra: str) -> tuple[str, dict]:
        out = tmp_path / name
        assert (
            main(
                ["validate", str(ident), str(tmp_path / "check.npz"), *extra, "--output", str(out)]
            )
            == 0
        )
        return capsys.readouterr().out, json.loads((out / "validation.json").read_text())

    printed, report = validate("v1")
    assert (
        "preparation applied: --cutoff 5.0 (recorded in the result), --min-velocity 0.2 "
        "(recorded in the result), --order 4 (recorded in the result)"
    ) in printed
    assert report["preparation"] == {"cutoff": 5.0, "min_velocity": 0.2, "order": 4}
    assert "trimmed" in printed  # the recorded low-pass ran, and its edges were trimmed

    printed, report = validate("v2", "--cutoff", "3", "--outliers", "6")
    assert "--cutoff 3.0 (command line)" in printed and "--outlier-k" not in printed
    assert "--outliers 6.0 (command line)" in printed
    assert report["preparation"]["cutoff"] == 3.0 and report["preparation"]["outlier_k"] == 6.0

    printed, report = validate("v3", "--no-recorded-preparation")
    assert "preparation applied: none" in printed and report["preparation"] == {}


def test_identify_reports_the_jitter_and_the_trim(arm, tmp_path, capsys) -> None:
    """A log stepping 10 ms / 12 ms at random: `dynid identify --cutoff` says what it found and
    did (resampled, trimmed) in its output and in result.json's notes; --nonuniform refuse
    is exit 2 with a message saying how to go on."""
    rng = np.random.default_rng(1)
    t = np.concatenate([[0.0], np.cumsum(rng.choice([0.010, 0.012], size=900))])
    w = 2 * np.pi * 0.5
    q = np.column_stack([np.sin(w * t), np.cos(1.3 * w * t)])
    qd = np.column_stack([w * np.cos(w * t), -1.3 * w * np.sin(1.3 * w * t)])
    qdd = np.column_stack([-(w**2) * q[:, 0], -((1.3 * w) ** 2) * q[:, 1]])
    save_log(Log(t=t, q=q, tau=arm.rnea(q, qd, qdd)), tmp_path / "ur.csv")
    argv = ["identify", str(tmp_path / "ur.csv"), "--model", "planar_2r", "--friction"]
    assert main([*argv, "--cutoff", "5", "--output", str(tmp_path / "a")]) == 0
    printed = capsys.readouterr().out
    assert "prepared: time stamps: median step" in printed and "jitter max" in printed
    assert "resampled onto a uniform grid" in printed and "trimmed" in printed
    notes = json.loads((tmp_path / "a" / "result.json").read_text())["training"]["notes"]
    assert any("resampled onto a uniform grid" in note for note in notes)
    assert (
        main([*argv, "--cutoff", "5", "--nonuniform", "refuse", "--output", str(tmp_path / "b")])
        == 2
    )
    err = capsys.readouterr().err
    assert "need a uniform grid" in err and "--nonuniform resample" in err


def test_skip_end_on_the_command_line(arm, tmp_path) -> None:
    log = fourier_log(arm, 1, seconds=4.0)
    save_log(log, tmp_path / "log.npz")
    out = tmp_path / "out"
    argv = ["identify", str(tmp_path / "log.npz"), "--model", "planar_2r", "--friction"]
    assert main([*argv, "--skip", "5", "--skip-end", "20", "--output", str(out)]) == 0
    training = json.loads((out / "result.json").read_text())["training"]
    assert training["samples"] == log.T - 25  # no filter: nothing trimmed
    assert "skipped the last 20 samples" in training["notes"]
