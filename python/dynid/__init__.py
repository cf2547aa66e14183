"""dynid: dynamics and identification of robot arms given by Denavit-Hartenberg tables.

The C++ core (``dynid._core``) computes kinematics, inverse and forward dynamics, the inertia
and Coriolis matrices and the regressors; this package holds the user's workflow on top of it,
one way from the model to the files:

- the model: :mod:`~dynid.robot` (:class:`Robot`), :mod:`~dynid.models`, :mod:`dynid.urdf`
  (``Robot.from_urdf`` / ``Robot.to_urdf``);
- its linear parametrisation: :mod:`~dynid.base_parameters`;
- data in: :mod:`dynid.io` (logs), :mod:`~dynid.signal`, :mod:`~dynid.sim` (closed-loop
  simulation, a virtual robot);
- identification: :mod:`~dynid.identify` (least squares), :mod:`~dynid.from_controller` (the
  paper's method), :mod:`~dynid.log_identification`, :mod:`dynid.excitation`,
  :mod:`~dynid.recursive`;
- checking the result: :mod:`~dynid.validation`, :mod:`~dynid.plots`;
- uses of the model: :mod:`~dynid.time_scaling`, :mod:`~dynid.bounds`, :mod:`~dynid.payload`;
- files: :mod:`dynid.io` (model and result files); the command line: :mod:`dynid.cli`.

Names are loaded on first use (PEP 562), so ``import dynid`` stays fast: SciPy's optimisers and
signal processing and matplotlib are imported only by the functions that need them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ._core import MomentumObserver, get_threads, set_threads
from ._version import __version__

# Imported here, not lazily: the submodule of the same name would otherwise shadow the function
# as soon as anything imports it.
from .base_parameters import BaseParameters, base_parameters
from .robot import Robot

if TYPE_CHECKING:
    from . import models
    from .bounds import DynamicBounds, dynamic_bounds
    from .cmake import get_cmake_dir, get_include
    from .drive_gains import DriveGainIdentification, identify_drive_gains
    from .elastic import ElasticRobot
    from .elastic_identification import DriveIdentification, identify_drives
    from .errors import PhysicalIdentificationError
    from .excitation import FourierTrajectory, optimize_excitation
    from .from_controller import IdentifiedModel, identify_from_controller, payload_mass_estimates
    from .identify import LeastSquaresResult, RankDeficientError, least_squares
    from .io.log_files import Log, load_log, save_log
    from .io.model_files import load_model, save_model
    from .io.preparation import prepare_log
    from .io.result_files import load_result, save_result
    from .log_identification import LogIdentification, identify_log, validate_log
    from .payload import PayloadEstimate, estimate_payload, payload_from_identified
    from .physical import PhysicalResult, physical_least_squares
    from .recursive import RecursiveLeastSquares
    from .sim import VirtualController, simulate
    from .streaming import LeastSquaresAccumulator, least_squares_streaming
    from .time_scaling import scale_motion, scale_time, scale_torques, scaling_for_torque_limits

#: Public name -> the module that defines it (imported on first access).
_LAZY = {
    "models": ".models",
    "io": ".io",
    "excitation": ".excitation",
    "signal": ".signal",
    "sim": ".sim",
    "validation": ".validation",
    "get_cmake_dir": ".cmake",
    "get_include": ".cmake",
    "FourierTrajectory": ".excitation",
    "optimize_excitation": ".excitation",
    "IdentifiedModel": ".from_controller",
    "identify_from_controller": ".from_controller",
    "payload_mass_estimates": ".from_controller",
    "LeastSquaresResult": ".identify",
    "RankDeficientError": ".identify",
    "least_squares": ".identify",
    "LeastSquaresAccumulator": ".streaming",
    "least_squares_streaming": ".streaming",
    "Log": ".io.log_files",
    "load_log": ".io.log_files",
    "save_log": ".io.log_files",
    "prepare_log": ".io.preparation",
    "load_model": ".io.model_files",
    "save_model": ".io.model_files",
    "load_result": ".io.result_files",
    "save_result": ".io.result_files",
    "LogIdentification": ".log_identification",
    "identify_log": ".log_identification",
    "validate_log": ".log_identification",
    "PhysicalIdentificationError": ".errors",
    "PhysicalResult": ".physical",
    "physical_least_squares": ".physical",
    "RecursiveLeastSquares": ".recursive",
    "VirtualController": ".sim",
    "simulate": ".sim",
    "DynamicBounds": ".bounds",
    "ElasticRobot": ".elastic",
    "elastic": ".elastic",
    "DriveGainIdentification": ".drive_gains",
    "identify_drive_gains": ".drive_gains",
    "DriveIdentification": ".elastic_identification",
    "identify_drives": ".elastic_identification",
    "dynamic_bounds": ".bounds",
    "PayloadEstimate": ".payload",
    "estimate_payload": ".payload",
    "payload_from_identified": ".payload",
    "scale_time": ".time_scaling",
    "scale_motion": ".time_scaling",
    "scale_torques": ".time_scaling",
    "scaling_for_torque_limits": ".time_scaling",
    "observer": ".observer",
}

# Literal (not computed) so that linters and type checkers see the public names; a test checks
# that it lists every name of _LAZY.
__all__ = [
    "BaseParameters",
    "DriveGainIdentification",
    "DriveIdentification",
    "DynamicBounds",
    "ElasticRobot",
    "FourierTrajectory",
    "IdentifiedModel",
    "LeastSquaresAccumulator",
    "LeastSquaresResult",
    "Log",
    "LogIdentification",
    "MomentumObserver",
    "PayloadEstimate",
    "PhysicalIdentificationError",
    "PhysicalResult",
    "RankDeficientError",
    "RecursiveLeastSquares",
    "Robot",
    "VirtualController",
    "__version__",
    "base_parameters",
    "dynamic_bounds",
    "elastic",
    "estimate_payload",
    "excitation",
    "get_cmake_dir",
    "get_include",
    "get_threads",
    "identify_drive_gains",
    "identify_drives",
    "identify_from_controller",
    "identify_log",
    "io",
    "least_squares",
    "least_squares_streaming",
    "load_log",
    "load_model",
    "load_result",
    "models",
    "observer",
    "optimize_excitation",
    "payload_from_identified",
    "payload_mass_estimates",
    "physical_least_squares",
    "prepare_log",
    "save_log",
    "save_model",
    "save_result",
    "scale_motion",
    "scale_time",
    "scale_torques",
    "scaling_for_torque_limits",
    "set_threads",
    "signal",
    "sim",
    "simulate",
    "validate_log",
    "validation",
]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'dynid' has no attribute {name!r}")
    value = importlib.import_module(module, __name__)
    if name != module.lstrip("."):
        value = getattr(value, name)
    globals()[name] = value  # later accesses skip this function
    return value


def __dir__() -> list[str]:
    return __all__
