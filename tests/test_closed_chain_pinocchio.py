"""dynid's closed chains (notes pp. 7-10; dynid.model.closed_chain) against an independent
simulation of the same mechanisms: a Pinocchio spanning tree with the loop closed by Lagrange
multipliers, solved here with NumPy.

The reference. Each mechanism is cut at its closing revolute joint C into a tree of two planar
branches from the base, each a base joint (actuated, its angle is q1 or q2) and a passive joint,
built with ``pinocchio.Model.addJoint`` / ``appendBodyToJoint`` (nothing of dynid, no URDF).
With the tree's coordinates y (4), the closed chain obeys the constrained equations
    M(y) ydd + h(y, yd) = S^T u + A(y)^T lambda,    A(y) ydd = -Adot(y, yd) yd,
A the x, y rows of J_C(branch 1) - J_C(branch 2) (Pinocchio frame Jacobians,
LOCAL_WORLD_ALIGNED), Adot yd the difference of the two frames' classical accelerations with
ydd = 0, S selecting the base joints. The KKT system [M -A^T; A 0] [ydd; lambda] = [S^T u - h;
-Adot yd] is solved with numpy.linalg.solve.

The parallelogram (notes p. 7): branch 1 is link 1 (pivot O, tip A = l1 e(q1)) then link 4
(pivot A, its x axis along -e(q2), relative angle q2 + pi - q1; C = A + l2 e(q2) is at -l2 on
it); branch 2 is link 2 (pivot O, tip B = l2 e(q2)) then link 3 (pivot B, along e(q1), relative
angle q1 - q2; C at l1). The five-bar: two base pivots O1 = 0, O2 = (d, 0); branch k is a crank
of length a_k at angle q_k and a coupler of length b_k, the couplers meeting at C.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

import dynid

pin = pytest.importorskip("pinocchio")

G0 = 9.81  # along -y (notes p. 10: U_i = m_i g0 y_ci)
ACTUATED = [0, 2]  # the tree's base joints, branch 1's then branch 2's: their angles are q1, q2
PASSIVE = [1, 3]
# Relative tolerance where the maths is exact: the KKT solve and dynid's model in double
# precision, conditioning of the 6 x 6 KKT matrix ~1e2..1e3 for these link data.
TOL = 1e-10


@dataclass
class Link:
    mass: float
    com: tuple[float, float]  # CoM in the link's frame (x along the link; link 4's: -e(q2))
    izz: float  # about the CoM, around z


@dataclass
class Tree:
    """The spanning tree: links are branch 1 (base, passive), branch 2 (base, passive)."""

    model: pin.Model
    data: pin.Data
    frames: tuple[int, int]  # C on branch 1's passive link, C on branch 2's passive link


def _inertia(link: Link, turn: float) -> pin.Inertia:
    # A full positive-definite tensor, principal axes turned about z: the planar motion sees
    # its zz entry only (omega is along z), the other entries must not matter.
    c, s = np.cos(turn), np.sin(turn)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    inertia = R @ np.diag([0.01 * link.izz, link.izz, link.izz]) @ R.T
    return pin.Inertia(link.mass, np.array([link.com[0], link.com[1], 0.0]), inertia)


def _tree(
    links: tuple[Link, Link, Link, Link],
    base2: tuple[float, float],
    reach: tuple[float, float],
    tip: tuple[float, float],
) -> Tree:
    """Branch k: base joint at (0, 0) / base2, passive joint at reach[k] along the base link's
    x axis, C at tip[k] along the passive link's x axis."""
    model = pin.Model()
    model.gravity.linear = np.array([0.0, -G0, 0.0])
    frames = []
    for k, origin in enumerate([(0.0, 0.0), base2]):
        at = pin.SE3(np.eye(3), np.array([origin[0], origin[1], 0.0]))
        base = model.addJoint(0, pin.JointModelRZ(), at, f"base{k}")
        model.appendBodyToJoint(base, _inertia(links[2 * k], 0.3 + k), pin.SE3.Identity())
        at = pin.SE3(np.eye(3), np.array([reach[k], 0.0, 0.0]))
        passive = model.addJoint(base, pin.JointModelRZ(), at, f"passive{k}")
        model.appendBodyToJoint(passive, _inertia(links[2 * k + 1], 1.1 + k), pin.SE3.Identity())
        c = pin.SE3(np.eye(3), np.array([tip[k], 0.0, 0.0]))
        frames.append(model.addFrame(pin.Frame(f"C{k}", passive, 0, c, pin.FrameType.OP_FRAME)))
    return Tree(model, model.createData(), (frames[0], frames[1]))


def _closure_points(tree: Tree, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pin.framesForwardKinematics(tree.model, tree.data, y)
    c1, c2 = (tree.data.oMf[f].translation.copy() for f in tree.frames)
    return c1, c2


def _constraint(tree: Tree, y: np.ndarray, yd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A(y) and Adot(y, yd) yd (the x, y rows of C's Jacobians and classical accelerations)."""
    m, d = tree.model, tree.data
    pin.forwardKinematics(m, d, y, yd, np.zeros(m.nv))
    pin.computeJointJacobians(m, d, y)
    pin.updateFramePlacements(m, d)
    world = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    J = [pin.getFrameJacobian(m, d, f, world)[:2] for f in tree.frames]
    a = [pin.getFrameClassicalAcceleration(m, d, f, world).linear[:2] for f in tree.frames]
    return J[0] - J[1], a[0] - a[1]


def _kkt(tree: Tree, y: np.ndarray, yd: np.ndarray, u: np.ndarray) -> np.ndarray:
    """ydd and lambda of the constrained tree under the actuator torques u."""
    m, d = tree.model, tree.data
    M = pin.crba(m, d, y)
    M = np.triu(M) + np.triu(M, 1).T  # crba fills the upper triangle
    h = pin.rnea(m, d, y, yd, np.zeros(m.nv))
    A, Adot_yd = _constraint(tree, y, yd)
    K = np.block([[M, -A.T], [A, np.zeros((2, 2))]])
    rhs = np.concatenate([-h, -Adot_yd])
    rhs[ACTUATED] += u
    return np.linalg.solve(K, rhs)


def _forward(tree: Tree, y: np.ndarray, yd: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The actuated accelerations (qdd1, qdd2) of the KKT solution."""
    return _kkt(tree, y, yd, u)[ACTUATED]


def _inverse(tree: Tree, y: np.ndarray, yd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """The u whose KKT solution has the actuated accelerations qdd (ydd is affine in u)."""
    free = _forward(tree, y, yd, np.zeros(2))
    F = np.column_stack([_forward(tree, y, yd, e) - free for e in np.eye(2)])
    return np.linalg.solve(F, qdd - free)


def _velocity(tree: Tree, y: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """yd with actuated rates qd and the passive ones from A(y) yd = 0."""
    A, _ = _constraint(tree, y, np.zeros(4))
    yd = np.zeros(4)
    yd[ACTUATED] = qd
    yd[PASSIVE] = -np.linalg.solve(A[:, PASSIVE], A[:, ACTUATED] @ qd)
    return yd


def _energy(tree: Tree, y: np.ndarray, yd: np.ndarray) -> tuple[float, float]:
    m, d = tree.model, tree.data
    return pin.computeKineticEnergy(m, d, y, yd), pin.computePotentialEnergy(m, d, y)


# ---------------------------------------------------------------------------------------------
# The parallelogram (notes pp. 7-10)


@dataclass
class Parallelogram:
    masses: tuple[float, float, float, float]
    inertias: tuple[float, float, float, float]
    com: tuple[float, float, float, float]  # lc1..lc4
    l1: float
    l2: float

    def chain(self) -> dynid.ClosedChain:
        return dynid.models.planar_parallelogram(
            masses=self.masses,
            inertias=self.inertias,
            com_distances=self.com,
            l1=self.l1,
            l2=self.l2,
            gravity=G0,
        )

    def tree(self) -> Tree:
        link = [Link(m, (c, 0.0), i) for m, c, i in zip(self.masses, self.com, self.inertias)]
        # branch 1: link 1 then link 4 (C at -l2 on it), branch 2: link 2 then link 3 (C at l1)
        return _tree(
            (link[0], link[3], link[1], link[2]),
            (0.0, 0.0),
            (self.l1, self.l2),
            (-self.l2, self.l1),
        )

    @staticmethod
    def state(q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The tree's y, yd: links 3 and 4 stay parallel to links 1 and 2."""
        y = np.array([q[0], q[1] + np.pi - q[0], q[1], q[0] - q[1]])
        yd = np.array([qd[0], qd[1] - qd[0], qd[1], qd[0] - qd[1]])
        return y, yd


def _random_parallelogram(rng: np.random.Generator, decoupled: bool) -> Parallelogram:
    m = rng.uniform(0.5, 4.0, 4)
    inertia = rng.uniform(0.005, 0.2, 4)
    l1, l2 = rng.uniform(0.3, 0.9, 2)
    lc = rng.uniform(0.05, 0.5, 4) * np.array([l1, l2, l1, 0.5])
    if decoupled:  # notes p. 9, (*): m3 l2 lc3 = m4 l1 lc4, B diagonal and constant
        lc[3] = m[2] * l2 * lc[2] / (m[3] * l1)
    return Parallelogram(tuple(m), tuple(inertia), tuple(lc), l1, l2)  # type: ignore[arg-type]


PARALLELOGRAMS = [(seed, decoupled) for seed in range(3) for decoupled in (False, True)]


def _close(got: np.ndarray, reference: np.ndarray, tol: float = TOL) -> None:
    """|got - reference| <= tol * max |reference| (entrywise), with the numbers on failure."""
    got, reference = np.asarray(got), np.asarray(reference)
    scale = max(float(np.max(np.abs(reference))), 1e-300)
    error = float(np.max(np.abs(got - reference)))
    assert error <= tol * scale, f"error {error:.3e} vs scale {scale:.3e} (tol {tol:g} relative)"


def _samples(rng: np.random.Generator, count: int) -> tuple[np.ndarray, ...]:
    q = rng.uniform(-np.pi, np.pi, (count, 2))
    qd, qdd = rng.uniform(-3.0, 3.0, (2, count, 2))
    u = rng.uniform(-20.0, 20.0, (count, 2))
    return q, qd, qdd, u


def test_the_reference_is_the_notes_parallelogram() -> None:
    """The KKT reference itself against the notes' closed form (p. 9-10), so that a
    disagreement below is dynid's: B from the KKT's response to u, g from u at rest."""
    p = _random_parallelogram(np.random.default_rng(7), decoupled=False)
    tree = p.tree()
    m, Ic, lc, l1, l2 = np.array(p.masses), np.array(p.inertias), np.array(p.com), p.l1, p.l2
    for q in np.random.default_rng(8).uniform(-np.pi, np.pi, (5, 2)):
        y, yd = p.state(q, np.zeros(2))
        c1, c2 = _closure_points(tree, y)
        assert np.max(np.abs(c1 - c2)) <= 1e-15
        g = _inverse(tree, y, yd, np.zeros(2))
        B = np.column_stack([_inverse(tree, y, yd, e) - g for e in np.eye(2)])
        B12 = (m[2] * l2 * lc[2] - m[3] * l1 * lc[3]) * np.cos(q[1] - q[0])
        notes_B = [
            [Ic[0] + m[0] * lc[0] ** 2 + Ic[2] + m[2] * lc[2] ** 2 + m[3] * l1**2, B12],
            [B12, Ic[1] + m[1] * lc[1] ** 2 + Ic[3] + m[3] * lc[3] ** 2 + m[2] * l2**2],
        ]
        notes_g = G0 * np.array(
            [
                (m[0] * lc[0] + m[2] * lc[2] + m[3] * l1) * np.cos(q[0]),
                (m[1] * lc[1] + m[2] * l2 - m[3] * lc[3]) * np.cos(q[1]),
            ]
        )
        _close(B, notes_B, 1e-12)
        _close(g, notes_g, 1e-12)


@pytest.mark.parametrize(("seed", "decoupled"), PARALLELOGRAMS)
def test_parallelogram_forward_dynamics_is_the_constrained_trees(
    seed: int, decoupled: bool
) -> None:
    p = _random_parallelogram(np.random.default_rng(seed), decoupled)
    chain, tree = p.chain(), p.tree()
    q, qd, _, u = _samples(np.random.default_rng(100 + seed), 20)
    reference = np.array([_forward(tree, *p.state(*s), us) for *s, us in zip(q, qd, u)])
    for k in range(len(q)):
        _close(chain.forward_dynamics(q[k], qd[k], u[k]), reference[k])
    _close(chain.forward_dynamics(q, qd, u), reference)  # the batch, (T, 2)


@pytest.mark.parametrize(("seed", "decoupled"), PARALLELOGRAMS)
def test_parallelogram_rnea_is_the_torque_the_constrained_tree_needs(
    seed: int, decoupled: bool
) -> None:
    p = _random_parallelogram(np.random.default_rng(seed), decoupled)
    chain, tree = p.chain(), p.tree()
    q, qd, qdd, _ = _samples(np.random.default_rng(200 + seed), 20)
    reference = np.array([_inverse(tree, *p.state(a, b), c) for a, b, c in zip(q, qd, qdd)])
    for k in range(len(q)):
        _close(chain.rnea(q[k], qd[k], qdd[k]), reference[k])
    _close(chain.rnea(q, qd, qdd), reference)


@pytest.mark.parametrize(("seed", "decoupled"), PARALLELOGRAMS)
def test_parallelogram_mass_matrix_gravity_and_energies(seed: int, decoupled: bool) -> None:
    """M and g as the KKT model implies them (u = M qdd + c + g is affine in qdd), T and U of
    the tree at the loop's state from Pinocchio."""
    p = _random_parallelogram(np.random.default_rng(seed), decoupled)
    chain, tree = p.chain(), p.tree()
    q, qd, _, _ = _samples(np.random.default_rng(300 + seed), 10)
    for a, b in zip(q, qd):
        y, yd = p.state(a, b)
        y0 = p.state(a, np.zeros(2))[1]
        g = _inverse(tree, y, y0, np.zeros(2))
        M = np.column_stack([_inverse(tree, y, y0, e) - g for e in np.eye(2)])
        _close(chain.mass_matrix(a), M)
        _close(chain.gravity(a), g)
        T, U = _energy(tree, y, yd)
        _close(chain.kinetic_energy(a, b), T, 1e-12)
        _close(chain.potential_energy(a), U, 1e-12)
        if decoupled:  # notes p. 9: B diagonal; |B12| is rounding of the B11-sized terms
            assert abs(M[0, 1]) <= 1e-12 * M[0, 0]
            assert abs(chain.mass_matrix(a)[0, 1]) <= 1e-12 * M[0, 0]
