"""Robots with a closed kinematic chain: a spanning tree of serial branches plus a loop closure.

The lecture's closed-chain robots (notes pp. 5-10: the Comau Smart NJ130's parallelogram, the MIT
five-bar arms, the planar parallelogram robot) are modelled by the **equivalent-tree projection**:
cut one joint of the loop, so the mechanism becomes a tree of serial branches hanging from the
fixed base (each a :class:`dynid.Robot`, evaluated by the C++ core in one batch call), and let a
closure (:mod:`dynid.model.loop_closures`) give the tree's joint motion y(q), its Jacobian
G = dy/dq and the bias Gdot qd. By the principle of virtual work the torques at the independent
joints q are

    tau = G^T tau_tree(y, yd, ydd)        (Nakamura and Ghodoussi 1989, eq. 11),

so M(q) = G^T M_tree G, g(q) = G^T g_tree and, since tau_tree = Y_tree(y, yd, ydd) pi is linear in
the links' standard parameters, the closed chain's regressor is G^T Y_tree: the same 10 standard
parameters per link, combined by the loop into its own groupings (for the notes' parallelogram,
p. 9: Izz1 + m1 lc1^2 + Izz3 + m3 lc3^2 + m4 l1^2, ..., m3 l2 lc3 - m4 l1 lc4), found numerically by
:meth:`ClosedChain.base_parameters` as for a serial robot. The drive terms (rotor inertia Ia,
viscous Fv and Coulomb Fs friction) act on the independent joints, where the motors are.

The branches start at the fixed base; a loop hanging from a moving link (the parallelogram of
joints 2-3 on an arm's turret) is modelled with a massless copy of the trunk's joints at the
start of its branch, tied to the trunk by the closure (docs/closed_chains.md). One loop per
:class:`~dynid.model.loop_closures.PointClosure`.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .base_parameters import BaseParameters, from_stacked_regressor
from .loop_closures import Closure, Motion
from .robot import Robot


class ClosedChain:
    """A closed-chain robot: serial ``branches`` from the base, a ``closure`` tying their joints.

    ``links`` numbers the bodies: ``links[k] = (branch, index)`` is the chain's link k + 1 (the
    default: the branches' links in order). A tree link left out of ``links`` must be massless
    (all 10 parameters zero, and kept so: the regressor has no columns for it): a copy of a trunk
    joint that lets a second branch start on a moving link (the loop of a parallelogram between
    joints 2 and 3 hangs from the turret; the closure ties the copy's angle to the trunk's,
    docs/closed_chains.md). The standard parameter vector is the links' 10 parameters each in
    that order (as :meth:`dynid.Robot.parameter_vector`), then the drive terms
    of the n independent joints: Ia, then Fv, then Fs. The branches must have no drive terms of
    their own (the tree's passive joints are frictionless and motorless here).

    Every dynamics call takes one sample (q of shape (n,)) or a batch ((T, n)) as the serial
    robot's do and returns the same leading shape.
    """

    def __init__(
        self,
        branches: Sequence[Robot],
        closure: Closure,
        *,
        links: Sequence[tuple[int, int]] | None = None,
        name: str = "closed chain",
        joint_names: Sequence[str] | None = None,
    ) -> None:
        self.branches = tuple(checks.robot(b, f"branches[{k}]") for k, b in enumerate(branches))
        if not self.branches:
            raise ValueError("branches: expected at least one serial branch")
        for k, b in enumerate(self.branches):
            if np.any(b.Ia) or np.any(b.Fv) or np.any(b.Fs) or b.coupled:
                raise ValueError(
                    f"branches[{k}]: drive terms belong to the closed chain (Ia, Fv, Fs), "
                    "not to a branch"
                )
        gravity = self.branches[0].gravity_vector
        if any(not np.array_equal(b.gravity_vector, gravity) for b in self.branches):
            raise ValueError("branches: every branch needs the same gravity vector")
        self.tree_dof = sum(b.n for b in self.branches)
        if closure.tree_dof != self.tree_dof:
            raise ValueError(
                f"closure: it ties {closure.tree_dof} tree joints, "
                f"the branches have {self.tree_dof}"
            )
        self.closure = closure
        self.n = int(closure.dof)
        default = [(k, i) for k, b in enumerate(self.branches) for i in range(b.n)]
        try:
            self.links = tuple((int(k), int(i)) for k, i in (default if links is None else links))
        except (TypeError, ValueError):
            raise ValueError(f"links: expected (branch, index) pairs among {default}") from None
        if len(set(self.links)) != len(self.links) or not set(self.links) <= set(default):
            raise ValueError(f"links: expected distinct (branch, index) pairs among {default}")
        for k, i in sorted(set(default) - set(self.links)):
            if np.any(self.branches[k].parameter_vector()[10 * i : 10 * i + 10]):
                raise ValueError(
                    f"links: branch {k}'s link {i} is left out, so it must be massless (a copy of "
                    "a trunk joint), but it has inertial parameters"
                )
        self.name = str(name)
        self.joint_names = (
            tuple(f"q{j + 1}" for j in range(self.n))
            if joint_names is None
            else tuple(checks.names(joint_names, "joint_names", self.n))
        )
        self._drive_terms = {name: np.zeros(self.n) for name in ("Ia", "Fv", "Fs")}
        self.gravity_vector = gravity
        self._edges = np.cumsum([0] + [b.n for b in self.branches])
        # Column j of the tree's stacked regressor (branches in order) is column _order[j] of the
        # chain's (links in chain order): the permutation from branch order to link numbers.
        self._order = np.full(10 * self.tree_dof, -1)  # -1: a massless copy, no columns
        for number, (k, i) in enumerate(self.links):
            tree_link = self._edges[k] + i
            self._order[10 * tree_link : 10 * tree_link + 10] = np.arange(10) + 10 * number
        self._base_cache: dict[tuple[str, bool, bool], BaseParameters] = {}

    def __repr__(self) -> str:
        return f"ClosedChain({self.name!r}, n={self.n}, links={len(self.links)})"

    # -- drive terms on the independent joints (lecture pp. 12-13, 11) ---------------------------

    @property
    def Ia(self) -> NDArray[np.float64]:
        """Rotor inertias reflected to the independent joints [kg m^2], (n,), >= 0."""
        return self._drive_terms["Ia"].copy()

    @Ia.setter
    def Ia(self, value: ArrayLike) -> None:
        self._set_drive("Ia", value)

    @property
    def Fv(self) -> NDArray[np.float64]:
        """Viscous friction of the independent joints [N m s/rad], (n,), >= 0."""
        return self._drive_terms["Fv"].copy()

    @Fv.setter
    def Fv(self, value: ArrayLike) -> None:
        self._set_drive("Fv", value)

    @property
    def Fs(self) -> NDArray[np.float64]:
        """Coulomb friction of the independent joints [N m], (n,), >= 0."""
        return self._drive_terms["Fs"].copy()

    @Fs.setter
    def Fs(self, value: ArrayLike) -> None:
        self._set_drive("Fs", value)

    def _set_drive(self, name: str, value: ArrayLike) -> None:
        arr = np.array(value, dtype=float)
        if arr.shape != (self.n,) or not np.all(np.isfinite(arr)) or np.any(arr < 0):
            raise ValueError(f"{name}: expected {self.n} finite values >= 0, got {value!r}")
        self._drive_terms[name] = arr

    # -- parameters ---------------------------------------------------------------------------

    def parameter_names(self, rotor: bool = False, friction: bool = False) -> list[str]:
        """Names of the standard parameters, ``m1 mx1 ... Izz1 m2 ...`` by link number, then
        ``Ia1..``, ``Fv1.. Fs1..`` of the independent joints when asked."""
        names: list[str] = []
        for number, (k, i) in enumerate(self.links):
            own = self.branches[k].parameter_names()[10 * i : 10 * i + 10]
            names += [re.sub(r"\d+$", str(number + 1), text) for text in own]
        joints = range(1, self.n + 1)
        if rotor:
            names += [f"Ia{j}" for j in joints]
        if friction:
            names += [f"Fv{j}" for j in joints] + [f"Fs{j}" for j in joints]
        return names

    def parameter_vector(self, rotor: bool = False, friction: bool = False) -> NDArray[np.float64]:
        """The standard parameters in the order of :meth:`parameter_names`."""
        values = [self.branches[k].parameter_vector()[10 * i : 10 * i + 10] for k, i in self.links]
        if rotor:
            values.append(self.Ia)
        if friction:
            values += [self.Fv, self.Fs]
        return np.concatenate(values)

    # -- the tree and its projection ----------------------------------------------------------

    def tree_motion(
        self, q: ArrayLike, qd: ArrayLike | None = None, qdd: ArrayLike | None = None
    ) -> Motion:
        """The spanning tree's joint positions, velocities, accelerations (T, m) and G (T, m, n)
        for a batch of independent joint states (a single sample becomes T = 1)."""
        qb = self._batch(q, "q")
        qdb = None if qd is None else self._batch(qd, "qd", qb.shape[0])
        qddb = None if qdd is None else self._batch(qdd, "qdd", qb.shape[0])
        return self.closure.tree_motion(self.branches, qb, qdb, qddb)

    def _batch(self, value: ArrayLike, name: str, rows: int | None = None) -> NDArray[np.float64]:
        arr = np.asarray(value, dtype=float)
        if arr.ndim not in (1, 2) or arr.shape[-1] != self.n:
            raise ValueError(
                f"{name}: expected shape ({self.n},) or (T, {self.n}), got {arr.shape}"
            )
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name}: not finite")
        arr = arr.reshape(-1, self.n)
        if rows is not None and arr.shape[0] != rows:
            raise ValueError(f"{name}: {arr.shape[0]} samples, q has {rows}")
        return arr

    def _per_branch(self, y: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        return [y[:, self._edges[k] : self._edges[k + 1]] for k in range(len(self.branches))]

    def _tree_call(self, method: str, *states: NDArray[np.float64]) -> NDArray[np.float64]:
        """A branch method on every branch, stacked over the tree's joints: (T, m)."""
        split = [self._per_branch(s) for s in states]
        parts = [
            getattr(b, method)(*(s[k] for s in split)).reshape(states[0].shape[0], b.n)
            for k, b in enumerate(self.branches)
        ]
        return np.concatenate(parts, axis=1)

    @staticmethod
    def _project(G: NDArray[np.float64], tree: NDArray[np.float64]) -> NDArray[np.float64]:
        """G^T tree: (T, n) from (T, m), or (T, n, P) from (T, m, P)."""
        return np.einsum("tmn,tm...->tn...", G, tree)

    @staticmethod
    def _shape(value: NDArray[np.float64], q: ArrayLike) -> NDArray[np.float64]:
        return value[0] if np.ndim(q) == 1 else value

    def _drive(self, qd: NDArray[np.float64], qdd: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.Ia * qdd + self.Fv * qd + self.Fs * np.sign(qd)

    # -- dynamics -----------------------------------------------------------------------------

    def rnea(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """Torques at the independent joints, tau = G^T tau_tree(y, yd, ydd) + the drive terms."""
        motion = self.tree_motion(q, qd, qdd)
        tau = self._project(motion.G, self._tree_call("rnea", motion.y, motion.yd, motion.ydd))
        tau += self._drive(self._batch(qd, "qd"), self._batch(qdd, "qdd"))
        return self._shape(tau, q)

    def gravity(self, q: ArrayLike) -> NDArray[np.float64]:
        """Gravity torques g(q) = G^T g_tree(y) (notes p. 10)."""
        motion = self.tree_motion(q)
        return self._shape(self._project(motion.G, self._tree_call("gravity", motion.y)), q)

    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]:
        """Inertia matrix M(q) = G^T M_tree(y) G + diag(Ia) (notes p. 9), (n, n) or (T, n, n)."""
        return self._shape(self._mass_matrix(self.tree_motion(q)), q)

    def _mass_matrix(self, motion: Motion) -> NDArray[np.float64]:
        T = motion.y.shape[0]
        M_tree = np.zeros((T, self.tree_dof, self.tree_dof))
        for k, (b, y) in enumerate(zip(self.branches, self._per_branch(motion.y))):
            part = slice(self._edges[k], self._edges[k + 1])
            M_tree[:, part, part] = b.mass_matrix(y).reshape(T, b.n, b.n)
        M: NDArray[np.float64] = np.einsum("tmi,tmk,tkj->tij", motion.G, M_tree, motion.G)
        return M + np.diag(self.Ia)

    def coriolis(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
        """Centrifugal and Coriolis torques c(q, qd) = G^T (M_tree Gdot qd + c_tree)."""
        qdb = self._batch(qd, "qd")
        motion = self.tree_motion(q, qdb, np.zeros_like(qdb))
        rigid = self._project(motion.G, self._tree_call("rnea", motion.y, motion.yd, motion.ydd))
        gravity = self._project(motion.G, self._tree_call("gravity", motion.y))
        return self._shape(rigid - gravity, q)

    def forward_dynamics(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> NDArray[np.float64]:
        """Accelerations qdd = M^-1 (tau - c - g - friction) of the independent joints."""
        qb = self._batch(q, "q")
        qdb = self._batch(qd, "qd", qb.shape[0])
        taub = self._batch(tau, "tau", qb.shape[0])
        zero = np.zeros_like(qdb)
        motion = self.tree_motion(qb, qdb, zero)  # one closure solve for the bias and M
        bias = self._project(motion.G, self._tree_call("rnea", motion.y, motion.yd, motion.ydd))
        bias += self._drive(qdb, zero)
        M = self._mass_matrix(motion)
        qdd = np.asarray(np.linalg.solve(M, (taub - bias)[..., None])[..., 0], dtype=np.float64)
        return self._shape(qdd, q)

    def kinetic_energy(self, q: ArrayLike, qd: ArrayLike) -> float | NDArray[np.float64]:
        """Kinetic energy: the tree's at yd = G qd, plus the rotors' 1/2 Ia qd^2."""
        motion = self.tree_motion(q, qd)
        energy = 0.5 * np.sum(self.Ia * self._batch(qd, "qd") ** 2, axis=1)
        for branch, y, yd in zip(
            self.branches, self._per_branch(motion.y), self._per_branch(motion.yd)
        ):
            energy = energy + np.asarray(branch.kinetic_energy(y, yd)).reshape(-1)
        return float(energy[0]) if np.ndim(q) == 1 else energy

    def potential_energy(self, q: ArrayLike) -> float | NDArray[np.float64]:
        """Gravity potential energy of the tree at y(q) (notes p. 10: the y-components of p_ci)."""
        motion = self.tree_motion(q)
        energy = np.zeros(motion.y.shape[0])
        for branch, y in zip(self.branches, self._per_branch(motion.y)):
            energy = energy + np.asarray(branch.potential_energy(y)).reshape(-1)
        return float(energy[0]) if np.ndim(q) == 1 else energy

    # -- linear parametrization ---------------------------------------------------------------

    def regressor(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        rotor: bool = False,
        friction: bool = False,
        columns: ArrayLike | None = None,
    ) -> NDArray[np.float64]:
        """Y (n, P) or (T, n, P) with Y @ parameter_vector(rotor, friction) == rnea: G^T Y_tree,
        then the drive-term columns; ``columns`` selects some of the P columns."""
        motion = self.tree_motion(q, qd, qdd)
        Y = self._stacked_tree("regressor", motion.y, motion.yd, motion.ydd, G=motion.G)
        qdb, qddb = self._batch(qd, "qd"), self._batch(qdd, "qdd")
        Y = self._with_drive(Y, qdb, qddb, bool(rotor), bool(friction))
        return self._shape(self._select(Y, columns), q)

    def gravity_regressor(self, q: ArrayLike) -> NDArray[np.float64]:
        """Y_g (n, 10 L) or (T, n, 10 L) with Y_g @ parameter_vector() == gravity(q)."""
        motion = self.tree_motion(q)
        return self._shape(self._stacked_tree("gravity_regressor", motion.y, G=motion.G), q)

    def _stacked_tree(self, method: str, *states: NDArray[np.float64], G: Any) -> Any:
        """G^T times the tree's regressor (block diagonal over the branches), in link order."""
        T = states[0].shape[0]
        split = [self._per_branch(s) for s in states]
        Y = np.zeros((T, self.n, 10 * len(self.links)))
        for k, b in enumerate(self.branches):
            part = slice(self._edges[k], self._edges[k + 1])
            order = self._order[10 * self._edges[k] : 10 * self._edges[k + 1]]
            kept = order >= 0
            if not kept.any():
                continue
            Yb = getattr(b, method)(*(s[k] for s in split)).reshape(T, b.n, 10 * b.n)
            Y[:, :, order[kept]] = self._project(G[:, part, :], Yb[:, :, kept])
        return Y

    def _with_drive(
        self,
        Y: NDArray[np.float64],
        qd: NDArray[np.float64],
        qdd: NDArray[np.float64],
        rotor: bool,
        friction: bool,
    ) -> NDArray[np.float64]:
        blocks = [Y]
        eye = np.eye(self.n)
        if rotor:
            blocks.append(qdd[:, :, None] * eye)
        if friction:
            blocks += [qd[:, :, None] * eye, np.sign(qd)[:, :, None] * eye]
        return np.concatenate(blocks, axis=2)

    @staticmethod
    def _select(Y: NDArray[np.float64], columns: ArrayLike | None) -> NDArray[np.float64]:
        if columns is None:
            return Y
        index = np.asarray(columns)
        if index.ndim != 1 or not np.issubdtype(index.dtype, np.integer):
            raise ValueError("columns: expected a 1-D array of column indices")
        if index.size and (index.min() < 0 or index.max() >= Y.shape[-1]):
            raise ValueError(f"columns: indices must be in [0, {Y.shape[-1]})")
        return Y[..., index]

    def random_configurations(self, count: int, seed: int | None = 0) -> NDArray[np.float64]:
        """``count`` configurations where the loop closes, uniformly over the full circle of each
        independent joint for a linear closure, around the closure's assembly otherwise."""
        rng = np.random.default_rng(seed)
        span = getattr(self.closure, "sample_span", np.pi)
        center = getattr(self.closure, "sample_center", np.zeros(self.n))
        return center + rng.uniform(-1.0, 1.0, (count, self.n)) * span

    def base_parameters(
        self, kind: str = "torque", rotor: bool = False, friction: bool = False
    ) -> BaseParameters:
        """The base parameters of the closed chain, with the loop's own groupings (notes p. 9),
        by the numerical method of :func:`dynid.base_parameters` on G^T Y_tree."""
        if kind not in ("torque", "gravity"):
            raise ValueError(
                f"kind: expected 'torque' or 'gravity' for a closed chain, got {kind!r}"
            )
        rotor, friction = checks.flag(rotor, "rotor"), checks.flag(friction, "friction")
        if kind == "gravity" and (rotor or friction):
            raise ValueError("rotor/friction: the gravity regressor has no drive-term columns")
        key = (kind, bool(rotor), bool(friction))
        if key not in self._base_cache:
            columns = 10 * len(self.links) + self.n * (int(rotor) + 2 * int(friction))
            samples = max(20, 4 * columns // self.n + 1)
            rng = np.random.default_rng(0)
            q = self.random_configurations(samples, seed=1)
            if kind == "gravity":
                W = self.gravity_regressor(q)
            else:
                qd, qdd = rng.normal(size=(2, samples, self.n))
                W = self.regressor(q, qd, qdd, rotor=rotor, friction=friction)
            self._base_cache[key] = from_stacked_regressor(
                W.reshape(-1, W.shape[-1]),
                self.parameter_names(rotor, friction),
                kind=kind,
                rotor=bool(rotor),
                friction=bool(friction),
            )
        return self._base_cache[key]
