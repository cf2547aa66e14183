"""The pseudo-inertia matrix of a link and the maps between it and the standard parameters.

Wensing, Kim, Slotine, "Linear matrix inequalities for physically consistent inertial parameter
identification: a statistical perspective on the mass distribution", IEEE RA-L 3(1), 2018
(arXiv 2017), eq. (5)-(9): for a rigid body with density rho in frame i,

    J = [[Sigma, h], [h^T, m]] = integral of [r; 1][r; 1]^T rho dV,   Sigma = 0.5 tr(I) E - I,

with m the mass, h = m c the first moment and Sigma the second moment of the mass about the frame
origin (I is the inertia tensor about that origin, the standard parameters' I). J is linear in the
10 standard parameters [m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz], and a mass distribution with
these moments exists exactly when J is positive semidefinite (Theorem 1). J positive *definite* is
m > 0 and Sigma_c = Sigma - h h^T / m (the second moment about the centre of mass) positive
definite, i.e. an inertia about the centre of mass I_c = tr(Sigma_c) E - Sigma_c that is positive
definite with strict triangle inequalities (I_c,x + I_c,y - I_c,z = 2 Sigma_c,zz > 0): what
``Robot.is_physically_consistent`` checks.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def pseudo_inertia(parameters: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 4x4 pseudo-inertia J of one link from its 10 standard parameters."""
    m, mx, my, mz, ixx, ixy, ixz, iyy, iyz, izz = np.asarray(parameters, dtype=float)
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    J = np.empty((4, 4))
    J[:3, :3] = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    J[:3, 3] = J[3, :3] = (mx, my, mz)
    J[3, 3] = m
    return J


def standard_from_pseudo_inertia(J: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 10 standard parameters of the symmetric 4x4 pseudo-inertia J (inverse of
    :func:`pseudo_inertia`): I = tr(Sigma) E - Sigma."""
    J = 0.5 * (np.asarray(J, dtype=float) + np.asarray(J, dtype=float).T)
    sigma = J[:3, :3]
    inertia = np.trace(sigma) * np.eye(3) - sigma
    return np.array(
        [
            J[3, 3],
            J[0, 3],
            J[1, 3],
            J[2, 3],
            inertia[0, 0],
            inertia[0, 1],
            inertia[0, 2],
            inertia[1, 1],
            inertia[1, 2],
            inertia[2, 2],
        ]
    )


def nearest_with_margin(J: NDArray[np.float64], margin: float) -> NDArray[np.float64]:
    """The symmetric matrix closest to J in the Frobenius norm whose eigenvalues are all at
    least ``margin``: J's eigenvalues below ``margin`` raised to it (Higham 1988), the
    eigenvectors kept. J itself when it already satisfies the margin."""
    J = 0.5 * (J + J.T)
    values, vectors = np.linalg.eigh(J)
    if values.min() >= margin:
        return J
    return (vectors * np.maximum(values, margin)) @ vectors.T
