"""The motors on the chain (notes pp. 12-13; dynid.model.motors): the motor-side model, and the
rotors' gyroscopic coupling against a model with the rotors as extra spinning bodies.

The reference: rotor i (axial inertia I_i, gear ratio n_i) on link i - 1 spins at
s_i = z_i . omega_{i-1} + n_i qd_i, omega_{i-1} the angular velocity of link i - 1 (from the
geometric Jacobian's angular rows, summed over the joints before i). Its kinetic energy beyond
the spinning term and the link's own is L_i = 1/2 I_i (s_i^2 - (n_i qd_i)^2 - (z_i . omega)^2);
the torque is d/dt dL/dqd - dL/dq, every derivative by central differences (no B_g, no
Christoffel symbol of the module)."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.model.motors import gyroscopic_inertia, gyroscopic_torque, motor_side

RATIOS = np.array([100.0, 100.0, 80.0, 80.0, 60.0, 60.0, 50.0])
ROTORS = np.array([3e-4, 3e-4, 2e-4, 2e-4, 1e-4, 1e-4, 5e-5])


def _extra_energy(robot: dynid.Robot, q: np.ndarray, qd: np.ndarray) -> float:
    J = robot.jacobian(q)
    energy = 0.0
    for i in range(robot.n):
        z = J[3:, i]
        omega = J[3:, :i] @ qd[:i]  # link i - 1's angular velocity
        spin = z @ omega + RATIOS[i] * qd[i]
        energy += 0.5 * ROTORS[i] * (spin**2 - (RATIOS[i] * qd[i]) ** 2 - (z @ omega) ** 2)
    return energy


def _path(t: float) -> tuple[np.ndarray, np.ndarray]:
    w = np.arange(1, 8) * 0.7
    return 0.6 * np.sin(w * t + 0.3), 0.6 * w * np.cos(w * t + 0.3)


def test_gyroscopic_torque_equals_the_rotors_lagrangian() -> None:
    robot = dynid.models.kuka_lwr4()
    t, h, e = 0.4, 1e-4, 1e-5
    q, qd = _path(t)
    w = np.arange(1, 8) * 0.7
    qdd = -0.6 * w**2 * np.sin(w * t + 0.3)

    def momentum(time: float) -> np.ndarray:  # dL/dqd along the path (L quadratic in qd)
        qt, qdt = _path(time)
        return np.array(
            [
                (_extra_energy(robot, qt, qdt + e * u) - _extra_energy(robot, qt, qdt - e * u))
                / (2 * e)
                for u in np.eye(7)
            ]
        )

    dp = (momentum(t + h) - momentum(t - h)) / (2 * h)
    dq = np.array(
        [
            (_extra_energy(robot, q + e * u, qd) - _extra_energy(robot, q - e * u, qd)) / (2 * e)
            for u in np.eye(7)
        ]
    )
    reference = dp - dq
    got = gyroscopic_torque(robot, q, qd, qdd, ROTORS, RATIOS)[0]
    assert np.max(np.abs(got - reference)) <= 1e-5 * np.max(np.abs(reference))
    assert np.max(np.abs(reference)) > 1e-3  # not a vanishing effect: ~n I qd^2


def test_gyroscopic_inertia_is_the_energy_and_vanishes_for_parallel_axes() -> None:
    robot = dynid.models.kuka_lwr4()
    q, qd = _path(1.1)
    B = gyroscopic_inertia(robot, q, ROTORS, RATIOS)
    assert np.allclose(B, B.T) and np.allclose(np.diag(B), 0)
    assert abs(0.5 * qd @ B @ qd - _extra_energy(robot, q, qd)) <= 1e-12
    planar = dynid.models.planar_2r()  # both axes along z: B_g12 = n_2 I_2, constant, c_g = 0
    Bp = gyroscopic_inertia(planar, [0.3, 1.2], [1e-3, 2e-3], [50.0, 40.0])
    np.testing.assert_allclose(Bp, [[0.0, 0.08], [0.08, 0.0]], rtol=1e-12)
    tau = gyroscopic_torque(planar, [0.3, 1.2], [1.0, -2.0], [0.5, 0.1], [1e-3, 2e-3], [50, 40])
    np.testing.assert_allclose(tau[0], [0.08 * 0.1, 0.08 * 0.5], rtol=1e-12)


def test_motor_side_model() -> None:
    """tau_m = tau / n, and the inertia each motor sees is I_m + b_ii / n^2 (p. 13): with Ia =
    I_m n^2, the diagonal of M divided by n^2."""
    robot = dynid.models.kuka_lwr4()
    q, qd = _path(0.7)
    qdd = np.linspace(-1, 1, 7)
    tau_m, inertia = motor_side(robot, q, qd, qdd, RATIOS)
    np.testing.assert_allclose(tau_m, robot.rnea(q, qd, qdd) / RATIOS, rtol=1e-14)
    B = robot.rigid_body().mass_matrix(q)  # links only
    np.testing.assert_allclose(inertia, robot.Ia / RATIOS**2 + np.diag(B) / RATIOS**2, rtol=1e-12)
    with pytest.raises(ValueError, match="gear_ratios: expected non-zero"):
        motor_side(robot, q, qd, qdd, np.zeros(7))
    with pytest.raises(ValueError, match="motor_inertias: expected values >= 0"):
        gyroscopic_inertia(robot, q, -ROTORS, RATIOS)
