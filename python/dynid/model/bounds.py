"""Estimates of the bounds on the dynamic terms over the joint ranges (notes p. 4).

For a serial arm there are positive constants k0..k7 with, for all q and qd (notes p. 4),

    k0 <= ||B(q)|| <= k1 + k2 ||q|| + k3 ||q||^2,
    ||S(q, qd)|| <= ||qd|| (k4 + k5 ||q||),
    ||g(q)|| <= k6 + k7 ||q||,

norms being Euclidean for vectors and induced (spectral) for matrices; with revolute joints only
they reduce to k0 <= ||B(q)|| <= k1, ||S(q, qd)|| <= k4 ||qd||, ||g(q)|| <= k6. Over the bounded
joint ranges ``robot.qlim`` the terms in ||q|| are bounded as well, so the constant form holds for
any joint types there, and this module estimates its four constants:

- k0 = min over q of the smallest eigenvalue of M(q): the lower bound used in control
  (k0 ||x||^2 <= x^T M(q) x, ||M(q)^-1|| <= 1/k0); it is also a lower bound of ||M(q)||;
- k1 = max over q of the largest eigenvalue of M(q) = ||M(q)||;
- k4 = max over q and unit qd of ||S(q, qd)||, S the Christoffel factorisation
  (``robot.coriolis_matrix``; another factorisation has another k4);
- k6 = max over q of ||g(q)||.

M(q) = B(q) + diag(Ia) is ``robot.mass_matrix`` (rotor inertias included). k2, k3, k5, k7, the
growth with the prismatic displacements for every q, are :mod:`dynid.model.growth_bounds`'.

These are ESTIMATES, not guaranteed bounds: extreme values of non-convex functions, found by
evaluating the terms at ``samples`` random configurations (uniform in ``qlim``; unit velocity
directions uniform on the sphere for k4) with batch C++ calls, then refining the best sample of
every block of ``samples_per_start`` consecutive samples by a local optimisation (SciPy's L-BFGS-B
within ``qlim``, finite-difference gradients). k0 may only be too high and k1, k4, k6 too low. The
samples are a prefix-stable random sequence (seeded), so with more samples the samples and the
starting points only grow in number and no estimate gets worse.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.optimize
from numpy.typing import NDArray

from .. import _checks as checks
from .._checks import count
from .._equality import ValueEquality
from .robot import Robot

#: L-BFGS-B settings of the local refinement: tight, the functions are cheap and smooth away from
#: repeated eigen/singular values.
_OPTIONS = {"ftol": 1e-15, "gtol": 1e-12, "maxiter": 500}


@dataclass(frozen=True, eq=False)
class BoundEstimate(ValueEquality):
    """One constant: its estimate and where it is attained."""

    value: float  #: the estimate (sampled, then locally refined)
    sampled: float  #: the best value over the random samples alone
    q: NDArray[np.float64]  #: (n,) configuration attaining ``value``
    qd: NDArray[np.float64] | None  #: (n,) unit velocity attaining it (k4 only)


@dataclass(frozen=True, eq=False)
class DynamicBounds(ValueEquality):
    """Estimates of the notes' k0, k1, k4, k6 (p. 4) over ``qlim``; see :func:`dynamic_bounds`."""

    k0: BoundEstimate  #: min_q lambda_min(M(q))
    k1: BoundEstimate  #: max_q lambda_max(M(q)) = max_q ||M(q)||
    k4: BoundEstimate  #: max_{q, ||qd|| = 1} ||S(q, qd)||
    k6: BoundEstimate  #: max_q ||g(q)||
    qlim: NDArray[np.float64]  #: (n, 2) the joint ranges searched
    samples: int  #: random samples evaluated
    starts: int  #: local optimisations run per constant

    def as_dict(self) -> dict[str, float]:
        """{"k0": ..., "k1": ..., "k4": ..., "k6": ...}."""
        return {name: getattr(self, name).value for name in ("k0", "k1", "k4", "k6")}


def dynamic_bounds(
    robot: Robot,
    samples: int = 4000,
    *,
    samples_per_start: int = 500,
    optimize: bool = True,
    seed: int = 0,
) -> DynamicBounds:
    """Estimate k0, k1, k4, k6 of the notes (p. 4) over ``robot.qlim``.

    Parameters
    ----------
    robot
        The arm; its ``qlim`` are the ranges searched, its ``mass_matrix``, ``coriolis_matrix``
        and ``gravity`` the terms bounded.
    samples
        Random configurations evaluated (batch C++ calls), >= ``samples_per_start``.
    samples_per_start
        A local optimisation starts from the best sample of each full block of this many
        consecutive samples: ``samples // samples_per_start`` starts per constant.
    optimize
        False keeps the sampled values (no local refinement).
    seed
        Seed of the random samples.

    Returns
    -------
    DynamicBounds, each constant with its sampled and refined value and the configuration (and,
    for k4, the unit velocity) attaining it. See the module docstring: estimates, not guarantees.
    """
    if not isinstance(robot, Robot):
        raise ValueError(f"robot: expected a dynid.Robot, got {type(robot).__name__}")
    per_start = count(samples_per_start, "samples_per_start", 1)
    samples = count(
        samples, "samples", per_start, "at least one block of samples_per_start samples"
    )
    optimize = checks.flag(optimize, "optimize")
    seed = count(seed, "seed", 0)
    n = robot.n
    low, high = robot.qlim[:, 0], robot.qlim[:, 1]
    q_stream, direction_stream = np.random.SeedSequence(seed).spawn(2)
    Q = low + (high - low) * np.random.default_rng(q_stream).random((samples, n))
    U = np.random.default_rng(direction_stream).standard_normal((samples, n))
    U /= np.linalg.norm(U, axis=1, keepdims=True)

    # Each constant as "maximise f": k0 maximises -lambda_min. Batch values from one C++ call.
    eig = np.linalg.eigvalsh(robot.mass_matrix(Q))
    sampled = {
        "k0": -eig[:, 0],
        "k1": eig[:, -1],
        "k4": np.linalg.norm(robot.coriolis_matrix(Q, U), ord=2, axis=(1, 2)),
        "k6": np.linalg.norm(robot.gravity(Q), axis=1),
    }
    single = {
        "k0": lambda q: -np.linalg.eigvalsh(robot.mass_matrix(q))[0],
        "k1": lambda q: np.linalg.eigvalsh(robot.mass_matrix(q))[-1],
        "k6": lambda q: float(np.linalg.norm(robot.gravity(q))),
    }
    starts = samples // per_start if optimize else 0
    results = {}
    for name, values in sampled.items():
        if name == "k4":
            results[name] = _coriolis_bound(robot, Q, U, values, per_start, starts)
        else:
            results[name] = _refine(single[name], Q, values, robot.qlim, per_start, starts)
    k0 = results["k0"]
    results["k0"] = BoundEstimate(-k0.value, -k0.sampled, k0.q, None)
    return DynamicBounds(**results, qlim=robot.qlim.copy(), samples=samples, starts=starts)


def _block_best(values: NDArray[np.float64], per_start: int, starts: int) -> list[int]:
    """Index of the best sample in each of the first ``starts`` full blocks."""
    return [
        k * per_start + int(np.argmax(values[k * per_start : (k + 1) * per_start]))
        for k in range(starts)
    ]


def _refine(
    f: Callable[[NDArray[np.float64]], float],
    Q: NDArray[np.float64],
    values: NDArray[np.float64],
    qlim: NDArray[np.float64],
    per_start: int,
    starts: int,
) -> BoundEstimate:
    """Maximise f over the box qlim from the block-best samples; never below the best sample."""
    best = int(np.argmax(values))
    value, q = float(values[best]), Q[best].copy()
    sampled = value
    for i in _block_best(values, per_start, starts):
        res = scipy.optimize.minimize(
            lambda x: -f(x),
            Q[i],
            method="L-BFGS-B",
            bounds=list(map(tuple, qlim)),
            options=_OPTIONS,
        )
        x = np.clip(res.x, qlim[:, 0], qlim[:, 1])
        fx = f(x)
        if fx > value:
            value, q = float(fx), x
    return BoundEstimate(value, sampled, q, None)


def _coriolis_bound(
    robot: Robot,
    Q: NDArray[np.float64],
    U: NDArray[np.float64],
    values: NDArray[np.float64],
    per_start: int,
    starts: int,
) -> BoundEstimate:
    """k4: maximise ||S(q, u / ||u||)|| over q in qlim and u free (S is linear in qd)."""
    n = robot.n

    def norm(x: NDArray[np.float64]) -> float:
        q, u = x[:n], x[n:]
        length = np.linalg.norm(u)
        if length == 0.0:
            return 0.0
        return float(np.linalg.norm(robot.coriolis_matrix(q, u / length), 2))

    best = int(np.argmax(values))
    value, q, qd = float(values[best]), Q[best].copy(), U[best].copy()
    sampled = value
    bounds = list(map(tuple, robot.qlim)) + [(None, None)] * n
    for i in _block_best(values, per_start, starts):
        res = scipy.optimize.minimize(
            lambda x: -norm(x),
            np.concatenate([Q[i], U[i]]),
            method="L-BFGS-B",
            bounds=bounds,
            options=_OPTIONS,
        )
        x = res.x.copy()
        x[:n] = np.clip(x[:n], robot.qlim[:, 0], robot.qlim[:, 1])
        fx = norm(x)
        if fx > value and np.linalg.norm(x[n:]) > 0:
            value, q, qd = fx, x[:n], x[n:] / np.linalg.norm(x[n:])
    return BoundEstimate(value, sampled, q, qd)
