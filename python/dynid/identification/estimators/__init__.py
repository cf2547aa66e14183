"""Estimators of the log identification beyond ordinary and weighted least squares.

Each is a function ``(Problem) -> EstimatorFit`` (:mod:`.base`) in a file of its own, made a
``method=`` of :func:`dynid.identify_log` by one :func:`.registry.register` line below.
"""

from __future__ import annotations

from .base import EstimatorFit, Problem
from .periodic import periodic
from .registry import methods, register

register(
    "periodic",
    periodic,
    "periodic-data ML (Swevers et al. 1997): whole periods averaged, weighted by the noise of "
    "their scatter",
    options=("period",),
)

__all__ = ["EstimatorFit", "Problem", "methods", "register"]
