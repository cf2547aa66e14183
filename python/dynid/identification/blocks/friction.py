"""The asymmetric friction block: Fv+, Fv-, Fs+, Fs- per joint (Fv+, Fv-, Fs with offsets).

The columns, names and the reason for the offset variant are those of
:mod:`dynid.identification.friction_models`; every coefficient is >= 0 in the physically
consistent fit, as a friction that dissipates needs (tau_f,j qd_j >= 0).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..friction_models import asymmetric_columns, asymmetric_count, asymmetric_names
from .base import Block, Context


@dataclass(frozen=True)
class AsymmetricFriction(Block):
    """A coefficient per direction of motion; ``offset``: the symmetric Coulomb column Fs in
    place of Fs+, Fs- (the offset block carries the asymmetry)."""

    key = "asymmetric_friction"
    friction_model = "asymmetric"
    version = 3  # results with it are format version 3 (dynid.export.result_files)
    n: int
    offset: bool

    @classmethod
    def build(cls, context: Context) -> AsymmetricFriction | None:
        if context.friction != cls.friction_model:
            return None
        if context.robot.coupled:
            raise ValueError(
                "friction: the asymmetric model acts on each joint's velocity, but the robot's "
                "drives are coupled (robot.transmission); friction=True gives the motor-side "
                "friction T^T (Fv T qd + Fs sign(T qd))"
            )
        return cls(context.robot.n, context.offset)

    @classmethod
    def from_record(cls, options: Mapping[str, Any], n: int) -> AsymmetricFriction | None:
        if options.get("friction_model") != cls.friction_model:
            return None
        return cls(n, options.get("offset") is True)

    def record(self) -> dict[str, Any]:
        return {"friction_model": self.friction_model}

    def names(self) -> list[str]:
        return asymmetric_names(self.n, self.offset)[0]

    def expressions(self) -> list[str]:
        return asymmetric_names(self.n, self.offset)[1]

    @property
    def size(self) -> int:
        return asymmetric_count(self.n, self.offset)

    def columns(self, q: NDArray[np.float64], qd: NDArray[np.float64]) -> NDArray[np.float64]:
        return asymmetric_columns(np.asarray(qd, dtype=float).reshape(q.shape), self.offset)

    def nonnegative(self) -> NDArray[np.bool_]:
        return np.ones(self.size, dtype=bool)  # friction dissipates

    def describe(self) -> str:
        return f"{self.size} asymmetric friction coefficients"
