"""Non-uniform time scaling (notes p. 37; dynid.motion.nonuniform_scaling): the torque of a
path executed with a timing r(t) from the path's stored parts equals the inverse dynamics of
the re-timed trajectory, computed directly (its derivatives by the chain rule, and separately by
finite differences of q(t) = q_s(r(t))), and the uniform case equals time_scaling's."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.motion.nonuniform_scaling import path_torques, retimed_torques
from dynid.motion.time_scaling import scale_torques

W = 2 * np.pi * 0.25


def path(r):
    """A smooth 7-joint path q_s(r) and its first two derivatives in r."""
    k = np.arange(1, 8)
    q = 0.4 * np.sin(W * np.outer(r, k) / 3 + k)
    dq = 0.4 * (W * k / 3) * np.cos(W * np.outer(r, k) / 3 + k)
    ddq = -0.4 * (W * k / 3) ** 2 * np.sin(W * np.outer(r, k) / 3 + k)
    return q, dq, ddq


def timing(t):
    """r(t) = t + 0.3 sin(1.7 t): strictly increasing (r' >= 0.49)."""
    return t + 0.3 * np.sin(1.7 * t), 1 + 0.51 * np.cos(1.7 * t), -0.867 * np.sin(1.7 * t)


@pytest.fixture(scope="module")
def lwr():
    return dynid.models.kuka_lwr4()  # with Ia, Fv, Fs


def test_retimed_torque_equals_direct_inverse_dynamics(lwr) -> None:
    t = np.linspace(0.0, 4.0, 200)
    r, rd, rdd = timing(t)
    q, dq, ddq = path(r)
    got = retimed_torques(path_torques(lwr, q, dq, ddq), rd, rdd)
    direct = lwr.rnea(q, dq * rd[:, None], ddq * rd[:, None] ** 2 + dq * rdd[:, None])
    assert np.max(np.abs(got - direct)) <= 1e-12 * np.max(np.abs(direct))


def test_the_chain_rule_itself_by_finite_differences(lwr) -> None:
    """qd, qdd of q(t) = q_s(r(t)) by central differences (h = 1e-4: error ~1e-8): the
    inverse dynamics at them matches the re-timed torque to the differences' accuracy."""
    t = np.linspace(0.2, 3.8, 50)
    h = 1e-4
    q_of = lambda s: path(timing(s)[0])[0]  # noqa: E731
    qd = (q_of(t + h) - q_of(t - h)) / (2 * h)
    qdd = (q_of(t + h) - 2 * q_of(t) + q_of(t - h)) / h**2
    r, rd, rdd = timing(t)
    got = retimed_torques(path_torques(lwr, *path(r), friction=True), rd, rdd)
    direct = lwr.rnea(q_of(t), qd, qdd)
    assert np.max(np.abs(got - direct)) <= 1e-5 * np.max(np.abs(direct))


def test_uniform_scaling_is_the_special_case(lwr) -> None:
    k = 1.7  # t' = k t: r(t') = t' / k
    r = np.linspace(0.0, 3.0, 80)
    q, dq, ddq = path(r)
    tau = lwr.rnea(q, dq, ddq)
    expected = scale_torques(tau, lwr.gravity(q), k, qd=dq, robot=lwr)
    got = retimed_torques(path_torques(lwr, q, dq, ddq), np.full(r.size, 1 / k), np.zeros(r.size))
    assert np.max(np.abs(got - expected)) <= 1e-12 * np.max(np.abs(expected))


def test_without_friction_is_the_notes_formula(lwr) -> None:
    r = np.linspace(0.0, 2.0, 30)
    q, dq, ddq = path(r)
    rigid = lwr.copy()
    rigid.Fv = rigid.Fs = np.zeros(7)
    _, rd, rdd = timing(r)
    got = retimed_torques(path_torques(lwr, q, dq, ddq, friction=False), rd, rdd)
    direct = rigid.rnea(q, dq * rd[:, None], ddq * rd[:, None] ** 2 + dq * rdd[:, None])
    assert np.max(np.abs(got - direct)) <= 1e-12 * np.max(np.abs(direct))


def test_bad_input_is_named(lwr) -> None:
    q, dq, ddq = path(np.linspace(0, 1, 5))
    parts = path_torques(lwr, q, dq, ddq)
    with pytest.raises(ValueError, match="rd: the timing r"):
        retimed_torques(parts, np.array([1, 1, 0, 1, 1.0]), np.zeros(5))
    with pytest.raises(ValueError, match=r"rdd: expected shape \(5,\)"):
        retimed_torques(parts, np.ones(5), np.zeros(4))
    with pytest.raises(ValueError, match=r"dq: expected the shape of q"):
        path_torques(lwr, q, dq[:, :3], ddq)
