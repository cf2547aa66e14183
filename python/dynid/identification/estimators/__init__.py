"""Estimators of the log identification beyond ordinary and weighted least squares.

Each is a function ``(Problem) -> EstimatorFit`` (:mod:`.base`) in a file of its own, made a
``method=`` of :func:`dynid.identify_log` by one :func:`.registry.register` line below.
"""

from __future__ import annotations

from . import essential, irls, tls
from .base import EstimatorFit, Problem
from .closed_loop_model import OPTIONS as CLOSED_LOOP_OPTIONS
from .didim import didim
from .iv import instrumental_variables
from .periodic import periodic
from .registry import methods, register

register(
    "irls",
    irls.irls,
    "robust M-estimator by iteratively reweighted least squares (outliers, reversal spikes)",
    ("loss", "tuning"),
)
register(
    "tls",
    tls.tls,
    "errors in variables: total least squares with the accelerations' noise (noisy regressor)",
    ("acceleration_noise",),
    no_physical="the physical fit minimises a weighted residual, the attenuated objective "
    "that TLS corrects; use --method wls or irls with --physical (docs/identification.md, 'TLS')",
)
register(
    "essential",
    essential.essential,
    "essential parameters: WLS without the coefficients the data determine poorly",
    ("essential_threshold",),
    no_physical="the physical fit estimates the standard parameters and cannot set base "
    "parameters to zero; with --physical use --method wls (the constraints and a prior fix "
    "the poorly excited directions)",
)

register(
    "iv",
    instrumental_variables,
    "IDIM-IV: instruments from the closed loop simulated with the estimate (closed-loop data)",
    CLOSED_LOOP_OPTIONS,
    no_physical="the physical fit would weigh the measured regressor, whose noise IV's "
    "instruments avoid; use --method wls with --physical (docs/identification.md, "
    "'Closed-loop data')",
)
register(
    "didim",
    didim,
    "DIDIM: the torque of the simulated closed loop fitted to the measured one (output error)",
    CLOSED_LOOP_OPTIONS,
    no_physical="the physical fit would weigh the measured regressor, not the simulated one "
    "DIDIM fits; use --method wls with --physical (docs/identification.md, 'Closed-loop data')",
)
register(
    "periodic",
    periodic,
    "periodic-data ML (Swevers et al. 1997): whole periods averaged, weighted by the noise of "
    "their scatter",
    options=("period",),
)

__all__ = ["EstimatorFit", "Problem", "methods", "register"]
