"""How the dynamic terms grow with the prismatic displacements: the notes' k2, k3, k5, k7 (p. 4).

For all q and qd (notes p. 4)

    ||B(q)|| <= k1 + k2 ||q|| + k3 ||q||^2,   ||S(q, qd)|| <= ||qd|| (k4 + k5 ||q||),
    ||g(q)|| <= k6 + k7 ||q||,

with k2 = k3 = k5 = k7 = 0 for revolute joints only (dynid.dynamic_bounds estimates k0, k1, k4,
k6 over the joint ranges). The growth comes from the prismatic joints: a prismatic displacement
d moves the links beyond it along a line, so positions are affine in d, the Jacobians too, and
B(q) is exactly a polynomial of degree 2 in the displacements, g of degree 1, at fixed revolute
angles. Along a unit direction u of the displacements, q = q_r + t u:

    B = B0 + t B1 + t^2 B2,   S(., v) = S0 + t S1 + t^2 S2,   g = g0 + t g1,

the coefficients exact from three values (t = -1, 0, 1), and, with |t| <= ||q|| and the
triangle inequality, k1 = max ||B0||, k2 = max ||B1||, k3 = max ||B2||, k4 = max ||S0||,
k5 = max ||S1||, k6 = max ||g0||, k7 = max ||g1|| (over the revolute angles within ``qlim``, the
unit directions u and unit velocities v) bound the terms for every displacement; this module
estimates those maxima by sampling (estimates, as dynid.dynamic_bounds').

**The Coriolis bound can grow quadratically.** The Christoffel symbols of B are derivatives of
B; a derivative in a revolute angle keeps B's d^2 terms, so S can hold terms in d^2 (an R-R-P arm:
b11 = m3 d3^2 sin^2 q2 + ..., c112 = m3 d3^2 sin q2 cos q2). Then no k4 + k5 ||q|| bounds
||S||/||qd|| for all q: ``k5_quadratic`` = max ||S2|| is reported, and it is 0 exactly when the
notes' form holds (e.g. a polar R-P arm, or a Cartesian robot).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks as checks
from .._checks import count
from .robot import Robot


@dataclass(frozen=True)
class GrowthBounds:
    """Estimates of the notes' bounds on B, S and g for every prismatic displacement (module
    docstring); all growth terms are 0 for an arm of revolute joints only."""

    k1: float  #: max ||B0||: B at zero displacement
    k2: float  #: max ||B1||: B's growth linear in the displacement
    k3: float  #: max ||B2||: quadratic
    k4: float  #: max ||S0|| per unit velocity
    k5: float  #: max ||S1|| per unit velocity: linear growth
    k5_quadratic: float  #: max ||S2||: quadratic growth (0 where the notes' form holds)
    k6: float  #: max ||g0||
    k7: float  #: max ||g1||
    samples: int


def growth_bounds(robot: Robot, samples: int = 2000, seed: int = 0) -> GrowthBounds:
    """Estimate the bounds' constants (module docstring) from ``samples`` random revolute angles
    (uniform within ``robot.qlim``), unit displacement directions and unit velocities."""
    checks.robot(robot)
    samples = count(samples, "samples", 1)
    n = robot.n
    prismatic = np.array([t == "P" for t in robot.joint_types])
    rng = np.random.default_rng(seed)
    low, high = robot.qlim[:, 0], robot.qlim[:, 1]
    base = rng.uniform(low, high, (samples, n))
    base[:, prismatic] = 0.0  # the displacements are along u below
    u = np.zeros((samples, n))
    if prismatic.any():
        direction = rng.standard_normal((samples, int(prismatic.sum())))
        u[:, prismatic] = direction / np.linalg.norm(direction, axis=1, keepdims=True)
    v = rng.standard_normal((samples, n))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    minus, zero, plus = base - u, base, base + u
    B = [robot.mass_matrix(x) for x in (minus, zero, plus)]
    S = [robot.coriolis_matrix(x, v) for x in (minus, zero, plus)]
    g = [robot.gravity(x) for x in (minus, zero, plus)]

    def spectral(A: NDArray[np.float64]) -> float:
        return float(np.linalg.norm(A, ord=2, axis=(1, 2)).max())

    def euclid(a: NDArray[np.float64]) -> float:
        return float(np.linalg.norm(a, axis=1).max())

    # the quadratic through t = -1, 0, 1: c0 = f(0), c1 = (f(1) - f(-1)) / 2,
    # c2 = (f(1) + f(-1)) / 2 - f(0)
    return GrowthBounds(
        k1=spectral(B[1]),
        k2=spectral(0.5 * (B[2] - B[0])),
        k3=spectral(0.5 * (B[2] + B[0]) - B[1]),
        k4=spectral(S[1]),
        k5=spectral(0.5 * (S[2] - S[0])),
        k5_quadratic=spectral(0.5 * (S[2] + S[0]) - S[1]),
        k6=euclid(g[1]),
        k7=euclid(0.5 * (g[2] - g[0])),
        samples=samples,
    )
