"""Optimal point-to-point motion between two configurations at rest (notes, "Optimal
point-to-point motion", p. 50): the minimum-time motion under actuator torque bounds, and the
minimum-energy motion for a given time, with their command torques, for any model.

A direct transcription on a smooth basis, solved by SciPy (SLSQP for the minimum time, L-BFGS-B
for the minimum energy; no solver of our own). With s = t / T in [0, 1] the path is

    q(s) = q_0 + (q_1 - q_0) p(s) + sum_k c_k phi_k(s),   p(s) = 10 s^3 - 15 s^4 + 6 s^5,
    phi_k(s) = s^2 (1 - s)^2 P_{k-1}(2 s - 1)   (Legendre polynomials, k = 1..K),

so q(0) = q_0, q(1) = q_1 and qd = 0 at both ends whatever the coefficients c (n x K); the
velocities and accelerations are q'(s) / T and q''(s) / T^2, and the command torque is the
inverse dynamics tau = rnea(q, qd, qdd) (links, rotor inertia, friction). The energy is the
notes' E = integral of tau^T tau dt, by Gauss-Legendre quadrature on the nodes; the torque bounds
|tau_j| <= tau_max,j are imposed on those nodes and both ends. The gradients are analytic:
dtau/dc from ``rnea_derivatives`` (dtau/dq, dtau/dqd) and the mass matrix (dtau/dqdd).

The basis holds the cubic rest-to-rest motion (p minus a combination of phi_1, phi_2), so the
1-DoF minimum-energy motion (a cubic: E = 12 I^2 (q_1 - q_0)^2 / T^3) is exact; a minimum-time
motion under torque bounds is bang-bang (the torque jumps between its bounds), which a smooth
basis approaches from above as K grows, its torques at the bounds over most of the motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from ..model.robot import Robot


@dataclass(frozen=True)
class OptimalMotion:
    """A point-to-point motion: the samples of its trajectory and command torque, its duration
    and energy, and how the solver ended."""

    t: NDArray[np.float64]  #: (N,) s, from 0 to ``duration``
    q: NDArray[np.float64]  #: (N, n)
    qd: NDArray[np.float64]
    qdd: NDArray[np.float64]
    tau: NDArray[np.float64]  #: (N, n) the command torque, rnea(q, qd, qdd)
    duration: float  #: T [s]
    energy: float  #: integral of tau^T tau dt [N^2 m^2 s]
    coefficients: NDArray[np.float64]  #: (n, K) the basis' coefficients c
    success: bool
    message: str


class _Path:
    """The basis at the instants ``s`` (quadrature ``weights``) for n joints and K functions."""

    def __init__(self, q0: NDArray, q1: NDArray, functions: int, s: NDArray, weights: NDArray):
        self.s, self.weights = s, weights
        self.q0, self.delta, self.K = q0, q1 - q0, functions
        p = np.polynomial.Polynomial([0, 0, 0, 10, -15, 6])
        self.p = [p(s), p.deriv(1)(s), p.deriv(2)(s)]
        envelope = np.polynomial.Polynomial([0, 0, 1, -2, 1])  # s^2 (1 - s)^2
        self.phi = np.zeros((3, s.size, functions))
        for k in range(functions):
            shape = legendre.Legendre.basis(k, domain=[0, 1]).convert(kind=np.polynomial.Polynomial)
            f = envelope * shape
            for order in range(3):
                self.phi[order, :, k] = f.deriv(order)(s) if order else f(s)

    @classmethod
    def on_nodes(cls, q0: NDArray, q1: NDArray, functions: int, nodes: int) -> _Path:
        """Gauss-Legendre nodes on [0, 1] and both ends (weight 0: the bounds only)."""
        x, w = legendre.leggauss(nodes)
        s = np.concatenate([[0.0], 0.5 * (x + 1.0), [1.0]])
        return cls(q0, q1, functions, s, np.concatenate([[0.0], 0.5 * w, [0.0]]))

    def states(self, c: NDArray, T: float) -> tuple[NDArray, NDArray, NDArray]:
        q = self.q0 + np.outer(self.p[0], self.delta) + self.phi[0] @ c.T
        dq = np.outer(self.p[1], self.delta) + self.phi[1] @ c.T
        ddq = np.outer(self.p[2], self.delta) + self.phi[2] @ c.T
        return q, dq / T, ddq / T**2


def _torque_and_gradients(
    robot: Robot, path: _Path, c: NDArray, T: float
) -> tuple[NDArray, NDArray, NDArray]:
    """tau (M, n), dtau/dc (M, n, n, K) and dtau/dT (M, n) on the nodes."""
    q, qd, qdd = path.states(c, T)
    tau = robot.rnea(q, qd, qdd)
    d_q, d_qd = robot.rnea_derivatives(q, qd, qdd)
    M = robot.mass_matrix(q)
    phi, dphi, ddphi = path.phi
    # dq_j/dc_jk = phi_k, dqd_j/dc_jk = phi_k' / T, dqdd_j/dc_jk = phi_k'' / T^2
    d_c = (
        d_q[:, :, :, None] * phi[:, None, None, :]
        + d_qd[:, :, :, None] * dphi[:, None, None, :] / T
        + M[:, :, :, None] * ddphi[:, None, None, :] / T**2
    )
    d_T = -np.einsum("mij,mj->mi", d_qd, qd) / T - 2.0 * np.einsum("mij,mj->mi", M, qdd) / T
    return tau, d_c, d_T


def _motion(
    robot: Robot, path: _Path, c: NDArray, T: float, samples: int, result: object
) -> OptimalMotion:
    """The motion of coefficients ``c`` and duration ``T`` sampled at ``samples`` instants."""
    grid = np.linspace(0.0, 1.0, samples)
    dense = _Path(path.q0, path.q0 + path.delta, path.K, grid, np.zeros(samples))
    q, qd, qdd = dense.states(c, T)
    tau = robot.rnea(q, qd, qdd)
    nodes_tau = robot.rnea(*path.states(c, T))
    energy = float(T * path.weights @ np.sum(nodes_tau**2, axis=1))
    return OptimalMotion(
        t=dense.s * T,
        q=q,
        qd=qd,
        qdd=qdd,
        tau=tau,
        duration=float(T),
        energy=energy,
        coefficients=c,
        # L-BFGS-B stopping on a relative reduction below machine precision has converged too
        success=bool(getattr(result, "success", False))
        or str(getattr(result, "message", "")).startswith("CONVERGENCE"),
        message=str(getattr(result, "message", "")),
    )


def minimum_energy_motion(
    robot: Robot,
    q_start: ArrayLike,
    q_end: ArrayLike,
    duration: float,
    *,
    functions: int = 6,
    nodes: int = 40,
    samples: int = 200,
) -> OptimalMotion:
    """The rest-to-rest motion from ``q_start`` to ``q_end`` in ``duration`` seconds minimising
    E = integral of tau^T tau dt (module docstring); ``functions`` basis functions per joint,
    ``nodes`` quadrature nodes, the result sampled at ``samples`` instants."""
    import scipy.optimize

    _, _, path = _setup(robot, q_start, q_end, functions, nodes)
    T = _positive(duration, "duration")
    n, K = robot.n, functions

    def cost(x: NDArray) -> tuple[float, NDArray]:
        c = x.reshape(n, K)
        tau, d_c, _ = _torque_and_gradients(robot, path, c, T)
        w = path.weights * T
        value = float(w @ np.sum(tau**2, axis=1))
        grad = 2.0 * np.einsum("m,mi,mijk->jk", w, tau, d_c)
        return value, grad.ravel()

    result = scipy.optimize.minimize(
        cost, np.zeros(n * K), jac=True, method="L-BFGS-B", options={"maxiter": 2000, "gtol": 1e-12}
    )
    return _motion(robot, path, result.x.reshape(n, K), T, samples, result)


def minimum_time_motion(
    robot: Robot,
    q_start: ArrayLike,
    q_end: ArrayLike,
    tau_max: ArrayLike,
    *,
    functions: int = 6,
    nodes: int = 40,
    samples: int = 200,
    initial_duration: float | None = None,
) -> OptimalMotion:
    """The rest-to-rest motion from ``q_start`` to ``q_end`` of least duration with
    |tau_j| <= tau_max_j on the nodes and both ends (module docstring; SLSQP from the
    minimum-energy motion of ``initial_duration``, by default one that respects the bounds)."""
    import scipy.optimize

    q0, q1, path = _setup(robot, q_start, q_end, functions, nodes)
    bound = np.broadcast_to(real_array(tau_max, "tau_max"), (robot.n,)).astype(float)
    if np.any(~np.isfinite(bound)) or np.any(bound <= 0):
        raise ValueError(f"tau_max: expected finite limits > 0, got {bound}")
    n, K = robot.n, functions
    T0 = _feasible_start(robot, path, bound) if initial_duration is None else initial_duration
    start = minimum_energy_motion(robot, q0, q1, T0, functions=K, nodes=nodes, samples=2)
    x0 = np.concatenate([start.coefficients.ravel(), [np.log(T0)]])

    def split(x: NDArray) -> tuple[NDArray, float]:
        return x[:-1].reshape(n, K), float(np.exp(x[-1]))

    def margins(x: NDArray) -> NDArray:
        c, T = split(x)
        tau = robot.rnea(*path.states(c, T))
        return np.concatenate([(bound - tau).ravel(), (bound + tau).ravel()])

    def margins_jac(x: NDArray) -> NDArray:
        c, T = split(x)
        _, d_c, d_T = _torque_and_gradients(robot, path, c, T)
        rows = d_c.reshape(d_c.shape[0] * n, n * K)
        dlogT = (d_T * T).reshape(-1, 1)
        jac = np.hstack([rows, dlogT])
        return np.vstack([-jac, jac])

    gradient = np.zeros(x0.size)
    gradient[-1] = 1.0
    result = scipy.optimize.minimize(
        lambda x: float(x[-1]),  # log T: the same minimiser, better scaled
        x0,
        jac=lambda x: gradient,
        constraints=[{"type": "ineq", "fun": margins, "jac": margins_jac}],
        method="SLSQP",
        options={"maxiter": 500, "ftol": 1e-10},
    )
    c, T = split(result.x)
    return _motion(robot, path, c, T, samples, result)


def _feasible_start(robot: Robot, path: _Path, bound: NDArray) -> float:
    """A duration whose quintic motion (c = 0) keeps the torques within the bounds: doubled from
    the quintic's own inertial estimate until it does (gravity above the bound: ValueError)."""
    T = 1.0
    for _ in range(60):
        tau = robot.rnea(*path.states(np.zeros((robot.n, path.K)), T))
        if np.all(np.abs(tau) <= 0.9 * bound):
            return T
        T *= 1.5
    raise ValueError("tau_max: no slow motion stays within the bounds (gravity exceeds them?)")


def _setup(
    robot: Robot, q_start: ArrayLike, q_end: ArrayLike, functions: int, nodes: int
) -> tuple[NDArray, NDArray, _Path]:
    checks.robot(robot)
    q0, q1 = real_array(q_start, "q_start"), real_array(q_end, "q_end")
    for value, name in ((q0, "q_start"), (q1, "q_end")):
        if value.shape != (robot.n,):
            raise ValueError(f"{name}: expected shape ({robot.n},), got {value.shape}")
    functions = checks.count(functions, "functions", 2)
    nodes = checks.count(nodes, "nodes", 4)
    return q0, q1, _Path.on_nodes(q0, q1, functions, nodes)


def _positive(value: float, name: str) -> float:
    number = float(real_array(value, name))
    if not number > 0 or not np.isfinite(number):
        raise ValueError(f"{name}: expected a finite number > 0, got {value!r}")
    return number
