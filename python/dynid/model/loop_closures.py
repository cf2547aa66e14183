"""Loop closures: how the joints of a closed chain's spanning tree follow its independent ones.

A closed chain is modelled as a spanning tree (the chain with one joint of the loop cut open) plus
the closure: the tree's m joint positions y are functions y = gamma(q) of the n independent
(actuated) joint positions q, so that

    yd = G(q) qd,    ydd = G(q) qdd + Gdot(q, qd) qd,    G = d gamma / d q  (m, n).

:class:`dynid.model.closed_chain.ClosedChain` projects the tree's dynamics with G (Nakamura and
Ghodoussi, "Dynamics computation of closed-link robot mechanisms with nonredundant and redundant
actuators", IEEE Trans. Robotics and Automation 5(3), 1989; Featherstone, "Rigid Body Dynamics
Algorithms", 2008, section 8.2). Two closures:

- :class:`LinearClosure`: y = G q + offset with a constant G, as in the notes' parallelogram
  (p. 7: theta_1 = theta_3 = q1, theta_2 = theta_4 = q2), where Gdot = 0;
- :class:`PointClosure`: a general single loop whose cut joint makes two points coincide (a
  revolute joint of a planar loop, a spherical joint of a spatial one): the passive joints are
  solved by Newton's method, G and Gdot qd from the loop's constraint Jacobian.

All functions take batches: q, qd, qdd of shape (T, n) and return (T, m) and (T, m, n).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .robot import Robot

#: Newton's method on the loop equations stops when the closure error is below this (m) ...
CLOSURE_TOLERANCE = 1e-13
#: ... or, when it cannot get there for rounding, when its steps are below ROUNDING_STEP times
#: the passive angles and the error below ROUNDING_ERROR (m) ...
ROUNDING_STEP = 1e-14
ROUNDING_ERROR = 1e-10
#: ... or gives up after this many iterations (quadratic convergence needs ~5 from a near guess).
MAX_ITERATIONS = 50
#: The continuation's steps are halved up to this many times when a step jumps branch.
REFINEMENTS = 6
#: A step's passive motion may differ from the trapezoid rule on its end tangents by this fraction.
JUMP_FRACTION = 0.1
#: A passive-joint constraint Jacobian worse conditioned than this is a singular configuration:
#: the passive velocities (G) would carry a relative error above ~cond * eps = 2e-8.
SINGULAR_CONDITION = 1e8
#: The largest step of the independent joints between two Newton solves of the continuation [rad].
CONTINUATION_STEP = 0.25


class Closure(Protocol):
    """The map from independent joint motion to the spanning tree's joint motion."""

    tree_dof: int
    dof: int

    def tree_motion(
        self,
        branches: Sequence[Robot],
        q: NDArray[np.float64],
        qd: NDArray[np.float64] | None = None,
        qdd: NDArray[np.float64] | None = None,
    ) -> Motion: ...


class Motion:
    """y, yd, ydd (T, m) and G (T, m, n) of one batch (yd, ydd zero when not asked)."""

    __slots__ = ("G", "y", "yd", "ydd")

    def __init__(
        self,
        y: NDArray[np.float64],
        yd: NDArray[np.float64],
        ydd: NDArray[np.float64],
        G: NDArray[np.float64],
    ) -> None:
        self.y, self.yd, self.ydd, self.G = y, yd, ydd, G


class LinearClosure:
    """y = matrix @ q + offset with a constant (m, n) matrix: Gdot = 0 (parallelogram loops)."""

    def __init__(self, matrix: ArrayLike, offset: ArrayLike | None = None) -> None:
        G = np.array(matrix, dtype=float)
        if G.ndim != 2 or G.shape[0] < G.shape[1] or not np.all(np.isfinite(G)):
            raise ValueError(f"matrix: expected a finite (m, n) matrix with m >= n, got {G.shape}")
        if np.linalg.matrix_rank(G) < G.shape[1]:
            raise ValueError("matrix: the independent joints must move the tree independently")
        self.matrix = G
        self.offset = np.zeros(G.shape[0]) if offset is None else np.array(offset, dtype=float)
        if self.offset.shape != (G.shape[0],) or not np.all(np.isfinite(self.offset)):
            raise ValueError(f"offset: expected {G.shape[0]} finite values")
        self.tree_dof, self.dof = G.shape

    def tree_motion(
        self,
        branches: Sequence[Robot],
        q: NDArray[np.float64],
        qd: NDArray[np.float64] | None = None,
        qdd: NDArray[np.float64] | None = None,
    ) -> Motion:
        G = self.matrix
        zero = np.zeros((q.shape[0], self.tree_dof))
        yd = zero if qd is None else qd @ G.T
        ydd = zero if qdd is None else qdd @ G.T
        return Motion(q @ G.T + self.offset, yd, ydd, np.broadcast_to(G, (q.shape[0], *G.shape)))


class PointClosure:
    """A single loop cut at a joint that makes the tool points of two branches coincide.

    ``branches[a]`` and ``branches[b]`` (``between=(a, b)``) end, through their ``tool``
    transforms, at the two halves of the cut joint; the loop equations are the world
    ``components`` of p_a(y) - p_b(y) = 0 (``(0, 1)`` for a revolute cut in a loop moving in the
    base x-y plane, ``(0, 1, 2)`` for a spherical cut). ``actuated`` lists the tree joints (indices
    into the concatenated branch joints) that are the independent coordinates q, in order; the
    others are passive, as many as there are equations. ``assembly`` (m tree positions) is the
    starting guess of Newton's method and picks the assembly mode (e.g. elbow up or down of a
    five-bar); every sample starts from it (not from its neighbour's solution), so that a result
    does not depend on the batch it came in. Random configurations for the base parameters are
    drawn within ``sample_span`` rad of the assembly's independent joints, where the loop closes.
    """

    def __init__(
        self,
        between: tuple[int, int],
        actuated: Sequence[int],
        assembly: ArrayLike,
        components: Sequence[int] = (0, 1),
        sample_span: float = 0.3,
    ) -> None:
        self.between = (int(between[0]), int(between[1]))
        if self.between[0] == self.between[1]:
            raise ValueError("between: the loop joins two different branches")
        self.assembly = np.array(assembly, dtype=float)
        if self.assembly.ndim != 1 or not np.all(np.isfinite(self.assembly)):
            raise ValueError("assembly: expected a finite vector of the tree's joint positions")
        self.tree_dof = self.assembly.size
        self.actuated = np.array(actuated, dtype=int)
        if np.unique(self.actuated).size != self.actuated.size or not np.all(
            (self.actuated >= 0) & (self.actuated < self.tree_dof)
        ):
            raise ValueError(f"actuated: expected distinct tree joint indices < {self.tree_dof}")
        self.components = np.array(components, dtype=int)
        if not np.all(np.isin(self.components, (0, 1, 2))) or np.unique(self.components).size != (
            self.components.size
        ):
            raise ValueError("components: expected distinct world axes among 0, 1, 2")
        self.passive = np.setdiff1d(np.arange(self.tree_dof), self.actuated)
        if self.passive.size != self.components.size:
            raise ValueError(
                f"components: {self.components.size} loop equations for {self.passive.size} "
                "passive joints (a single loop needs as many as it has passive joints)"
            )
        self.dof = self.actuated.size
        if not (np.isfinite(sample_span) and sample_span > 0):
            raise ValueError(f"sample_span: expected a positive angle, got {sample_span!r}")
        self.sample_span = float(sample_span)
        self.sample_center = self.assembly[self.actuated]

    def tree_motion(
        self,
        branches: Sequence[Robot],
        q: NDArray[np.float64],
        qd: NDArray[np.float64] | None = None,
        qdd: NDArray[np.float64] | None = None,
    ) -> Motion:
        T, m = q.shape[0], self.tree_dof
        start = self.assembly[self.actuated]
        # Whole turns of a revolute independent joint do not change the mechanism: follow the
        # shortest path from the assembly, then put the turns back.
        types = "".join(b.joint_types for b in branches)
        revolute = np.array([types[j] == "R" for j in self.actuated])
        turns = np.where(revolute, 2.0 * np.pi * np.round((q - start) / (2.0 * np.pi)), 0.0)
        near = q - turns
        base_steps = max(
            1, int(np.ceil(np.max(np.abs(near - start), initial=0.0) / CONTINUATION_STEP))
        )
        # Samples whose path jumps branch are followed again with twice as many steps, alone.
        followed = np.empty((T, m))
        pending = np.arange(T)
        for refinement in range(REFINEMENTS + 1):
            y_part, jumped = self._continuation(branches, near[pending], base_steps * 2**refinement)
            followed[pending] = y_part
            pending = pending[jumped]
            if pending.size == 0:
                break
        else:
            raise ValueError(
                "q: the loop cannot be closed along the path from the assembly: outside the "
                "mechanism's workspace, or through or near a singularity where the passive joints "
                f"would jump to another assembly mode ({pending.size} of {T} samples, the first "
                f"at q = {q[pending[0]].tolist()})"
            )
        y = followed
        y[:, self.actuated] = q
        _, A = self._constraint(branches, y)
        A_a, A_p = A[:, :, self.actuated], A[:, :, self.passive]
        if np.any(np.linalg.cond(A_p) > SINGULAR_CONDITION):
            raise ValueError(
                "q: the loop is at or near a singularity (the passive joints' constraint "
                f"Jacobian has a condition number above {SINGULAR_CONDITION:.0e})"
            )
        # Velocity: A_a qd + A_p yd_p = 0, so G = [I; -A_p^-1 A_a] (rows rearranged).
        G = np.zeros((T, m, self.dof))
        G[:, self.actuated, np.arange(self.dof)] = 1.0
        G[:, self.passive, :] = -np.linalg.solve(A_p, A_a)
        zero = np.zeros((T, m))
        yd = zero if qd is None else np.einsum("tij,tj->ti", G, qd)
        ydd = zero
        if qdd is not None:
            # Acceleration: A ydd + Adot yd = 0, Adot yd = the points' accelerations at ydd = 0.
            bias = self._bias(branches, y, zero if qd is None else yd)
            ydd = np.einsum("tij,tj->ti", G, qdd)
            ydd[:, self.passive] -= np.linalg.solve(A_p, bias[..., None])[..., 0]
        return Motion(y, yd, ydd, G)

    def _continuation(
        self, branches: Sequence[Robot], q: NDArray[np.float64], steps: int
    ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """The tree positions at q, followed from the assembly in ``steps`` steps, and which
        samples jumped branch on the way (a step's passive motion disagreeing with the tangents
        at its ends).

        Each step predicts the passive joints along the tangent (dy_p = -A_p^-1 A_a dq) and
        Newton corrects them. Without the predictor, Newton from the previous step's passive
        joints lands on another branch near a bifurcation (a parallelogram close to folding flat
        jumps to the crossed "anti-parallelogram"); the check catches what the predictor misses:
        on the same branch dy_p equals the trapezoid rule on the two tangents to O(dq^3). Near a
        fold of the loop (a five-bar's couplers almost folded onto each other) the two assembly
        modes come close and a step can tunnel to the other one with tangents that agree; the
        modes are separated by the singular configurations det(A_p) = 0, so a change of the sign
        of det(A_p) along the path is a jump too (tests/test_closed_chain_pinocchio.py)."""
        start = self.assembly[self.actuated]
        y = np.empty((q.shape[0], self.tree_dof))
        y[:] = self.assembly
        self._newton(branches, y)
        dq = (q - start) / steps
        tangent, mode = self._tangent(branches, y, dq)
        jumped = np.zeros(q.shape[0], dtype=bool)
        for step in range(steps):
            before = y[:, self.passive].copy()
            y[:, self.actuated] = q if step == steps - 1 else start + dq * (step + 1)
            y[:, self.passive] += tangent
            self._newton(branches, y, jumped)
            moved = y[:, self.passive] - before
            tangent_after, mode_after = self._tangent(branches, y, dq)
            mismatch = np.abs(moved - 0.5 * (tangent + tangent_after))
            scale = np.maximum(np.abs(moved), np.maximum(np.abs(tangent), np.abs(tangent_after)))
            jumped |= np.any(mismatch > JUMP_FRACTION * scale + 1e-12, axis=1)
            jumped |= mode_after != mode
            tangent = tangent_after
        return y, jumped

    def _tangent(
        self, branches: Sequence[Robot], y: NDArray[np.float64], dq: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The passive joints' first-order motion -A_p^-1 A_a dq (zero where A_p is singular)
        and the sign of det(A_p), which tells the assembly modes apart."""
        _, A = self._constraint(branches, y)
        A_p = A[:, :, self.passive]
        step = -_solve(A_p, A[:, :, self.actuated] @ dq[..., None])
        return np.where(np.isfinite(step[..., 0]), step[..., 0], 0.0), np.sign(np.linalg.det(A_p))

    def _newton(
        self,
        branches: Sequence[Robot],
        y: NDArray[np.float64],
        given_up: NDArray[np.bool_] | None = None,
    ) -> None:
        """Solve the loop equations for the passive joints of ``y`` in place. Samples marked in
        ``given_up`` (already off their branch, to be followed again) are marked there when they
        do not converge instead of raising."""
        for _ in range(MAX_ITERATIONS):
            error, A = self._constraint(branches, y)
            size = np.max(np.abs(error), axis=1, initial=0.0)
            if given_up is not None:
                size[given_up] = 0.0
            if np.all(size < CLOSURE_TOLERANCE):
                return
            # Newton on the passive joints: A_p dy_p = -error
            step = _solve(A[:, :, self.passive], -error[..., None])[..., 0]
            stuck = ~np.all(np.isfinite(step), axis=1)
            if given_up is not None:
                given_up |= stuck
                step[given_up] = 0.0
            elif stuck.any():
                break
            # At the rounding floor (large angles after many turns, a large mechanism) the error
            # stops falling below CLOSURE_TOLERANCE while the steps vanish: converged.
            floor = ROUNDING_STEP * (1.0 + np.abs(y[:, self.passive]))
            if np.all(
                (size < CLOSURE_TOLERANCE)
                | ((size < ROUNDING_ERROR) & np.all(np.abs(step) <= floor, axis=1))
            ):
                return
            y[:, self.passive] += step
        if given_up is not None:
            error = self._constraint(branches, y)[0]
            given_up |= ~(np.max(np.abs(error), axis=1, initial=0.0) < ROUNDING_ERROR)
            return
        worst = float(np.nanmax(np.abs(self._constraint(branches, y)[0])))
        raise ValueError(
            f"q: the loop does not close (error {worst:.3g} m after Newton's method): the "
            "configuration is outside the mechanism's workspace or at a singularity"
        )

    def _split(
        self, branches: Sequence[Robot], y: NDArray[np.float64]
    ) -> list[NDArray[np.float64]]:
        edges = np.cumsum([0] + [b.n for b in branches])
        if edges[-1] != self.tree_dof:
            raise ValueError(f"branches: {edges[-1]} tree joints, the closure has {self.tree_dof}")
        return [y[:, edges[k] : edges[k + 1]] for k in range(len(branches))]

    def _constraint(
        self, branches: Sequence[Robot], y: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The loop error p_a - p_b (T, c) and its Jacobian (T, c, m) in the tree's joints."""
        parts = self._split(branches, y)
        edges = np.cumsum([0] + [b.n for b in branches])
        A = np.zeros((y.shape[0], self.components.size, self.tree_dof))
        error = np.zeros((y.shape[0], self.components.size))
        for sign, k in ((1.0, self.between[0]), (-1.0, self.between[1])):
            pose = branches[k].fkine(parts[k]).reshape(-1, 4, 4)
            J = branches[k].jacobian(parts[k]).reshape(-1, 6, branches[k].n)
            error += sign * pose[:, self.components, 3]
            A[:, :, edges[k] : edges[k + 1]] = sign * J[:, self.components, :]
        return error, A

    def _bias(
        self, branches: Sequence[Robot], y: NDArray[np.float64], yd: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Adot yd (T, c): the difference of the two points' accelerations at zero ydd."""
        parts, rates = self._split(branches, y), self._split(branches, yd)
        bias = np.zeros((y.shape[0], self.components.size))
        for sign, k in ((1.0, self.between[0]), (-1.0, self.between[1])):
            Jdot = branches[k].jacobian_dot(parts[k], rates[k]).reshape(-1, 6, branches[k].n)
            bias += sign * np.einsum("tij,tj->ti", Jdot[:, self.components, :], rates[k])
        return bias


def _solve(A: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Batched A^-1 b; NaN for the samples whose A is exactly singular (the callers check)."""
    with np.errstate(all="ignore"):
        singular = ~(np.abs(np.linalg.det(A)) > 0.0)
        safe = np.where(singular[:, None, None], np.eye(A.shape[-1]), A)
        x = np.asarray(np.linalg.solve(safe, b))
    x[singular] = np.nan
    return x
