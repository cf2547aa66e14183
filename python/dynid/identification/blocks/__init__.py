"""Column blocks of the identification regressor (docs/identification.md, "Column blocks")."""

from .base import Block, Context
from .model import IdentificationModel
from .registry import REGISTRY, register, unregister
from .rigid_body import RigidBody

__all__ = [
    "REGISTRY",
    "Block",
    "Context",
    "IdentificationModel",
    "RigidBody",
    "register",
    "unregister",
]
