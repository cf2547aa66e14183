"""Which configuration variables the inertia matrix and the gravity vector depend on: the
notes' "Analysis of inertial couplings" and "Analysis of gravity term" (pp. 2-3), for any arm.

The notes read the structure off the closed forms: a Cartesian robot has a constant diagonal
B; a "skew" Cartesian robot a constant B with b12 != 0; the PR and 2R robots b11(q2), b12(q2) and
a constant b22 (constant B when the centre of mass of link 2 is on joint 2's axis); a 3R
articulated robot, under simplifying assumptions on the centres of mass, b11(q2, q3),
b22(q3), b23(q3), b33 constant and no coupling between joint 1 and the others. The dynamic model
is linear when g = 0 and B is constant (then c = 0, Christoffel symbols of a constant B); g = 0
in the absence of gravity, for motion in a horizontal plane, or with static balancing
(p. 3).

Here the structure is found numerically, from the model itself: at random configurations within
``qlim``, each q_k is moved alone to other random values and every entry B_ij(q) and g_i(q) that
changes is marked as depending on q_k. B and g are analytic in q (sums of products of sines,
cosines and prismatic displacements), so an entry that depends on q_k changes for almost every
such move: a dependence is missed only on a set of measure zero. An entry is zero when it is
within ``tolerance`` times the largest |B| (|g|) at every configuration tried, constant when it
depends on no q_k.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks as checks
from .robot import Robot


@dataclass(frozen=True)
class DynamicStructure:
    """The dependence of B(q) and g(q) on the joint variables (0-based joint indices)."""

    #: inertia[i][j]: the joints B_ij depends on; () for a constant entry
    inertia: tuple[tuple[tuple[int, ...], ...], ...]
    inertia_zero: NDArray[np.bool_]  #: (n, n) B_ij = 0 everywhere tried
    #: gravity[i]: the joints g_i depends on; () for a constant entry
    gravity: tuple[tuple[int, ...], ...]
    gravity_zero: NDArray[np.bool_]  #: (n,) g_i = 0 everywhere tried

    @property
    def inertia_constant(self) -> bool:
        """B constant: then c(q, qd) = 0 (notes p. 2)."""
        return all(not deps for row in self.inertia for deps in row)

    @property
    def no_gravity(self) -> bool:
        """g = 0 at every configuration (notes p. 3)."""
        return bool(self.gravity_zero.all())

    @property
    def linear(self) -> bool:
        """The dynamic model is linear, B qdd = tau (g = 0 and B constant, notes p. 2)."""
        return self.inertia_constant and self.no_gravity

    def entry(self, i: int, j: int) -> str:
        """B_ij in the notes' words: "0", "const" or "b(q2, q3)" (1-based joints)."""
        if self.inertia_zero[i, j]:
            return "0"
        deps = self.inertia[i][j]
        return "const" if not deps else "b(" + ", ".join(f"q{k + 1}" for k in deps) + ")"

    def table(self) -> str:
        """B's structure as a matrix of entries, then g's, as text."""
        n = len(self.inertia)
        cells = [[self.entry(i, j) for j in range(n)] for i in range(n)]
        width = max(len(c) for row in cells for c in row)
        lines = ["B(q):"] + ["  " + "  ".join(f"{c:<{width}}" for c in row) for row in cells]
        words = [
            "0"
            if self.gravity_zero[i]
            else ("const" if not deps else f"g(q{', q'.join(str(k + 1) for k in deps)})")
            for i, deps in enumerate(self.gravity)
        ]
        lines.append("g(q): " + "  ".join(words))
        verdict = (
            "linear (g = 0, B constant)"
            if self.linear
            else ("c = 0 (B constant)" if self.inertia_constant else "nonlinear")
        )
        lines.append(f"dynamic model: {verdict}")
        return "\n".join(lines)


def dynamic_structure(
    robot: Robot, samples: int = 8, seed: int = 0, tolerance: float = 1e-9
) -> DynamicStructure:
    """The structure of ``robot``'s B(q) and g(q) (module docstring): ``samples`` random
    configurations within ``robot.qlim``, each q_k moved alone to ``samples`` other values.
    ValueError naming a bad argument."""
    checks.robot(robot)
    samples = checks.count(samples, "samples", 1)
    if not (isinstance(tolerance, (int, float)) and 0 < tolerance < 1):
        raise ValueError(f"tolerance: expected a number in (0, 1), got {tolerance!r}")
    n = robot.n
    rng = np.random.default_rng(seed)
    low, high = robot.qlim[:, 0], robot.qlim[:, 1]
    base = rng.uniform(low, high, (samples, n))
    B, g = robot.mass_matrix(base), robot.gravity(base)
    scale_B = max(float(np.abs(B).max()), float(np.finfo(float).tiny))
    # Gravity torques are measured against |g0| times the total mass times the arm's reach (a
    # torque g could have), not against the largest g found: g = 0 up to rounding must be zero.
    reach = max(1e-3, float(np.abs(robot.dh[:, [0, 2]]).sum()))
    weight = float(np.linalg.norm(robot.gravity_vector)) * float(np.abs(robot.params[:, 0]).sum())
    scale_g = max(weight * reach, float(np.abs(g).max()), float(np.finfo(float).tiny))
    depends_B: NDArray[np.bool_] = np.zeros((n, n, n), dtype=bool)  # [i, j, k]: B_ij depends on q_k
    depends_g: NDArray[np.bool_] = np.zeros((n, n), dtype=bool)  # [i, k]: g_i depends on q_k
    zero_B = np.all(np.abs(B) <= tolerance * scale_B, axis=0)
    zero_g = np.all(np.abs(g) <= tolerance * scale_g, axis=0)
    for k in range(n):
        moved = np.repeat(base, samples, axis=0)
        moved[:, k] = rng.uniform(low[k], high[k], moved.shape[0])
        B_k, g_k = robot.mass_matrix(moved), robot.gravity(moved)
        dB = np.abs(B_k - np.repeat(B, samples, axis=0)).max(axis=0)
        dg = np.abs(g_k - np.repeat(g, samples, axis=0)).max(axis=0)
        depends_B[:, :, k] = dB > tolerance * scale_B
        depends_g[:, k] = dg > tolerance * scale_g
        zero_B &= np.all(np.abs(B_k) <= tolerance * scale_B, axis=0)
        zero_g &= np.all(np.abs(g_k) <= tolerance * scale_g, axis=0)
    inertia = tuple(
        tuple(tuple(int(k) for k in np.flatnonzero(depends_B[i, j])) for j in range(n))
        for i in range(n)
    )
    gravity = tuple(tuple(int(k) for k in np.flatnonzero(depends_g[i])) for i in range(n))
    return DynamicStructure(inertia, zero_B, gravity, zero_g)
