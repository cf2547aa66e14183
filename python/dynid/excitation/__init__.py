"""Exciting trajectories for identification (notes, "Identification experiments").

- :mod:`dynid.excitation.trajectory`: the finite Fourier series (:class:`FourierTrajectory`), its
  limits, the rest-to-rest projection and the condition number that measures its excitation;
- :mod:`dynid.excitation.optimization`: choosing its coefficients (:func:`optimize_excitation`,
  SciPy's SLSQP, imported when first used), within joint torque limits too
  (:mod:`dynid.excitation.torque_limits`);
- :mod:`dynid.excitation.experiment`: the trajectory of an experiment (:func:`design_experiment`,
  what ``dynid excite`` runs), and :mod:`dynid.excitation.trajectory_files`: its file
  trajectory.json (:class:`ExperimentTrajectory`, :func:`load_trajectory`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .trajectory import FourierTrajectory, excitation_condition_number, rest_to_rest
from .trajectory_files import ExperimentTrajectory, load_trajectory

if TYPE_CHECKING:
    from .experiment import design_experiment
    from .optimization import ExcitationResult, optimize_excitation

__all__ = [
    "ExcitationResult",
    "ExperimentTrajectory",
    "FourierTrajectory",
    "design_experiment",
    "excitation_condition_number",
    "load_trajectory",
    "optimize_excitation",
    "rest_to_rest",
]


def __getattr__(name: str) -> Any:
    # The optimiser needs scipy.optimize (~0.3 s to import): loaded on first use only.
    if name in ("ExcitationResult", "optimize_excitation"):
        from . import optimization

        return getattr(optimization, name)
    if name == "design_experiment":
        from .experiment import design_experiment

        return design_experiment
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
