"""Column blocks (dynid.identification.blocks): the identification model built from named
blocks, a new friction model added as one block plus a registration line, and the log's
regressor computed once per ``dynid identify`` run.

The toy block here is a smooth Coulomb friction, tau_f,j = Fc_j tanh(qd_j / V0), a model the
package does not have: it is defined in this file only, registered, identified on an exact
simulated log (torques = RNEA of a robot without friction + this friction, computed here
element by element) and must return the true Fc_j to 1e-9 of the largest base value, be saved,
loaded and validated like the built-in blocks.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result, result_to_dict, save_result
from dynid.identification.blocks import Block, Context, register, unregister
from dynid.identification.log_identification import identify_log, validate_log
from dynid.logs import Log, save_log
from dynid.model.model_files import save_model
from test_blocks_fixture_log import fixture_log
from test_log_identification import fourier_log

N = 7
V0 = 0.05  # rad/s: the velocity scale of the smooth Coulomb law
FC = np.array([0.8, 1.2, 0.4, 0.6, 0.25, 0.3, 0.1])  # N m, the true coefficients


@dataclass(frozen=True)
class SmoothFriction(Block):
    """Toy block: Fc_j tanh(qd_j / V0) in row j, Fc_j >= 0 (a friction that dissipates)."""

    key = "smooth_friction"
    friction_model = "smooth"
    version = 3
    n: int

    @classmethod
    def build(cls, context: Context) -> SmoothFriction | None:
        return cls(context.robot.n) if context.friction == cls.friction_model else None

    @classmethod
    def from_record(cls, options: Mapping[str, Any], n: int) -> SmoothFriction | None:
        return cls(n) if options.get("friction_model") == cls.friction_model else None

    def record(self) -> dict[str, Any]:
        return {"friction_model": self.friction_model, "smooth_velocity": V0}

    def names(self) -> list[str]:
        return [f"Fc{j}" for j in range(1, self.n + 1)]

    def expressions(self) -> list[str]:
        return [f"smooth Coulomb friction of joint {j}" for j in range(1, self.n + 1)]

    def columns(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        columns = np.zeros((q.shape[0], self.n, self.n))
        rows = np.arange(self.n)
        columns[:, rows, rows] = np.tanh(qd / V0)
        return columns

    def nonnegative(self) -> np.ndarray:
        return np.ones(self.n, dtype=bool)


@pytest.fixture
def smooth() -> Iterator[type[SmoothFriction]]:
    register(SmoothFriction)  # the registration line
    yield SmoothFriction
    unregister(SmoothFriction.key)


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    """kuka_lwr4() without its viscous and Coulomb friction: the truth's rigid body and rotors."""
    robot = dynid.models.kuka_lwr4()
    robot.Fv = np.zeros(N)
    robot.Fs = np.zeros(N)
    return robot


def smooth_log(robot: dynid.Robot, seed: int) -> Log:
    log = fourier_log(robot, seed)
    friction = np.zeros_like(log.qd)
    for (t, j), v in np.ndenumerate(log.qd):  # the law by its definition, element by element
        friction[t, j] = FC[j] * np.tanh(v / V0)
    return Log(t=log.t, q=log.q, tau=log.tau + friction, qd=log.qd, qdd=log.qdd, source=log.source)


def test_a_registered_friction_block_is_identified_saved_and_validated(smooth, lwr, tmp_path):
    """identify_log(friction="smooth") has the toy block's columns after the base parameters,
    recovers the true Fc (noise-free: to 1e-9 of the largest base value) and the base values
    beta @ pi; save/load gives an equal result (file version 3, the block's own option); the
    loaded result predicts another log to 1e-9 relative RMS."""
    train, check = smooth_log(lwr, 1), smooth_log(lwr, 4)
    result = identify_log(train, lwr, rotor=True, friction="smooth", method="ols")
    count = result.count
    assert result.names[count:] == [f"Fc{j}" for j in range(1, N + 1)]
    assert result.friction_model == "smooth"
    true_base = dynid.base_parameters(lwr, rotor=True, friction=False).values(lwr)
    scale = np.abs(true_base).max()
    np.testing.assert_allclose(result.theta[:count], true_base, rtol=0, atol=1e-9 * scale)
    where = result.identification_model.slice("smooth_friction")
    np.testing.assert_allclose(result.theta[where], FC, rtol=0, atol=1e-9 * scale)

    path = save_result(result, tmp_path / "ident", plots=False)
    data = json.loads(path.read_text())
    assert data["version"] == 3 and data["options"]["smooth_velocity"] == V0
    assert data["options"]["friction_model"] == "smooth"
    loaded = load_result(path)
    assert loaded == result
    metrics = validate_log(loaded, check)
    assert metrics["relative_rms"].max() < 1e-9


def test_a_registered_friction_block_is_constrained_in_the_physical_fit(smooth, lwr):
    """physical=True keeps the block's coefficients >= 0 (its ``nonnegative``): on data whose
    smooth friction is negative on joint 1 the physical fit gives Fc1 = 0 to the solver's
    tolerance while least squares gives the negative value."""
    pytest.importorskip("cvxpy")
    log = smooth_log(lwr, 1)
    flipped = -2 * FC[0] * np.tanh(log.qd[:, 0] / V0)  # Fc1 -> -Fc1
    tau = log.tau.copy()
    tau[:, 0] += flipped
    log = Log(t=log.t, q=log.q, tau=tau, qd=log.qd, qdd=log.qdd, source="flipped")
    free = identify_log(log, lwr, rotor=True, friction="smooth", method="ols")
    assert free.theta[free.count] == pytest.approx(-FC[0], abs=1e-9)
    physical = identify_log(log, lwr, rotor=True, friction="smooth", physical=True)
    value = physical.theta[physical.identification_model.slice("smooth_friction")][0]
    assert -1e-6 <= value <= 1e-6 + 0.05 * FC[0]


def test_unknown_friction_models_name_the_registered_ones(smooth, lwr):
    log = smooth_log(lwr, 1)
    with pytest.raises(ValueError, match=r"friction: .*'smooth'.*got 'lugre'"):
        identify_log(log, lwr, friction="lugre")


def test_the_model_gives_every_block_its_slice(lwr):
    """IdentificationModel: the blocks' slices tile theta after the base parameters, each with
    the block's names, and the regressor's columns at a slice are the block's columns."""
    log = fourier_log(lwr, 2)
    result = identify_log(
        Log(t=log.t, q=log.q, tau=log.tau + 0.3, qd=log.qd, qdd=log.qdd, source="x"),
        lwr,
        rotor=True,
        friction="asymmetric",
        offset=True,
        position_torque=True,
        method="ols",
    )
    model = result.identification_model
    assert [b.key for b in model.blocks] == ["asymmetric_friction", "offset", "position_torque"]
    Y = result.regressor(log.q, log.qd, log.qdd)
    start = result.count
    for block in model.blocks:
        where = model.slice(block.key)
        assert where == slice(start, start + block.size)
        assert result.names[where] == block.names()
        np.testing.assert_array_equal(Y[..., where], block.columns(log.q, log.qd))
        start += block.size
    assert start == result.theta.size
    np.testing.assert_allclose(result.offsets, 0.3, rtol=0, atol=1e-8)


@pytest.mark.parametrize("physical", [False, True])
def test_dynid_identify_computes_the_logs_regressor_once(lwr, tmp_path, monkeypatch, physical):
    """A spy on dynid.Robot.regressor counts the calls on the training log's samples (the
    position-torque test runs on its own 60 random states): one per run, with and without
    --physical (before the column blocks: 3, and 4 with --physical)."""
    if physical:
        pytest.importorskip("cvxpy")
    model = tmp_path / "lwr.json"
    save_model(dynid.models.kuka_lwr4(), model)
    log = fourier_log(dynid.models.kuka_lwr4(), 1, seconds=4.0)
    save_log(log, tmp_path / "train.npz")
    calls: list[int] = []
    original = dynid.Robot.regressor

    def counted(self: dynid.Robot, q: Any, *args: Any, **kwargs: Any) -> np.ndarray:
        calls.append(np.shape(q)[0])
        return original(self, q, *args, **kwargs)

    monkeypatch.setattr(dynid.Robot, "regressor", counted)
    argv = ["identify", str(tmp_path / "train.npz"), "--model", str(model), "--rotor"]
    argv += ["--friction", "--offset", "--position-torque", "--output", str(tmp_path / "out")]
    argv += ["--physical"] if physical else []
    assert main(argv) == 0
    assert calls.count(log.T) == 1
    assert (tmp_path / "out" / "torques.png").is_file()


BEFORE = Path(__file__).resolve().parent / "data" / "results_before_blocks"
FIXTURE_OPTIONS = {
    "asymmetric": {
        "rotor": True,
        "friction": "asymmetric",
        "offset": True,
        "position_torque": True,
    },
    "symmetric": {"friction": True, "position_torque": True, "method": "ols"},
}


@pytest.mark.parametrize("name", sorted(FIXTURE_OPTIONS))
def test_results_written_before_the_blocks_load_and_are_reproduced(name):
    """tests/data/results_before_blocks/*.json were written by dynid 0.2 before the column
    blocks (tests/test_blocks_fixture_log.py's log, models.planar_2r()): they load, and the
    same identification today gives the same coefficients, standard deviations and training
    fit to 1e-12 and the same file content (the dynid version aside); the symmetric model's
    standard deviations are now the correlation-robust ones (its residuals are model error)."""
    robot = dynid.models.planar_2r()
    before = json.loads((BEFORE / f"{name}.json").read_text())
    loaded = load_result(BEFORE / f"{name}.json")
    now = identify_log(fixture_log(robot), robot, **FIXTURE_OPTIONS[name])
    assert loaded.names == now.names and loaded.blocks == now.blocks
    np.testing.assert_allclose(now.theta, loaded.theta, rtol=1e-12, atol=1e-15)
    correlated = any("residuals are correlated" in note for note in now.training["notes"])
    if correlated:
        # The symmetric model misses the log's asymmetric friction and position torque: its
        # residuals are model error, correlated in time, and since the files were written the
        # standard deviations account for that (larger than the independent-samples ones).
        assert name == "symmetric" and np.all(now.std >= loaded.std)
    else:
        np.testing.assert_allclose(now.std, loaded.std, rtol=1e-12, atol=1e-15)
    for key, value in loaded.training["metrics"].items():
        np.testing.assert_allclose(now.training["metrics"][key], value, rtol=1e-12, atol=1e-15)
    log = fixture_log(robot)
    np.testing.assert_allclose(now.predict(log), loaded.predict(log), rtol=0, atol=1e-12)
    assert correlated or now.summary() == loaded.summary()
    data = json.loads(json.dumps(result_to_dict(now)))
    for key in ("dynid_version", "coefficients", "covariance", "training", "condition_number"):
        data.pop(key), before.pop(key)
    assert data == before
