"""The registered blocks, in column order: name -> Block class.

The fit (:func:`dynid.identify_log`), the prediction, the physically consistent fit and the
result file (:mod:`dynid.export.result_files`) find the blocks here. A new block is one file
and one :func:`register` line (below, or in the code that defines it, before it is used).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .base import Block, Context
from .friction import AsymmetricFriction
from .offset import Offset
from .position_torque import PositionTorque
from .stribeck import StribeckFriction

#: The blocks by name, in the order of their columns in theta.
REGISTRY: dict[str, type[Block]] = {}

#: The friction models that live in the rigid-body columns (the robot's Fv, Fs).
BUILT_IN_FRICTION = ("none", "symmetric")


def register(block: type[Block]) -> type[Block]:
    """Add ``block`` after the registered ones (its columns follow theirs); usable as a class
    decorator. ValueError when its name or friction model is taken."""
    if block.key in REGISTRY and REGISTRY[block.key] is not block:
        raise ValueError(f"block: a block named {block.key!r} is registered already")
    taken = block.friction_model is not None and block.friction_model in friction_models()
    if taken and REGISTRY.get(block.key) is not block:
        raise ValueError(f"block: friction model {block.friction_model!r} exists already")
    REGISTRY[block.key] = block
    return block


def unregister(key: str) -> None:
    """Remove a registered block (tests that register a toy block clean up with it)."""
    REGISTRY.pop(key, None)


def friction_models() -> tuple[str, ...]:
    """The ``friction=`` values of :func:`dynid.identify_log`: the built-in ones, then the
    friction models of the registered blocks."""
    more = [b.friction_model for b in REGISTRY.values() if b.friction_model is not None]
    return BUILT_IN_FRICTION + tuple(more)


def friction_model(value: Any) -> str:
    """``friction`` of :func:`dynid.identify_log` as one of :func:`friction_models`: False is
    "none" and True "symmetric" (the meaning they always had). ValueError otherwise."""
    if isinstance(value, (bool, np.bool_)):
        return "symmetric" if value else "none"
    models = friction_models()
    if isinstance(value, str) and value in models:
        return value
    raise ValueError(
        f"friction: expected True, False or one of {', '.join(map(repr, models))}, got {value!r}"
    )


def build_blocks(context: Context) -> list[Block]:
    """The blocks a run with these options asks for, in column order."""
    blocks = [block.build(context) for block in REGISTRY.values()]
    return [b for b in blocks if b is not None]


def blocks_from_record(options: Mapping[str, Any], n: int) -> list[Block]:
    """The blocks that result.json's ``options`` record, in column order."""
    blocks = [block.from_record(options, n) for block in REGISTRY.values()]
    return [b for b in blocks if b is not None]


register(AsymmetricFriction)
register(StribeckFriction)
register(Offset)
register(PositionTorque)
