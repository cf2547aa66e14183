"""The transmission coupling T as part of a Robot (docs/transmission.md): default, setting,
copies, pickling, equality, model files, URDF export, rigid_body, link_frames, derived helpers
(time scaling, stable substeps). Exact comparisons unless stated."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import dynid
import dynid.model.model_files
from coupled_robots import T_WRIST, coupled_puma
from dynid.model.model_files import load_model, model_to_dict, save_model


def test_default_is_the_identity_and_read_only() -> None:
    robot = dynid.models.puma560()
    assert robot.transmission.shape == (6, 6)
    assert np.array_equal(robot.transmission, np.eye(6))
    with pytest.raises(ValueError, match="read-only"):
        robot.transmission[0, 1] = 1.0  # a read-only copy: change it by assignment


def test_from_dh_keyword_and_none_resets() -> None:
    T = np.array([[1.0, 0.0], [1.0, 1.0]])
    robot = dynid.Robot.from_dh([[1, 0, 0, 0], [1, 0, 0, 0]], transmission=T)
    assert np.array_equal(robot.transmission, T)
    robot.transmission = None
    assert np.array_equal(robot.transmission, np.eye(2))


def test_copy_pickle_and_equality_include_the_transmission() -> None:
    robot = coupled_puma()
    for other in (robot.copy(), pickle.loads(pickle.dumps(robot))):
        assert np.array_equal(other.transmission, robot.transmission)
        assert other == robot
    plain = dynid.models.puma560()
    assert plain != robot  # differs only in T
    # A robot pickled before the transmission existed (no key in its state) is decoupled.
    state = plain._state()
    del state["transmission"]
    restored = dynid.model.robot._robot_from_state(state)
    assert restored == plain


def test_model_file_round_trip(tmp_path) -> None:
    robot = coupled_puma()
    path = save_model(robot, tmp_path / "coupled.json")
    loaded = load_model(path)
    assert np.array_equal(loaded.transmission, robot.transmission)
    assert loaded == robot
    # A decoupled robot's file has no transmission field (files stay as they were).
    assert "transmission" not in model_to_dict(dynid.models.puma560())
    data = model_to_dict(robot)
    data["transmission"] = [[1.0, 0.0], [0.0, 1.0]]
    with pytest.raises(ValueError, match="transmission"):
        dynid.model.model_files.model_from_dict(data)


def test_to_urdf_refuses_coupled_drives_and_rigid_body_drops_them() -> None:
    robot = dynid.models.kuka_lwr4()  # the PUMA's massless link 1 cannot be a URDF link
    T = np.eye(7)
    T[4:, 4:] = T_WRIST
    robot.transmission = T
    with pytest.raises(ValueError, match=r"^transmission: .*save_model"):
        robot.to_urdf()
    links = robot.rigid_body()
    assert np.array_equal(links.transmission, np.eye(7))
    assert not links.Ia.any() and not links.Fv.any() and not links.Fs.any()
    assert "<robot" in links.to_urdf()
    q = np.linspace(-1, 1, 7)
    expected = dynid.models.kuka_lwr4().rigid_body().mass_matrix(q)
    np.testing.assert_array_equal(links.mass_matrix(q), expected)


def test_model_summary_shows_a_coupled_transmission() -> None:
    from dynid.export.summary import model_summary

    assert "transmission" not in model_summary(dynid.models.puma560())
    text = model_summary(coupled_puma())
    assert "transmission T (motor velocities T qd; Ia, Fv, Fs per motor):" in text
    assert "   -0.15      0.3        1" in text  # the last row of the wrist block


def test_with_payload_keeps_the_transmission() -> None:
    robot = coupled_puma()
    assert np.array_equal(robot.with_payload(1.0, [0, 0, 0.1]).transmission, robot.transmission)


def test_time_scaling_of_coupled_torques_is_rnea_of_the_scaled_motion() -> None:
    """scale_torques(k) of a coupled robot's torques equals rnea at (q, qd / k, qdd / k^2): the
    motor friction T^T Fv T qd scales as 1/k and T^T Fs sign(T qd) not at all (1e-12)."""
    from dynid.motion import time_scaling

    robot = coupled_puma()
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.normal(size=(3, 5, 6))
    tau = robot.rnea(q, qd, qdd)
    for k in (0.5, 2.0):
        scaled = time_scaling.scale_torques(tau, robot.gravity(q), k, qd=qd, robot=robot)
        expected = robot.rnea(q, qd / k, qdd / k**2)
        np.testing.assert_allclose(scaled, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_stable_substeps_sees_the_coupled_damping() -> None:
    """The wrist's coupled Coulomb band makes a stiffer damping T^T diag(Fs / band) T than
    the decoupled diagonal; the step count follows the largest eigenvalue of M^-1 D, computed
    here directly."""
    from dynid.sim.virtual_controller import stable_substeps

    robot = coupled_puma()
    q = np.zeros(6)
    T = robot.transmission
    D = T.T @ np.diag(robot.Fv + robot.Fs / 1e-3) @ T + np.diag(np.full(6, 2.0))
    rate = np.max(np.linalg.eigvals(np.linalg.solve(robot.mass_matrix(q), D)).real)
    assert stable_substeps(robot, q, 1e-3, 1e-3, kd=2.0) == max(1, int(np.ceil(1e-3 * rate / 2)))
