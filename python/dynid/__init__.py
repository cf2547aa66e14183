"""dynid: dynamics and identification of robot arms given by Denavit-Hartenberg tables.

The C++ core (``dynid._core``) computes kinematics, inverse and forward dynamics, the inertia
and Coriolis matrices and the regressors; this package holds the user's workflow on top of it,
one way from the model to the files, each step a subpackage that imports only the ones before it
(docs/architecture.md):

- :mod:`dynid.model`: the robot (:class:`Robot`), ready-made arms (``dynid.models``), URDF in and
  out, model files, elastic joints, the base parameters of its regressor;
- :mod:`dynid.excitation` (exciting trajectories), :mod:`dynid.motion` (time scaling) and
  :mod:`dynid.sim` (closed-loop simulation, a virtual robot): motions and data from a model;
- :mod:`dynid.logs`: data in, the measurement logs and their preparation (``dynid.signal``);
- :mod:`dynid.identification`: least squares, the physically consistent fit, a log's
  identification, the paper's method, payloads, drive gains, validation (``dynid.validation``),
  the momentum observer (``dynid.observer``);
- :mod:`dynid.export`: files out (results, output folders, plots, summaries);
- :mod:`dynid.cli`: the command line, and ``dynid demo``.

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
from .model.base_parameters import BaseParameters, base_parameters
from .model.robot import Robot

if TYPE_CHECKING:
    from .cmake import get_cmake_dir, get_include
    from .errors import PhysicalIdentificationError
    from .excitation import FourierTrajectory, optimize_excitation
    from .export.result_files import load_result, save_result
    from .identification.closed_chain_identification import identify_closed_chain
    from .identification.drive_gains import DriveGainIdentification, identify_drive_gains
    from .identification.elastic_identification import DriveIdentification, identify_drives
    from .identification.from_controller import (
        IdentifiedModel,
        identify_from_controller,
        payload_mass_estimates,
    )
    from .identification.identify import LeastSquaresResult, RankDeficientError, least_squares
    from .identification.log_identification import LogIdentification, identify_log, validate_log
    from .identification.payload import PayloadEstimate, estimate_payload, payload_from_identified
    from .identification.payload_logs import estimate_payload_from_logs
    from .identification.physical import PhysicalResult, physical_least_squares
    from .identification.recursive import RecursiveLeastSquares
    from .identification.streaming import LeastSquaresAccumulator, least_squares_streaming
    from .logs.log_files import Log, load_log, save_log
    from .logs.motor_side import motor_to_joint
    from .logs.preparation import prepare_log
    from .model import models
    from .model.bounds import DynamicBounds, dynamic_bounds
    from .model.closed_chain import ClosedChain
    from .model.elastic import ElasticRobot
    from .model.loop_closures import LinearClosure, PointClosure
    from .model.model_files import load_model, save_model
    from .motion.time_scaling import (
        scale_motion,
        scale_time,
        scale_torques,
        scaling_for_torque_limits,
    )
    from .sim import VirtualController, simulate

#: Public name -> the module that defines it (imported on first access).
_LAZY = {
    "models": ".model.models",
    "io": ".io",
    "excitation": ".excitation",
    "signal": ".logs.signal",
    "sim": ".sim",
    "validation": ".identification.validation",
    "get_cmake_dir": ".cmake",
    "get_include": ".cmake",
    "FourierTrajectory": ".excitation",
    "optimize_excitation": ".excitation",
    "IdentifiedModel": ".identification.from_controller",
    "identify_from_controller": ".identification.from_controller",
    "payload_mass_estimates": ".identification.from_controller",
    "LeastSquaresResult": ".identification.identify",
    "RankDeficientError": ".identification.identify",
    "least_squares": ".identification.identify",
    "LeastSquaresAccumulator": ".identification.streaming",
    "least_squares_streaming": ".identification.streaming",
    "Log": ".logs.log_files",
    "load_log": ".logs.log_files",
    "motor_to_joint": ".logs.motor_side",
    "save_log": ".logs.log_files",
    "prepare_log": ".logs.preparation",
    "load_model": ".model.model_files",
    "save_model": ".model.model_files",
    "load_result": ".export.result_files",
    "save_result": ".export.result_files",
    "LogIdentification": ".identification.log_identification",
    "identify_log": ".identification.log_identification",
    "validate_log": ".identification.log_identification",
    "PhysicalIdentificationError": ".errors",
    "PhysicalResult": ".identification.physical",
    "physical_least_squares": ".identification.physical",
    "RecursiveLeastSquares": ".identification.recursive",
    "VirtualController": ".sim",
    "simulate": ".sim",
    "DynamicBounds": ".model.bounds",
    "ClosedChain": ".model.closed_chain",
    "LinearClosure": ".model.loop_closures",
    "PointClosure": ".model.loop_closures",
    "identify_closed_chain": ".identification.closed_chain_identification",
    "ElasticRobot": ".model.elastic",
    "elastic": ".model.elastic",
    "DriveGainIdentification": ".identification.drive_gains",
    "identify_drive_gains": ".identification.drive_gains",
    "DriveIdentification": ".identification.elastic_identification",
    "identify_drives": ".identification.elastic_identification",
    "dynamic_bounds": ".model.bounds",
    "PayloadEstimate": ".identification.payload",
    "estimate_payload": ".identification.payload",
    "estimate_payload_from_logs": ".identification.payload_logs",
    "payload_from_identified": ".identification.payload",
    "scale_time": ".motion.time_scaling",
    "scale_motion": ".motion.time_scaling",
    "scale_torques": ".motion.time_scaling",
    "scaling_for_torque_limits": ".motion.time_scaling",
    "observer": ".identification.observer",
}

# Literal (not computed) so that linters and type checkers see the public names; a test checks
# that it lists every name of _LAZY.
__all__ = [
    "BaseParameters",
    "ClosedChain",
    "DriveGainIdentification",
    "DriveIdentification",
    "DynamicBounds",
    "ElasticRobot",
    "FourierTrajectory",
    "IdentifiedModel",
    "LeastSquaresAccumulator",
    "LeastSquaresResult",
    "LinearClosure",
    "Log",
    "LogIdentification",
    "MomentumObserver",
    "PayloadEstimate",
    "PhysicalIdentificationError",
    "PhysicalResult",
    "PointClosure",
    "RankDeficientError",
    "RecursiveLeastSquares",
    "Robot",
    "VirtualController",
    "__version__",
    "base_parameters",
    "dynamic_bounds",
    "elastic",
    "estimate_payload",
    "estimate_payload_from_logs",
    "excitation",
    "get_cmake_dir",
    "get_include",
    "get_threads",
    "identify_closed_chain",
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
    "motor_to_joint",
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
    if name != module.rsplit(".", 1)[-1]:  # a name defined in the module, not the module
        value = getattr(value, name)
    globals()[name] = value  # later accesses skip this function
    return value


def __dir__() -> list[str]:
    return __all__
