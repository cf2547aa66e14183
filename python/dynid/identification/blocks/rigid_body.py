"""The rigid-body block: the base parameters of the robot's regressor (with the rotor Ia and
symmetric friction Fv, Fs columns when asked), always the first columns of theta.

Y_base = Y[:, independent], theta_base = beta @ pi (lecture, "Least Squares (LS)
identification", Robotics 2 p. 26; ``dynid.model.base_parameters``). Unlike the other blocks
its columns depend on the accelerations and on the robot's DH table, and its record is the
result file's ``base_parameters`` (beside the robot's model), so it is no registered block.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...model.robot import Robot


@dataclass(frozen=True, eq=False)
class RigidBody:
    """The base columns of ``robot``'s regressor: ``independent`` among its ``parameter_names``
    (10 n standard parameters, then Ia, then Fv, Fs as asked by ``rotor``, ``friction``)."""

    robot: Robot
    rotor: bool
    friction: bool
    independent: NDArray[np.int64]

    @property
    def size(self) -> int:
        return int(self.independent.size)

    @property
    def parameter_count(self) -> int:
        """Number of standard columns P (10 n + the drive terms)."""
        return self.robot.n * (10 + int(self.rotor) + 2 * int(self.friction))

    def columns(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """(T, n, count) the base columns, selected in C++ (no full (T, n, P) array)."""
        Y = self.robot.regressor(
            q, qd, qdd, rotor=self.rotor, friction=self.friction, columns=self.independent
        )
        return Y[None] if Y.ndim == 2 else Y

    def standard_columns(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """(T, n, P) all the standard columns (the physically consistent fit's unknowns)."""
        Y = self.robot.regressor(q, qd, qdd, rotor=self.rotor, friction=self.friction)
        return Y[None] if Y.ndim == 2 else Y
