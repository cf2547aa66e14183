"""Joints at rest (dynid.logs.rest, prepare_log's rest_velocity, --rest-velocity): velocities
below the rest velocity set to exactly 0, so that Coulomb friction there is Fs sign(0) = 0.

The "auto" estimate is checked against its definition on an angle quantized to a known count
(2 pi f_c delta, delta the count); the effect on a prediction against the closed form of the
friction law on a log that stands still with a toggling encoder."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
import dynid.cli
from dynid.logs.rest import rest_velocity


def quantized_log(count: float = 1e-4, fs: float = 1000.0) -> dynid.Log:
    """Two joints: a sine for 2 s, then standing still for 1 s with the encoder toggling by one
    count every few samples (as a real encoder at rest); angles quantized to ``count``."""
    t = np.arange(int(3 * fs)) / fs
    moving = t < 2.0
    q = np.zeros((t.size, 2))
    q[:, 0] = np.where(moving, 0.5 * np.sin(np.pi * t), 0.0)
    q[:, 1] = np.where(moving, 0.3 * (1 - np.cos(np.pi * t)), 0.0)
    rng = np.random.default_rng(0)
    q[~moving] += count * (rng.random((int((~moving).sum()), 2)) < 0.2)  # toggles by one count
    q = np.round(q / count) * count
    return dynid.Log(t=t, q=q, tau=np.zeros_like(q))


def test_auto_is_one_count_at_the_cutoff():
    log = quantized_log(count=1e-4)
    v = rest_velocity("auto", log.q, log.fs, 20.0)
    np.testing.assert_allclose(v, 2 * np.pi * 20.0 * 1e-4, rtol=1e-9)
    # without a filter: a quarter of one count per sample (the velocity is 0 or >= fs delta / 2)
    np.testing.assert_allclose(rest_velocity("auto", log.q, log.fs, None), 250.0 * 1e-4, rtol=1e-9)
    np.testing.assert_array_equal(rest_velocity(0.5, log.q, log.fs, None), [0.5, 0.5])
    np.testing.assert_array_equal(rest_velocity([0.1, 0.2], log.q, log.fs, None), [0.1, 0.2])


def test_a_smooth_angle_gets_no_rest_velocity():
    """A simulated, unquantized angle has no recurring step: its 1st percentile step is only the
    speed 99 % of the samples exceed, so "auto" leaves it alone (0), filtered or not."""
    t = np.arange(3000) / 1000.0
    q = np.column_stack([0.5 * np.sin(np.pi * t), 0.3 * np.cos(2.0 * t) + 0.01 * t**2])
    for cutoff in (None, 20.0):
        np.testing.assert_array_equal(rest_velocity("auto", q, 1000.0, cutoff), [0.0, 0.0])
    log = dynid.Log(t=t, q=q, tau=np.zeros_like(q))
    np.testing.assert_array_equal(
        dynid.prepare_log(log, cutoff=20.0, rest_velocity="auto").qd,
        dynid.prepare_log(log, cutoff=20.0).qd,
    )


def test_at_rest_the_coulomb_term_vanishes():
    """With rest_velocity the standing part has qd = 0 exactly, so the friction law predicts
    Fv*0 + Fs*sign(0) = 0 there; without it, the toggling encoder makes +-Fs at random."""
    log = quantized_log()
    options = {"cutoff": 20.0}
    plain = dynid.prepare_log(log, **options)
    rested = dynid.prepare_log(log, **options, rest_velocity="auto")
    assert rested.T == plain.T
    standing = (rested.t > 2.3) & (rested.t < 2.9)
    assert np.all(rested.qd[standing] == 0.0)
    assert np.any(plain.qd[standing] != 0.0)
    moving = (rested.t > 0.2) & (rested.t < 1.8)
    fast = np.abs(plain.qd[moving]) > 0.05
    np.testing.assert_array_equal(rested.qd[moving][fast], plain.qd[moving][fast])
    Fs = 2.0
    coulomb = Fs * np.sign(rested.qd[standing])  # the law, written out
    assert not coulomb.any()
    assert "joints at rest: qd_j = 0 where |qd_j| <" in rested.notes[-1]


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (-0.1, "rest_velocity: expected values >= 0"),
        ([0.1, 0.2, 0.3], r"rest_velocity: expected a scalar or 2 values"),
        ("fast", "rest_velocity: expected 'auto' or a velocity"),
    ],
)
def test_bad_rest_velocity(value, message):
    with pytest.raises(ValueError, match=message):
        dynid.prepare_log(quantized_log(), rest_velocity=value)


def test_cli_option(tmp_path, capsys):
    log = quantized_log()
    robot = dynid.models.planar_2r()
    tau = robot.rnea(log.q, np.gradient(log.q, log.t, axis=0), np.zeros_like(log.q))
    path = tmp_path / "log.npz"
    dynid.save_log(log.replace(tau=tau), path)
    argv = ["identify", str(path), "--model", "planar_2r", "--cutoff", "20"]
    assert dynid.cli.main([*argv, "--rest-velocity", "auto", "--output", str(tmp_path / "a")]) == 0
    assert "joints at rest" in capsys.readouterr().out
    result = dynid.load_result(tmp_path / "a")
    assert result.training["preparation"]["rest_velocity"] == "auto"
    with pytest.raises(SystemExit) as stopped:  # argparse's usage error
        dynid.cli.main([*argv, "--rest-velocity", "slow", "--output", str(tmp_path / "b")])
    assert stopped.value.code == 2
    assert "expected a velocity or 'auto'" in capsys.readouterr().err
