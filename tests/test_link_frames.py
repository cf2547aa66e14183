"""Re-expressing a model's standard parameters in another DH table of the same arm
(dynid.link_frames), against independent computations: the LWR4+ tables of
tests/data/kuka_lwr4_dh.json (standard and modified DH, each with the URDF's parameters derived
there independently, verified against Pinocchio on the URDF) and the hand-made prior
examples/kuka_lwr4_urdf_prior.json (Steiner by hand on link 7).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.identification.physical import physical_least_squares
from dynid.model.link_frames import express_in_frames_of, link_frames

DATA = Path(__file__).parent / "data"
PRIOR = Path(__file__).parent.parent / "examples" / "kuka_lwr4_urdf_prior.json"
SOURCE = json.loads((DATA / "kuka_lwr4_dh.json").read_text())
URDF = "kuka_lwr4.urdf (HEAD)"


def arm_table(convention: str) -> dynid.Robot:
    rows = SOURCE["dh"][convention]["rows"]
    a, alpha = ("a", "alpha") if convention == "standard" else ("a_prev", "alpha_prev")
    return dynid.Robot.from_dh(
        [[r[a], r[alpha], r["d"], r["theta_offset"]] for r in rows],
        convention=convention,
        params=SOURCE["params"][URDF][convention],
    )


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_the_arms_tables_map_to_the_prior_file(convention):
    """The arm's own table (standard: d1 = 0.3105, d7 = 0.078; modified: frames at the joints)
    with the URDF parameters, mapped to the frames of kuka_lwr4(): the parameters of the
    hand-made prior file to 1e-12, and the rigid-body torques of the source table to 1e-12 N m."""
    lwr = dynid.models.kuka_lwr4()
    source = arm_table(convention)
    mapped = express_in_frames_of(source, lwr)
    prior = dynid.load_model(PRIOR)
    np.testing.assert_allclose(mapped.params, prior.params, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(mapped.dh, lwr.dh)
    rng = np.random.default_rng(1)
    q = lwr.random_configurations(30, seed=1)
    qd, qdd = rng.uniform(-2, 2, (2, 30, 7))
    np.testing.assert_allclose(mapped.rnea(q, qd, qdd), source.rnea(q, qd, qdd), rtol=0, atol=1e-12)


def test_link_frames_end_at_fkine():
    """The last frame times the tool is fkine (1e-14)."""
    robot = dynid.models.puma560()
    q = robot.random_configurations(5, seed=2)
    frames = link_frames(robot, q)
    np.testing.assert_allclose(frames[:, -1] @ robot.tool, robot.fkine(q), rtol=0, atol=1e-14)


def test_another_arm_is_refused():
    """A table with one alpha of the other sign (another arm), a different joint count or a
    different gravity: ValueError naming the model."""
    lwr = dynid.models.kuka_lwr4()
    dh = arm_table("standard").dh.copy()
    dh[2, 1] *= -1
    other = dynid.Robot.from_dh(dh, params=arm_table("standard").params)
    with pytest.raises(ValueError, match=r"^model:"):
        express_in_frames_of(other, lwr)
    with pytest.raises(ValueError, match=r"^model:"):
        express_in_frames_of(dynid.models.puma560(), lwr)
    tilted = dynid.Robot.from_dh(lwr.dh, gravity=(0, 9.81, 0), params=lwr.params)
    with pytest.raises(ValueError, match=r"^model:"):
        express_in_frames_of(tilted, lwr)


def test_a_prior_in_other_frames_is_mapped_by_the_physical_fit():
    """physical_least_squares with the modified-DH table of the arm as prior (truth = its
    mapping to kuka_lwr4()'s frames, noise-free data): the full standard parameters of the truth
    (1e-6 of the largest); a prior of another arm: ValueError naming prior."""
    lwr = dynid.models.kuka_lwr4()
    truth = dynid.load_model(PRIOR)
    rng = np.random.default_rng(3)
    q = lwr.random_configurations(300, seed=3)
    qd, qdd = rng.uniform(-2, 2, (2, 300, 7))
    Y = lwr.regressor(q, qd, qdd)
    tau = truth.rigid_body().rnea(q, qd, qdd)
    fit = physical_least_squares(lwr, Y, tau, prior=arm_table("modified"), prior_weight=1e-4)
    np.testing.assert_allclose(
        fit.params, truth.params, rtol=0, atol=1e-6 * np.abs(truth.params).max()
    )
    dh = lwr.dh.copy()
    dh[2, 1] *= -1
    with pytest.raises(ValueError, match=r"^prior:"):
        physical_least_squares(
            lwr, Y, tau, prior=dynid.Robot.from_dh(dh, params=truth.params), prior_weight=1e-4
        )


def test_the_lwr4_urdf_maps_to_the_prior_file():
    """Robot.from_urdf on the LWR4 URDF (its own DH: d1 = 1.3105 with a world offset, d7 =
    0.078) mapped to kuka_lwr4()'s frames: the hand-made prior file's parameters to 1e-12, the
    URDF's damping and friction as Fv, Fs."""
    urdf = dynid.Robot.from_urdf(DATA / "urdf" / "kuka_lwr4.urdf")
    mapped = express_in_frames_of(urdf, dynid.models.kuka_lwr4())
    prior = dynid.load_model(PRIOR)
    np.testing.assert_allclose(mapped.params, prior.params, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(mapped.Fv, prior.Fv)
    np.testing.assert_array_equal(mapped.Fs, prior.Fs)
