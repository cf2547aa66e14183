"""The identification model: the rigid-body columns, then the blocks in order, each with its
slice of theta (no index arithmetic elsewhere)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .base import Block
from .rigid_body import RigidBody


@dataclass(frozen=True, eq=False)
class IdentificationModel:
    """tau = [Y_base | Y_1 | ... ] theta: ``rigid`` (the base columns) then ``blocks``."""

    rigid: RigidBody
    blocks: tuple[Block, ...]

    @property
    def n(self) -> int:
        return self.rigid.robot.n

    @property
    def size(self) -> int:
        """Number of coefficients (columns)."""
        return self.rigid.size + self.extra_size

    @property
    def extra_size(self) -> int:
        return sum(b.size for b in self.blocks)

    def slice(self, key: str) -> slice | None:
        """The coefficients of the block named ``key`` in theta (None when absent)."""
        start = self.rigid.size
        for block in self.blocks:
            if block.key == key:
                return slice(start, start + block.size)
            start += block.size
        return None

    def block(self, key: str) -> Block | None:
        return next((b for b in self.blocks if b.key == key), None)

    def extra_columns(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
        """(T, n, e) the columns of every block, in order: functions of q and qd only."""
        q_ = np.asarray(q, dtype=float).reshape(-1, self.n)
        qd_ = np.asarray(qd, dtype=float).reshape(q_.shape)
        parts = [np.zeros((q_.shape[0], self.n, 0))]
        parts += [block.columns(q_, qd_) for block in self.blocks]
        return np.concatenate(parts, axis=2)

    def regressor(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """(T, n, size) the whole regressor: base columns, then the blocks' columns."""
        return np.concatenate([self.rigid.columns(q, qd, qdd), self.extra_columns(q, qd)], axis=2)

    def nonnegative_extra(self) -> NDArray[np.bool_]:
        """(extra_size,) the blocks' coefficients kept >= 0 by the physically consistent fit."""
        parts = [np.zeros(0, dtype=bool)] + [b.nonnegative() for b in self.blocks]
        return np.concatenate(parts)

    def extra_names(self) -> tuple[list[str], list[str]]:
        """Names and expressions of the blocks' coefficients, in order."""
        names: list[str] = []
        expressions: list[str] = []
        for block in self.blocks:
            names += block.names()
            expressions += block.expressions()
        return names, expressions

    def version(self, lowest: int) -> int:
        """The result-file version that holds every block (at least ``lowest``)."""
        return max([lowest, *(b.version for b in self.blocks)])


def kept(blocks: Sequence[Block]) -> tuple[Block, ...]:
    """The blocks with columns (a position-torque block whose joints were all left out has
    none, and is no part of the model)."""
    return tuple(b for b in blocks if b.size)
