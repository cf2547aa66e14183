"""The position-torque block: ks_j sin q_j + kc_j cos q_j on the joints where these columns are
structurally identifiable (:mod:`dynid.identification.position_torque`); unconstrained."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..position_torque import position_columns, position_names, position_torque_joints
from .base import Block, Context


@dataclass(frozen=True)
class PositionTorque(Block):
    """Two columns per joint of ``joints`` (0-based); ``left_out`` are the joints asked for
    where gravity hides them (reported, not recorded)."""

    key = "position_torque"
    n: int
    joints: tuple[int, ...]
    left_out: tuple[int, ...] = field(default=(), compare=False)

    @classmethod
    def build(cls, context: Context) -> PositionTorque | None:
        if not context.position_torque:
            return None
        # Any friction model's columns are functions of qd_j alone: sin q_j, cos q_j are
        # independent of them, so the symmetric columns stand in for every friction model.
        joints, left_out = position_torque_joints(
            context.robot, context.rotor, context.friction != "none", context.offset
        )
        return cls(context.robot.n, joints, left_out)

    @classmethod
    def from_record(cls, options: Mapping[str, Any], n: int) -> PositionTorque | None:
        value = options.get("position_torque_joints", [])
        if not (
            isinstance(value, list)
            and all(isinstance(j, int) and not isinstance(j, bool) for j in value)
            and all(1 <= j <= n for j in value)
            and value == sorted(set(value))
        ):
            raise ValueError(
                f"options.position_torque_joints: expected increasing joint numbers "
                f"1..{n}, got {value!r}"
            )
        return cls(n, tuple(j - 1 for j in value)) if value else None

    def record(self) -> dict[str, Any]:
        return {"position_torque_joints": [j + 1 for j in self.joints]}

    def names(self) -> list[str]:
        return position_names(self.joints)[0]

    def expressions(self) -> list[str]:
        return position_names(self.joints)[1]

    def columns(self, q: NDArray[np.float64], qd: NDArray[np.float64]) -> NDArray[np.float64]:
        return position_columns(q, self.joints)

    def notes(self) -> list[str]:
        if not self.left_out:
            return []
        joints = ", ".join(str(j + 1) for j in self.left_out)
        return [
            f"position torque: not on joint(s) {joints}, where sin q, cos q are combinations of "
            "the rigid-body columns (gravity) and cannot be told apart from them"
        ]

    def describe(self) -> str:
        return f"position torque on joint(s) {', '.join(str(j + 1) for j in self.joints)}"
