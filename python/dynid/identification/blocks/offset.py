"""The torque-offset block: one constant torque per joint (a sensor bias), off_j in row j.

With Coulomb friction the offset also carries the friction's asymmetry (Fs+ - Fs- = 2 off_j;
:mod:`dynid.identification.friction_models`). Unconstrained in the physically consistent fit.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .base import Block, Context

#: Name of the torque-offset coefficient of joint j (1-based): "off1", "off2", ...
OFFSET_NAME = "off"


@dataclass(frozen=True)
class Offset(Block):
    """Columns e_j (the identity in each sample's rows)."""

    key = "offset"
    n: int

    @classmethod
    def build(cls, context: Context) -> Offset | None:
        return cls(context.robot.n) if context.offset else None

    @classmethod
    def from_record(cls, options: Mapping[str, Any], n: int) -> Offset | None:
        return cls(n) if options.get("offset") is True else None

    def record(self) -> dict[str, Any]:
        return {"offset": True}

    def names(self) -> list[str]:
        return [f"{OFFSET_NAME}{j}" for j in range(1, self.n + 1)]

    def expressions(self) -> list[str]:
        return [f"torque offset of joint {j}" for j in range(1, self.n + 1)]

    def columns(self, q: NDArray[np.float64], qd: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.broadcast_to(np.eye(self.n), (q.shape[0], self.n, self.n))

    def describe(self) -> str:
        return f"{self.n} offsets"
