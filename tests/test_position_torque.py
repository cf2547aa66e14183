"""The position-torque option (dynid.position_torque; identify_log(position_torque=True)).

Synthetic, exact logs: torques from the robot's RNEA (rigid body, rotor, friction) plus known
offsets and a known ks_j sin q_j + kc_j cos q_j per joint, on the 3-harmonic trajectories of
tests/test_log_identification.py. Both fits must return the known coefficients; the joints left
out are those where the closed form says sin q, cos q are gravity columns.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.export.result_files import load_result, save_result
from dynid.identification.log_identification import identify_log
from dynid.identification.position_torque import (
    position_columns,
    position_names,
    position_torque_joints,
)
from dynid.logs import Log
from test_log_identification import fourier_log

KS = np.array([0.3, 0.0, -0.2, 0.5, 0.1, -0.4, 0.35])
KC = np.array([-0.25, 0.0, 0.15, -0.3, 0.2, 0.1, 0.3])
OFFSET = np.linspace(-0.5, 0.5, 7)


def pendulum(axis_vertical: bool) -> dynid.Robot:
    """One revolute joint: gravity along -z0 (the joint axis) or along -y0 (across it)."""
    gravity = [0.0, 0.0, -9.81] if axis_vertical else [0.0, -9.81, 0.0]
    return dynid.Robot.from_dh(
        [[0.4, 0.0, 0.0, 0.0]],
        gravity=gravity,
        params=[[2.0, 0.3, 0.05, 0.0, 0.1, 0.0, 0.0, 0.2, 0.0, 0.25]],
    )


def test_pendulum_position_torque_is_gravity_only_when_the_axis_is_horizontal():
    """Closed form: a pendulum across gravity has tau = ... + g (c1 cos q + c2 sin q) with
    c1, c2 its first moments, exactly the two position-torque columns, so they are left out;
    with the axis along gravity there is no gravity torque and they are kept."""
    for vertical, expected in ((True, ((0,), ())), (False, ((), (0,)))):
        assert position_torque_joints(pendulum(vertical), True, True, True) == expected


def test_lwr4_leaves_out_joint_2():
    """kuka_lwr4(): joint 1 vertical (no gravity torque), joint 2 the first horizontal axis:
    its row's gravity is a sin q2 + b cos q2 plus terms in q3..q7. Checked independently of the
    rank test: sin q2 and cos q2 in row 2 are fitted exactly (residual < 1e-9 of their norm) by
    the base columns at random states, sin q7 in row 7 is not (residual > 10 %)."""
    lwr = dynid.models.kuka_lwr4()
    assert position_torque_joints(lwr, True, True, True) == ((0, 2, 3, 4, 5, 6), (1,))
    q = lwr.random_configurations(80, seed=3)
    qd, qdd = np.random.default_rng(5).uniform(-1, 1, (2, 80, 7))
    base = dynid.base_parameters(lwr, rotor=True, friction=True)
    A = lwr.regressor(q, qd, qdd, rotor=True, friction=True)[..., base.independent]
    A = A.reshape(-1, A.shape[2])
    for j, k, fitted in ((1, 0, True), (1, 1, True), (6, 0, False)):
        b = position_columns(q, (j,))[..., k].reshape(-1)
        x = np.linalg.lstsq(A, b, rcond=None)[0]
        ratio = np.linalg.norm(A @ x - b) / np.linalg.norm(b)
        assert (ratio < 1e-9) if fitted else (ratio > 0.1), (j, k, ratio)


def test_columns_and_names():
    q = np.array([[0.1, 0.2, 0.3], [1.0, -2.0, 0.5]])
    Y = position_columns(q, (0, 2))
    assert Y.shape == (2, 3, 4)
    np.testing.assert_array_equal(Y[:, 0, 0], np.sin(q[:, 0]))
    np.testing.assert_array_equal(Y[:, 0, 1], np.cos(q[:, 0]))
    np.testing.assert_array_equal(Y[:, 2, 2], np.sin(q[:, 2]))
    np.testing.assert_array_equal(Y[:, 2, 3], np.cos(q[:, 2]))
    assert np.count_nonzero(Y[:, 1]) == 0 and np.count_nonzero(Y[:, 0, 2:]) == 0
    assert position_names((0, 2))[0] == ["ks1", "kc1", "ks3", "kc3"]


def log_with_position_torque(robot: dynid.Robot, seed: int) -> Log:
    log = fourier_log(robot, seed, offset=OFFSET)
    extra = KS * np.sin(log.q) + KC * np.cos(log.q)
    extra[:, 1] = 0.0  # joint 2: not identifiable apart from gravity (test above)
    return Log(t=log.t, q=log.q, tau=log.tau + extra, qd=log.qd, qdd=log.qdd, source=log.source)


@pytest.fixture(scope="module")
def lwr():
    return dynid.models.kuka_lwr4()


@pytest.mark.parametrize("physical", [False, True])
def test_known_position_torque_is_recovered(lwr, physical):
    """Exact log of a consistent robot plus offsets plus position torque: the least squares
    recover base values, offsets and ks, kc to 1e-8 of the largest base value (exact
    arithmetic); the physically consistent fit (no prior: the robot itself is feasible, its
    margin 1e-6 is the only bias) to 1e-4, and its prediction to 1e-4 of the torques."""
    log = log_with_position_torque(lwr, 1)
    kwargs = {"physical": True} if physical else {}
    result = identify_log(
        log,
        lwr,
        rotor=True,
        friction=True,
        offset=True,
        method="ols",
        position_torque=True,
        **kwargs,
    )
    assert result.position_joints == (0, 2, 3, 4, 5, 6)
    assert any("not on joint(s) 2" in note for note in result.training["notes"])
    joints = list(result.position_joints)
    truth = np.column_stack([KS[joints], KC[joints]]).reshape(-1)
    assert result.names[-truth.size :] == [
        "ks1",
        "kc1",
        "ks3",
        "kc3",
        "ks4",
        "kc4",
        "ks5",
        "kc5",
        "ks6",
        "kc6",
        "ks7",
        "kc7",
    ]
    expected = dynid.base_parameters(lwr, rotor=True, friction=True).values(lwr)
    scale = np.abs(expected).max()
    tolerance = 1e-4 if physical else 1e-8
    np.testing.assert_allclose(result.theta[-truth.size :], truth, rtol=0, atol=tolerance * scale)
    np.testing.assert_allclose(
        result.theta[-truth.size - 7 : -truth.size], OFFSET, rtol=0, atol=tolerance * scale
    )
    if not physical:
        np.testing.assert_allclose(
            result.theta[: expected.size], expected, rtol=0, atol=1e-8 * scale
        )
    other = log_with_position_torque(lwr, 4)
    np.testing.assert_allclose(
        result.predict(other), other.tau, rtol=0, atol=tolerance * np.abs(other.tau).max()
    )


def test_save_and_load_keep_the_position_torque(lwr, tmp_path):
    result = identify_log(
        log_with_position_torque(lwr, 1),
        lwr,
        rotor=True,
        friction=True,
        offset=True,
        position_torque=True,
    )
    loaded = load_result(save_result(result, tmp_path / "out"))
    assert loaded.position_joints == result.position_joints and loaded.position_torque
    other = fourier_log(lwr, 4, seconds=1.0)
    np.testing.assert_array_equal(loaded.predict(other), result.predict(other))
    assert loaded.summary() == result.summary()
    assert "position torque on joint(s) 1, 3, 4, 5, 6, 7" in result.summary()


def test_bad_position_torque_argument(lwr):
    log = fourier_log(lwr, 1, seconds=1.0)
    with pytest.raises(ValueError, match="position_torque: expected True or False"):
        identify_log(log, lwr, position_torque="yes")
