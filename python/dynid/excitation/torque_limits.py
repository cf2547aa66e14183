"""Joint torque limits of an exciting trajectory: SLSQP constraints on a grid, and a bound on
max |tau| over the whole period that holds between the grid points too.

The torque tau(t) = rnea(q(t), qd(t), qdd(t)) (links, rotor inertia, viscous and Coulomb
friction: docs/conventions.md) is not linear in the Fourier coefficients x = (a, b, q0), so
unlike the kinematic limits (optimization._inequalities) it is a nonlinear constraint:
|tau_j(t_k)| <= (1 - TORQUE_MARGIN) tau_max_j on the optimiser's grid, with its exact Jacobian

    d tau / dx = dtau/dq dq/dx + dtau/dqd dqd/dx + M(q) dqdd/dx

from the C++ batch calls ``rnea_derivatives`` and ``mass_matrix`` (notes pp. 46-47; Carpentier &
Mansard 2018). Coulomb friction is flat away from qd = 0 and contributes nothing.

Between grid points (:func:`torque_extents`): on an interval of length h over which no
component of the transmission's w = T qd changes sign, tau is smooth and
max tau <= max(tau(t_k), tau(t_k+1)) + K h^2 / 8 with K a bound of |tau''| there (the error of
linear interpolation). tau'' comes exactly from ``rnea_time_derivatives`` (jerk and snap of the
series are analytic); K is CURVATURE_SAFETY times its largest value on the grid. Where a sign of
w may change (a sign change between the ends, or an end within |w''| h^2 / 8 of zero, which
includes a start at rest), the bound is taken on the smooth part s = tau - T^T Fs sign(w), plus
the largest Coulomb torque sum_i |T_ij| Fs_i.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _core
from .trajectory import FourierTrajectory, _basis, _basis_states, _extents, _finite_array

if TYPE_CHECKING:
    from ..model.robot import Robot

#: Fraction of each torque limit kept free on the optimiser's grid: room for the excursion
#: between its points, so that the final scaling (limit_scaling.NonlinearLimits) rarely has to
#: shrink anything.
TORQUE_MARGIN = 0.02

#: |tau''| between grid points is taken as at most this times its largest value on the grid. On
#: the check grid (10x the optimiser's samples, 2000 points a period by default) tau'' changes
#: by a few percent between neighbours, and its term K h^2 / 8 is ~1e-6 of the torque: the factor
#: covers the first and costs nothing measurable.
CURVATURE_SAFETY = 2.0


def torque_limit_vector(value: ArrayLike, n: int) -> NDArray[np.float64]:
    """``tau_max`` as (n,) positive limits (a scalar for every joint); ValueError naming it."""
    array = _finite_array(value, "tau_max")
    if array.ndim == 0:
        array = np.full(n, float(array))
    if array.shape != (n,) or np.any(array <= 0.0):
        raise ValueError(f"tau_max: expected a positive number or {n} of them, got {value!r}")
    return array


class TorqueConstraint:
    """SLSQP's inequality (tau_limit - tau, tau_limit + tau) >= 0 at every grid point and joint,
    with its Jacobian; the torque and its derivatives are computed once per x."""

    def __init__(
        self, model: Robot, t: NDArray[np.float64], wf: float, harmonics: int, limit: NDArray
    ) -> None:
        self.model, self.n, self.harmonics, self.limit = model, model.n, harmonics, limit
        self.basis = _basis(t, wf, harmonics)
        self._x: NDArray[np.float64] | None = None

    def _states(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        return _basis_states(x, self.n, self.harmonics, self.basis)

    def _update(self, x: NDArray[np.float64]) -> None:
        if self._x is not None and np.array_equal(x, self._x):
            return
        q, qd, qdd = self._states(x)
        self._tau = self.model.rnea(q, qd, qdd)
        dq, dqd = self.model.rnea_derivatives(q, qd, qdd)
        M = self.model.mass_matrix(q)
        Bq, Bqd, Bqdd = self.basis
        # d tau_kj / d c_il = dtau/dq[k,j,i] Bq[k,l] + dtau/dqd[k,j,i] Bqd[k,l] + M[k,j,i] Bqdd[k,l]
        Jc = (
            np.einsum("kji,kl->kjil", dq, Bq)
            + np.einsum("kji,kl->kjil", dqd, Bqd)
            + np.einsum("kji,kl->kjil", M, Bqdd)
        )
        T, n, H = q.shape[0], self.n, self.harmonics
        self._jac = np.concatenate(
            [Jc[..., :H].reshape(T, n, n * H), Jc[..., H:].reshape(T, n, n * H), dq], axis=2
        ).reshape(T * n, -1)
        self._x = x.copy()

    def value(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        self._update(x)
        tau = self._tau.ravel()
        limit = np.tile(self.limit, self._tau.shape[0])
        return np.concatenate([limit - tau, limit + tau])

    def jacobian(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        self._update(x)
        return np.vstack([-self._jac, self._jac])

    def as_dict(self) -> dict[str, Any]:
        return {"type": "ineq", "fun": self.value, "jac": self.jacobian}


def torque_extents(model: Robot, trajectory: FourierTrajectory, samples: int) -> NDArray:
    """Upper bound of max over the whole period of |tau_j(t)|, per joint (see the module)."""
    if trajectory.n != model.n:
        raise ValueError(f"trajectory: expected {model.n} joints, got {trajectory.n}")
    t, q, qd, qdd = trajectory.sample(samples)
    qddd, qdddd = _jerk_and_snap(trajectory, t)
    tau, _, tau_ddot = model.rnea_time_derivatives(q, qd, qdd, qddd, qdddd)
    coulomb = _core._friction_terms(model, qd, 0.0)[:, 1, :]
    smooth = tau - coulomb
    h = trajectory.period / samples
    curvature = CURVATURE_SAFETY * np.abs(tau_ddot).max(axis=0) * h**2 / 8.0

    T = np.asarray(model.transmission)
    w = qd @ T.T  # the drive velocities whose signs switch the Coulomb torque
    # |w''| = |T qddd| <= |T| (H wf max|qdd|) (Bernstein: a trigonometric polynomial of degree H
    # in wf t has |p'| <= H wf max|p|), so on an interval w >= its linear interpolation minus
    # |w''| h^2 / 8: with one sign at both ends and both ends farther than that from zero, w
    # keeps its sign throughout.
    w_curve = np.abs(T) @ (
        trajectory.harmonics * trajectory.base_frequency * _extents(trajectory, samples)[3]
    )

    def neighbours(values: NDArray) -> NDArray:  # max over each interval's two ends (periodic)
        return np.maximum(values, np.roll(values, -1, axis=0))

    w_next = np.roll(w, -1, axis=0)
    same_sign = np.sign(w) * np.sign(w_next) > 0
    clear = np.minimum(np.abs(w), np.abs(w_next)) > w_curve * h**2 / 8.0
    may_switch = ~(same_sign & clear)  # (interval, drive)
    # joint j's Coulomb torque sum_i T_ij Fs_i sign(w_i) switches only with the drives it feels
    no_switch = (may_switch.astype(float) @ (T != 0.0)) == 0.0
    coulomb_max = np.abs(T).T @ model.Fs
    bound = np.where(
        no_switch,
        neighbours(np.abs(tau)),
        neighbours(np.abs(smooth)) + coulomb_max,
    )
    return np.asarray(bound.max(axis=0) + curvature, dtype=np.float64)


def _jerk_and_snap(trajectory: FourierTrajectory, t: NDArray) -> tuple[NDArray, NDArray]:
    """The third and fourth time derivatives of the series at ``t``, (T, n) each:
    qddd_i = sum_l (wf l)^2 (-a_il cos - b_il sin),
    qdddd_i = sum_l (wf l)^3 (a_il sin - b_il cos)."""
    w = trajectory.base_frequency * np.arange(1, trajectory.harmonics + 1)
    S, C = np.sin(np.outer(t, w)), np.cos(np.outer(t, w))
    a, b = trajectory.a, trajectory.b
    jerk = -(C * w**2) @ a.T - (S * w**2) @ b.T
    snap = (S * w**3) @ a.T - (C * w**3) @ b.T
    return jerk, snap
