"""dynid: dynamics and identification of robot arms given by Denavit-Hartenberg tables.

The C++ core (``dynid._core``) computes kinematics, inverse and forward dynamics, the inertia
and Coriolis matrices and the regressors; this package holds the user's workflow on top of it:
a model (``robot``, ``models``), its linear parametrisation (``base_parameters``), data in
(``io``, ``signal``, ``sim``), identification (``identify``, ``from_controller``, ``excitation``),
checking the result (``validation``, ``plots``) and the command line (``cli``).
"""

from . import models
from ._core import get_threads, set_threads
from .base_parameters import BaseParameters, base_parameters
from .cmake import get_cmake_dir, get_include
from .excitation import FourierTrajectory, optimize_excitation
from .from_controller import IdentifiedModel, identify_from_controller, payload_mass_estimates
from .identify import LeastSquaresResult, RankDeficientError, least_squares
from .io import Log, load_log, prepare_log, save_log
from .log_identification import LogIdentification, identify_log, validate_log
from .model_files import load_model, save_model
from .recursive import RecursiveLeastSquares
from .result_files import load_result
from .robot import Robot
from .sim import VirtualController
from .streaming import LeastSquaresAccumulator, least_squares_streaming

__all__ = [
    "BaseParameters",
    "FourierTrajectory",
    "IdentifiedModel",
    "LeastSquaresAccumulator",
    "LeastSquaresResult",
    "Log",
    "LogIdentification",
    "RankDeficientError",
    "RecursiveLeastSquares",
    "Robot",
    "VirtualController",
    "base_parameters",
    "get_cmake_dir",
    "get_include",
    "get_threads",
    "identify_from_controller",
    "identify_log",
    "least_squares",
    "least_squares_streaming",
    "load_log",
    "load_model",
    "load_result",
    "models",
    "optimize_excitation",
    "payload_mass_estimates",
    "prepare_log",
    "save_log",
    "save_model",
    "set_threads",
    "validate_log",
]
__version__ = "0.1.0"
