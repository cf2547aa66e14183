"""Pinocchio's reading of a URDF chain, the independent reference of the URDF tests.

Pinocchio (``pin``, a test extra) parses the URDF with urdfdom and builds its own kinematic tree;
nothing of dynid is used here. The chain from ``base_link`` to ``tip_link`` is found in
Pinocchio's tree (the joints between the base link's joint and the tip frame's joint); every
other joint is locked at its neutral position (zero) with ``buildReducedModel``, whose merged
inertias are what dynid's "off-chain subtrees held at 0" must reproduce. The world of dynid is
``base_link``'s frame: the reference re-expresses gravity and poses in it.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib.metadata import distribution
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

DATA = Path(__file__).parent / "data" / "urdf"
TOL = 1e-10  # relative to the largest entry of each result (the maths is exact)


def example_robot_data(relative: str) -> Path:
    """A file of the installed example-robot-data package (a test extra)."""
    path = Path(
        str(
            distribution("example-robot-data").locate_file(
                f"cmeel.prefix/share/example-robot-data/robots/{relative}"
            )
        )
    )
    assert path.is_file(), path
    return path


@dataclass
class Reference:
    model: pin.Model
    data: pin.Data
    joints: list[int]  # Pinocchio joint ids of the chain, base to tip
    tip_frame: int
    base_pose: np.ndarray  # base_link in Pinocchio's world (the root), chain at zero

    @property
    def gravity(self) -> np.ndarray:
        """Gravity (0, 0, -9.81) of the root frame, in base_link coordinates."""
        return self.base_pose[:3, :3].T @ np.array([0.0, 0.0, -9.81])

    def configuration(self, q: np.ndarray) -> np.ndarray:
        """Pinocchio's q for joint positions q (continuous joints store cos, sin)."""
        out = pin.neutral(self.model)
        for value, jid in zip(q, self.joints):
            joint = self.model.joints[jid]
            if joint.nq == 2:
                out[joint.idx_q : joint.idx_q + 2] = np.cos(value), np.sin(value)
            else:
                out[joint.idx_q] = value
        return out

    def rnea(self, q, qd, qdd) -> np.ndarray:
        return pin.rnea(self.model, self.data, self.configuration(q), qd, qdd).copy()

    def mass_matrix(self, q) -> np.ndarray:
        upper = np.triu(pin.crba(self.model, self.data, self.configuration(q)))
        return upper + np.triu(upper, 1).T

    def gravity_torques(self, q) -> np.ndarray:
        return pin.computeGeneralizedGravity(self.model, self.data, self.configuration(q)).copy()

    def tip_pose(self, q) -> np.ndarray:
        """Pose of tip_link in base_link coordinates."""
        pin.framesForwardKinematics(self.model, self.data, self.configuration(q))
        return np.linalg.inv(self.base_pose) @ self.data.oMf[self.tip_frame].homogeneous


def reference(text: str, base_link: str | None, tip_link: str) -> Reference:
    full = pin.buildModelFromXML(text)
    tip_joint = full.frames[full.getFrameId(tip_link)].parentJoint
    base_joint = 0 if base_link is None else full.frames[full.getFrameId(base_link)].parentJoint
    chain = []
    jid = tip_joint
    while jid != base_joint:
        chain.append(full.names[jid])
        jid = full.parents[jid]
    lock = [j for j in range(1, full.njoints) if full.names[j] not in chain]
    model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
    data = model.createData()
    joints = [model.getJointId(name) for name in reversed(chain)]
    base_pose = np.eye(4)
    if base_link is not None:
        pin.framesForwardKinematics(model, data, pin.neutral(model))
        base_pose = data.oMf[model.getFrameId(base_link)].homogeneous.copy()
    return Reference(model, data, joints, model.getFrameId(tip_link), base_pose)


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    """max |actual - expected| / max |expected|: the error relative to the result's scale."""
    return float(np.max(np.abs(actual - expected)) / max(1e-12, float(np.max(np.abs(expected)))))


def assert_matches_pinocchio(robot: Any, text: str, base_link, tip_link, seed=0, samples=8) -> None:
    """rnea, M, g (rigid body: Pinocchio has no friction) and the tip pose of ``robot`` equal
    Pinocchio's on ``text`` at random q, to TOL relative."""
    ref = reference(text, base_link, tip_link)
    assert ref.model.nv == robot.n
    rigid = robot.rigid_body()  # Pinocchio's rnea has no friction
    rigid.gravity_vector = ref.gravity
    rng = np.random.default_rng(seed)
    for _ in range(samples):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, robot.n))
        assert relative_error(rigid.rnea(q, qd, qdd), ref.rnea(q, qd, qdd)) < TOL
        assert relative_error(rigid.mass_matrix(q), ref.mass_matrix(q)) < TOL
        assert relative_error(rigid.gravity(q), ref.gravity_torques(q)) < TOL
        assert relative_error(robot.fkine(q), ref.tip_pose(q)) < TOL
