"""Estimators of the log identification beyond ordinary and weighted least squares.

Each is a function ``(Problem) -> EstimatorFit`` (:mod:`.base`) in a file of its own, made a
``method=`` of :func:`dynid.identify_log` by one :func:`.registry.register` line below.
"""

from __future__ import annotations

from .base import EstimatorFit, Problem
from .closed_loop_model import OPTIONS as CLOSED_LOOP_OPTIONS
from .didim import didim
from .iv import instrumental_variables
from .registry import methods, register

__all__ = ["EstimatorFit", "Problem", "methods", "register"]

register(
    "iv",
    instrumental_variables,
    "IDIM-IV: instruments from the closed loop simulated with the estimate (closed-loop data)",
    CLOSED_LOOP_OPTIONS,
)
register(
    "didim",
    didim,
    "DIDIM: the torque of the simulated closed loop fitted to the measured one (output error)",
    CLOSED_LOOP_OPTIONS,
)
