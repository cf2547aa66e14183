"""Linearization of the robot dynamics about an equilibrium or a trajectory (notes p. 44-47).

With the state x = (q, qd) and the input u = tau, the dynamics read
x' = f(x, u) = [qd; M(q)^-1 (u - n(q, qd))], n = c + g + friction. Its Jacobians at a point
(q, qd, qdd) with u = rnea(q, qd, qdd) follow from the analytic RNEA derivatives
(``Robot.rnea_derivatives``): differentiating M qdd + n = u,

    A = [[0, I], [-M^-1 dtau/dq, -M^-1 dtau/dqd]],   B = [[0], [M^-1]],

the partials taken at (q, qd, qdd) (notes p. 46: along a trajectory (q_d, qd_d, qdd_d); at an
equilibrium qd = qdd = 0, p. 45, dtau/dq is the gravity Jacobian dg/dq and dtau/dqd = diag(Fv)).
Coulomb friction Fs sign(qd) has no derivative at qd = 0 and is left out there (elsewhere it is
flat). The generalized-momentum state x = (q, p = M qd) of the notes is described in
docs/uses.md; this module returns the (q, qd) form.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import real_array

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

    from .robot import Robot

Array: TypeAlias = NDArray[np.float64]


def linearize(
    robot: Robot, q: ArrayLike, qd: ArrayLike | None = None, qdd: ArrayLike | None = None
) -> tuple[Array, Array]:
    """State-space matrices (A, B) of the dynamics linearized at (q, qd, qdd).

    ``q`` is one configuration (n,) or T of them (T, n); ``qd`` and ``qdd`` default to zeros
    (an equilibrium, held by the torque g(q)). Returns A (2n, 2n) and B (2n, n), or (T, 2n, 2n)
    and (T, 2n, n), for x = (q, qd) and u = tau:  dx' = A dx + B du.
    """
    q_array = real_array(q, "q")
    zeros = np.zeros_like(q_array)
    qd_array = zeros if qd is None else qd
    qdd_array = zeros if qdd is None else qdd
    dtau_dq, dtau_dqd = robot.rnea_derivatives(q_array, qd_array, qdd_array)
    M = robot.mass_matrix(q_array)
    n = robot.n
    # M^-1 [dtau/dq, dtau/dqd, I] in one solve per sample (M symmetric positive definite).
    rhs = np.concatenate([dtau_dq, dtau_dqd, np.broadcast_to(np.eye(n), M.shape)], axis=-1)
    solved = np.linalg.solve(M, rhs)
    lead = M.shape[:-2]
    A = np.zeros((*lead, 2 * n, 2 * n))
    A[..., :n, n:] = np.eye(n)
    A[..., n:, :] = -solved[..., : 2 * n]
    B = np.zeros((*lead, 2 * n, n))
    B[..., n:, :] = solved[..., 2 * n :]
    return A, B
