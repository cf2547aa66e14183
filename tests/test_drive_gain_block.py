"""The drive gains as a block (dynid.identification.blocks.drive_gains) and the unknowns of the
identification from currents (dynid.identification.drive_gain_system.CurrentModel).

The runs are those of tests/test_drive_gains.py: currents i = tau / k_true with tau from
Pinocchio's RNEA of the LWR written as URDF plus the drive terms, so the truth (base values
beta @ pi, k_true, the payload's parameters from its mass, centre of mass and inertia) is
independent of the regressor these tests check.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.identification.blocks.base import Context
from dynid.identification.blocks.drive_gains import DriveGains
from dynid.identification.blocks.model import IdentificationModel, kept
from dynid.identification.blocks.registry import build_blocks
from dynid.identification.blocks.rigid_body import RigidBody
from dynid.identification.drive_gain_system import PAYLOAD, TORQUE, CurrentModel
from dynid.identification.drive_gains import identify_drive_gains
from dynid.identification.payload import PAYLOAD_NAMES
from test_drive_gains import (
    COM,
    INERTIA,
    K_TRUE,
    MASS,
    current_log,
    pinocchio_torques,
    truth,
)
from test_drive_gains import (
    PAYLOAD as PAYLOAD_GIVEN,
)
from test_log_identification import fourier_log


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    return dynid.models.kuka_lwr4()


@pytest.fixture(scope="module")
def runs(lwr):
    loaded_arm = lwr.with_payload(MASS, COM, INERTIA)
    unloaded, loaded = fourier_log(lwr, 1), fourier_log(lwr, 2)
    return (
        current_log(unloaded, pinocchio_torques(lwr, unloaded)),
        current_log(loaded, pinocchio_torques(loaded_arm, loaded)),
    )


def payload_parameters() -> np.ndarray:
    """pi_L about the last frame's origin, by the parallel-axis theorem (not dynid's code)."""
    m, c = MASS, COM
    inertia = INERTIA + m * (c @ c * np.eye(3) - np.outer(c, c))
    return np.array([m, *(m * c), *inertia[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]])


def current_model(robot: dynid.Robot, estimated: tuple[int, ...] = ()) -> CurrentModel:
    base = dynid.base_parameters(robot, rotor=True, friction=True)
    rigid = RigidBody(robot, True, True, base.independent)
    known = payload_parameters()
    known[list(estimated)] = 0.0
    return CurrentModel(IdentificationModel(rigid, ()), DriveGains(robot.n), known, estimated)


@pytest.mark.parametrize("loaded", [False, True])
def test_rows_vanish_at_the_truth(lwr, runs, loaded):
    """[Y | -diag(i) | Y_n,est] x = b holds at the true x on exact currents (Pinocchio)."""
    log = runs[int(loaded)]
    estimated = (1, 2, 3) if loaded else ()
    system = current_model(lwr, estimated)
    x = np.zeros(system.size)
    x[system.slice(TORQUE)] = truth(lwr)
    x[system.slice("drive_gains")] = K_TRUE
    x[system.slice(PAYLOAD)] = payload_parameters()[list(estimated)]
    A, b = system.rows(log.q, log.qd, log.qdd, log.tau, loaded)
    assert A.shape == (log.T, lwr.n, system.size) and b.shape == (log.T, lwr.n)
    scale = np.abs(K_TRUE * log.tau).max()
    np.testing.assert_allclose(A @ x, b, rtol=0, atol=1e-9 * scale)
    if not loaded:
        assert not b.any()


def test_groups_partition_the_unknowns(lwr):
    system = current_model(lwr, (1, 2, 3))
    names = system.names([f"theta{i}" for i in range(system.torque.size)])
    assert len(names) == system.size == system.torque.size + lwr.n + 3
    assert names[system.slice("drive_gains")] == [f"k{j}" for j in range(1, 8)]
    assert names[system.slice(PAYLOAD)] == [PAYLOAD_NAMES[c] for c in (1, 2, 3)]
    assert names[system.slice(TORQUE)] == [f"theta{i}" for i in range(system.torque.size)]
    with pytest.raises(ValueError, match="key: expected one of torque, drive_gains, payload"):
        system.slice("gains")


def test_block_columns_and_torque():
    current = np.array([[1.0, -2.0, 3.0], [0.5, 0.0, -1.5]])
    gains = np.array([10.0, 12.0, 8.0])
    block = DriveGains(3)
    C = block.columns(current)
    # Row j of a sample: -i_j in the column of k_j, zero elsewhere.
    for t in range(2):
        for j in range(3):
            expected = np.zeros(3)
            expected[j] = -current[t, j]
            np.testing.assert_array_equal(C[t, j], expected)
    np.testing.assert_array_equal(block.torque(current, gains), current * gains)
    np.testing.assert_array_equal(C @ gains + block.torque(current, gains), 0.0)
    assert block.names() == ["k1", "k2", "k3"] and block.size == 3


@pytest.mark.parametrize(
    ("report", "message"),
    [
        ({"gains": [1.0, 2.0]}, r"drive_gains.gains: expected 3 finite gains"),
        ({"gains": [1.0, 2.0, float("nan")]}, r"drive_gains.gains: expected 3 finite gains"),
        ({"gains": [1.0, True, 2.0]}, r"drive_gains.gains: expected numbers"),
        ({"gains": "abc"}, r"drive_gains.gains: expected"),
        ({"method": "nls"}, r"drive_gains.gains: missing"),
        ([1, 2, 3], r"drive_gains: expected an object"),
    ],
)
def test_block_record_errors(report, message):
    with pytest.raises(ValueError, match=message):
        DriveGains.from_record({"drive_gains": report}, 3)


def test_block_record_round_trip():
    report = {"gains": [1.0, 2.0, 3.0], "method": "tls"}
    block = DriveGains(3)
    assert DriveGains.from_record(block.record(report), 3) == report
    assert DriveGains.from_record({}, 3) is None


def test_column_blocks_with_currents(lwr, runs):
    """The column blocks of identify_log work with currents too: asymmetric friction and a
    position torque on exact data give the true gains, Fv+ = Fv- = Fv, Fs+ = Fs- = Fs, and a
    zero position torque (there is none in the data)."""
    unloaded, loaded = runs
    fit = identify_drive_gains(
        lwr,
        unloaded,
        loaded,
        payload=PAYLOAD_GIVEN,
        rotor=True,
        friction="asymmetric",
        position_torque=True,
        method="wls",
    )
    np.testing.assert_allclose(fit.gains, K_TRUE, rtol=1e-8)
    result = fit.result
    assert result.friction_model == "asymmetric" and not result.friction
    coefficients = dict(zip(result.names, result.theta))
    for j in range(1, lwr.n + 1):
        Fv, Fs = lwr.Fv[j - 1], lwr.Fs[j - 1]
        for sign in "+-":
            assert coefficients[f"Fv{j}{sign}"] == pytest.approx(Fv, rel=1e-7, abs=1e-8)
            assert coefficients[f"Fs{j}{sign}"] == pytest.approx(Fs, rel=1e-7, abs=1e-8)
    where = result.identification_model.slice("position_torque")
    assert where is not None and where.stop > where.start
    np.testing.assert_allclose(result.theta[where], 0.0, atol=1e-7)
    context = Context(lwr, True, "asymmetric", False, True)
    assert [b.key for b in result.blocks] == [b.key for b in kept(build_blocks(context))]
