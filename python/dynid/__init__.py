"""dynid: dynamics and identification of robot arms given by Denavit-Hartenberg tables.

The C++ core (``dynid._core``) computes kinematics, inverse and forward dynamics, the inertia
and Coriolis matrices and the regressors; this package holds the user's workflow on top of it.
"""

from . import models
from .base_parameters import BaseParameters, base_parameters
from .robot import Robot

__all__ = ["BaseParameters", "Robot", "base_parameters", "models"]
__version__ = "0.1.0"
