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

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import dynid

pin = pytest.importorskip("pinocchio")

G0 = 9.81  # along -y (notes p. 10: U_i = m_i g0 y_ci)
ACTUATED = [0, 2]  # the tree's base joints, branch 1's then branch 2's: their angles are q1, q2
PASSIVE = [1, 3]
# Relative tolerance of the dynamics (to the largest entry of the reference): the maths is exact,
# the reference solves a 6 x 6 KKT system (for rnea, M, g, c: differences of its solutions);
# measured worst over 400 random parallelogram samples 2e-14. The five-bar's passive joints come
# from dynid's Newton, stopped at a 1e-13 m loop error: measured worst over 400 samples 2e-13.
TOL = 1e-12
FIVE_BAR_TOL = 1e-11


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


def _close(got: object, reference: object, tol: float = TOL, scale: float | None = None) -> None:
    """|got - reference| <= tol * scale (entrywise), the scale by default the reference's
    largest entry; the numbers in the message on failure."""
    got, reference = np.asarray(got), np.asarray(reference)
    if scale is None:
        scale = float(np.max(np.abs(reference)))
    error = float(np.max(np.abs(got - reference)))
    assert error <= tol * scale, f"error {error:.3e} vs scale {scale:.3e} (tol {tol:g} relative)"


def _samples(rng: np.random.Generator, count: int) -> tuple[np.ndarray, ...]:
    """Random states away from the flattened parallelogram: at q2 - q1 = 0 or pi the four links
    are collinear, the loop's constraint Jacobian A loses rank (the KKT matrix is singular) and
    the cut tree may leave the parallelogram for the crossed "anti-parallelogram"."""
    q = rng.uniform(-np.pi, np.pi, (4 * count, 2))
    q = q[np.abs(np.sin(q[:, 1] - q[:, 0])) > 0.2][:count]
    qd, qdd = rng.uniform(-3.0, 3.0, (2, count, 2))
    u = rng.uniform(-20.0, 20.0, (count, 2))
    return q, qd, qdd, u


def test_the_reference_is_the_notes_parallelogram() -> None:
    """The KKT reference itself against the notes' closed form (p. 9-10), so that a
    disagreement below is dynid's: B from the KKT's response to u, g from u at rest."""
    p = _random_parallelogram(np.random.default_rng(7), decoupled=False)
    tree = p.tree()
    m, Ic, lc, l1, l2 = np.array(p.masses), np.array(p.inertias), np.array(p.com), p.l1, p.l2
    for q in _samples(np.random.default_rng(8), 5)[0]:
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
    # the closed chain's regressor G^T Y_tree times its standard parameters
    _close(chain.regressor(q, qd, qdd) @ chain.parameter_vector(), reference)


def _check_terms(
    chain: dynid.ClosedChain,
    tree: Tree,
    q: np.ndarray,
    qd: np.ndarray,
    y: np.ndarray,
    tol: float = TOL,
) -> np.ndarray:
    """M, g, c as the KKT model implies them (u = M qdd + c + g, affine in qdd), T and U of the
    tree at the loop's state from Pinocchio; returns the KKT M."""
    yd, rest = _velocity(tree, y, qd), np.zeros(4)
    g = _inverse(tree, y, rest, np.zeros(2))
    M = np.column_stack([_inverse(tree, y, rest, e) - g for e in np.eye(2)])
    c = _inverse(tree, y, yd, np.zeros(2)) - g
    _close(chain.mass_matrix(q), M, tol)
    _close(chain.gravity(q), g, tol)
    # c's scale: M qd^2 (c vanishes in the decoupled design, notes p. 9, up to rounding)
    _close(chain.coriolis(q, qd), c, tol, scale=float(np.max(np.abs(M)) * qd @ qd))
    T, U = _energy(tree, y, yd)
    _close(chain.kinetic_energy(q, qd), T, 1e-12)
    # U's scale: g0 sum m_i (1 m); U itself may pass through 0
    mass = sum(inertia.mass for inertia in tree.model.inertias)
    _close(chain.potential_energy(q), U, 1e-12, scale=G0 * mass)
    return M


@pytest.mark.parametrize(("seed", "decoupled"), PARALLELOGRAMS)
def test_parallelogram_mass_matrix_gravity_coriolis_and_energies(
    seed: int, decoupled: bool
) -> None:
    p = _random_parallelogram(np.random.default_rng(seed), decoupled)
    chain, tree = p.chain(), p.tree()
    q, qd, _, _ = _samples(np.random.default_rng(300 + seed), 10)
    for a, b in zip(q, qd):
        M = _check_terms(chain, tree, a, b, p.state(a, b)[0])
        if decoupled:  # notes p. 9: B diagonal; |B12| is rounding of the B11-sized terms
            assert abs(M[0, 1]) <= 1e-12 * M[0, 0]
            assert abs(chain.mass_matrix(a)[0, 1]) <= 1e-12 * M[0, 0]
            assert np.max(np.abs(chain.coriolis(a, b))) <= 1e-12 * M[0, 0] * b @ b


# ---------------------------------------------------------------------------------------------
# The five-bar (notes p. 6, the MIT direct-drive arms' linkage)


@dataclass
class FiveBar:
    links: tuple[Link, Link, Link, Link]  # crank 1, coupler 1, crank 2, coupler 2
    d: float  # O2 = (d, 0)
    cranks: tuple[float, float]
    couplers: tuple[float, float]
    q0: np.ndarray  # the assembly's actuated angles
    up: bool  # C to the left of P1 -> P2 (the assembly mode)

    def tree(self) -> Tree:
        return _tree(self.links, (self.d, 0.0), self.cranks, self.couplers)

    def state(self, q: np.ndarray) -> np.ndarray:
        """The tree's y: C by intersecting the couplers' circles about the cranks' tips."""
        P1 = self.cranks[0] * np.array([np.cos(q[0]), np.sin(q[0])])
        P2 = np.array([self.d, 0.0]) + self.cranks[1] * np.array([np.cos(q[1]), np.sin(q[1])])
        b1, b2 = self.couplers
        span = np.linalg.norm(P2 - P1)
        e = (P2 - P1) / span
        along = (b1**2 - b2**2 + span**2) / (2 * span)
        across = np.sqrt(b1**2 - along**2) * (1.0 if self.up else -1.0)
        C = P1 + along * e + across * np.array([-e[1], e[0]])
        phi1, phi2 = np.arctan2(*(C - P1)[::-1]), np.arctan2(*(C - P2)[::-1])
        return np.array([q[0], phi1 - q[0], q[1], phi2 - q[1]])

    def chain(self) -> dynid.ClosedChain:
        branches = []
        for k in range(2):
            base, tool = np.eye(4), np.eye(4)
            base[0, 3], tool[0, 3] = (0.0, self.d)[k], self.couplers[k]
            robot = dynid.Robot.from_dh(
                [[0.0, 0.0, 0.0, 0.0], [self.cranks[k], 0.0, 0.0, 0.0]],
                joint_types="RR",
                convention="modified",
                gravity=(0.0, -G0, 0.0),
                base=base,
                tool=tool,
            )
            for i in range(2):
                link = self.links[2 * k + i]
                izz = link.izz
                robot.set_link(i, link.mass, (*link.com, 0.0), np.diag([0.01 * izz, izz, izz]))
            branches.append(robot)
        assembly = self.state(self.q0)
        closure = dynid.PointClosure(between=(0, 1), actuated=ACTUATED, assembly=assembly)
        return dynid.ClosedChain(branches, closure, name="five-bar")


def _random_five_bar(rng: np.random.Generator, hanging: bool = False) -> FiveBar:
    links = tuple(
        Link(rng.uniform(0.5, 2.0), (rng.uniform(0.05, 0.4), rng.uniform(-0.05, 0.05)), izz)
        for izz in rng.uniform(0.01, 0.1, 4)
    )
    # cranks up and out (C above), or down and out (C below: the stable rest of the free chain)
    q0 = np.radians([-110.0, -70.0] if hanging else [120.0, 60.0])
    return FiveBar(
        links,  # type: ignore[arg-type]
        d=rng.uniform(0.2, 0.4),
        cranks=tuple(rng.uniform(0.4, 0.5, 2)),  # type: ignore[arg-type]
        couplers=tuple(rng.uniform(0.55, 0.65, 2)),  # type: ignore[arg-type]
        q0=q0,
        up=not hanging,
    )


def _five_bar_samples(bar: FiveBar, rng: np.random.Generator, count: int) -> tuple[np.ndarray, ...]:
    q = bar.q0 + rng.uniform(-0.3, 0.3, (count, 2))  # within reach of the assembly
    qd, qdd = rng.uniform(-3.0, 3.0, (2, count, 2))
    u = rng.uniform(-20.0, 20.0, (count, 2))
    return q, qd, qdd, u


@pytest.mark.parametrize("seed", range(3))
def test_five_bar_passive_joints_close_the_loop(seed: int) -> None:
    bar = _random_five_bar(np.random.default_rng(seed))
    chain, tree = bar.chain(), bar.tree()
    q, qd, _, _ = _five_bar_samples(bar, np.random.default_rng(400 + seed), 20)
    motion = chain.tree_motion(q, qd)
    for k in range(len(q)):
        c1, c2 = _closure_points(tree, motion.y[k])
        assert np.max(np.abs(c1 - c2)) <= 1e-12  # metres, links ~0.5 m
        # the same assembly mode as the circle intersection (angles to rounding)
        assert np.max(np.abs(np.angle(np.exp(1j * (motion.y[k] - bar.state(q[k])))))) <= 1e-12
        _close(motion.yd[k], _velocity(tree, motion.y[k], qd[k]), 1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_five_bar_forward_dynamics_is_the_constrained_trees(seed: int) -> None:
    bar = _random_five_bar(np.random.default_rng(seed))
    chain, tree = bar.chain(), bar.tree()
    q, qd, _, u = _five_bar_samples(bar, np.random.default_rng(500 + seed), 20)
    reference = []
    for a, b, w in zip(q, qd, u):
        y = bar.state(a)
        reference.append(_forward(tree, y, _velocity(tree, y, b), w))
    for k in range(len(q)):
        _close(chain.forward_dynamics(q[k], qd[k], u[k]), reference[k], FIVE_BAR_TOL)
    _close(chain.forward_dynamics(q, qd, u), np.array(reference), FIVE_BAR_TOL)


@pytest.mark.parametrize("seed", range(3))
def test_five_bar_rnea_is_the_torque_the_constrained_tree_needs(seed: int) -> None:
    bar = _random_five_bar(np.random.default_rng(seed))
    chain, tree = bar.chain(), bar.tree()
    q, qd, qdd, _ = _five_bar_samples(bar, np.random.default_rng(600 + seed), 20)
    reference = []
    for a, b, c in zip(q, qd, qdd):
        y = bar.state(a)
        reference.append(_inverse(tree, y, _velocity(tree, y, b), c))
    for k in range(len(q)):
        _close(chain.rnea(q[k], qd[k], qdd[k]), reference[k], FIVE_BAR_TOL)
    _close(chain.rnea(q, qd, qdd), np.array(reference), FIVE_BAR_TOL)
    _close(
        chain.regressor(q, qd, qdd) @ chain.parameter_vector(), np.array(reference), FIVE_BAR_TOL
    )
    for a, b in zip(q[:5], qd[:5]):
        _check_terms(chain, tree, a, b, bar.state(a), FIVE_BAR_TOL)


@pytest.mark.parametrize("mechanism", ["parallelogram", "five-bar"])
def test_drive_terms_are_rotors_and_friction_at_the_base_joints(mechanism: str) -> None:
    """The drive terms act on the independent joints (notes pp. 11-13): in the reference the
    rotors are Pinocchio armature on the tree's base joints (crba adds it to M's diagonal) and
    the friction Fv qd + Fs sign(qd) adds to the torque the loop needs."""
    rng = np.random.default_rng(700)
    if mechanism == "parallelogram":
        p = _random_parallelogram(rng, decoupled=False)
        chain, tree = p.chain(), p.tree()
        q, qd, qdd, u = _samples(rng, 10)
        ys = [p.state(a, np.zeros(2))[0] for a in q]
        tol = TOL
    else:
        bar = _random_five_bar(rng)
        chain, tree = bar.chain(), bar.tree()
        q, qd, qdd, u = _five_bar_samples(bar, rng, 10)
        ys = [bar.state(a) for a in q]
        tol = FIVE_BAR_TOL
    Ia, Fv, Fs = rng.uniform(0.05, 0.5, (3, 2))
    chain.Ia, chain.Fv, chain.Fs = Ia, Fv, Fs
    tree.model.armature = np.array([Ia[0], 0.0, Ia[1], 0.0])
    tree.data = tree.model.createData()
    for y, a, b, c, w in zip(ys, q, qd, qdd, u):
        yd, friction = _velocity(tree, y, b), Fv * b + Fs * np.sign(b)
        _close(chain.rnea(a, b, c), _inverse(tree, y, yd, c) + friction, tol)
        _close(chain.forward_dynamics(a, b, w), _forward(tree, y, yd, w - friction), tol)
        rest = _inverse(tree, y, np.zeros(4), np.zeros(2))
        M = np.column_stack([_inverse(tree, y, np.zeros(4), e) - rest for e in np.eye(2)])
        _close(chain.mass_matrix(a), M, tol)
        _close(chain.kinetic_energy(a, b), 0.5 * b @ M @ b, 1e-12)


# ---------------------------------------------------------------------------------------------
# Free motion (u = 0): energy and trajectories over 1 s


def _free_motion(
    tree: Tree, chain: dynid.ClosedChain, y0: np.ndarray, yd0: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The KKT model's (y, yd) and dynid's (q, qd) at 21 times over 1 s, both from the same
    state, DOP853 with rtol = atol = 1e-11 (the reference integrates all 4 tree joints and
    keeps the loop closed only through A ydd = -Adot yd: its drift is checked below)."""

    def tree_rate(_t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate([x[4:], _kkt(tree, x[:4], x[4:], np.zeros(2))[:4]])

    def chain_rate(_t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate([x[2:], chain.forward_dynamics(x[:2], x[2:], np.zeros(2))])

    def run(rate: Callable[[float, np.ndarray], np.ndarray], x0: np.ndarray) -> np.ndarray:
        times = np.linspace(0.0, 1.0, 21)
        sol = solve_ivp(rate, (0.0, 1.0), x0, "DOP853", times, rtol=1e-11, atol=1e-11)
        assert sol.success, sol.message
        return np.asarray(sol.y.T)

    reference = run(tree_rate, np.concatenate([y0, yd0]))
    got = run(chain_rate, np.concatenate([y0[ACTUATED], yd0[ACTUATED]]))
    return reference, got


def _check_free_motion(
    tree: Tree, chain: dynid.ClosedChain, reference: np.ndarray, got: np.ndarray
) -> None:
    y, yd, q, qd = reference[:, :4], reference[:, 4:], got[:, :2], got[:, 2:]
    for state in y:  # the reference stays on the loop (no projection needed over 1 s)
        c1, c2 = _closure_points(tree, state)
        assert np.max(np.abs(c1 - c2)) <= 1e-9
    T, U = np.array([_energy(tree, a, b) for a, b in zip(y, yd)]).T
    assert np.ptp(T) > 0.1  # a real motion: the energy moves between T and U
    E_tree = T + U
    E_chain = chain.kinetic_energy(q, qd) + chain.potential_energy(q)
    # T + U conserved to ~1e-8 of the kinetic energy (measured: 1e-10; the integrators' error)
    assert np.max(np.abs(E_tree - E_tree[0])) <= 1e-8 * np.max(T)
    assert np.max(np.abs(E_chain - E_chain[0])) <= 1e-8 * np.max(T)
    # the same trajectory (measured: 7e-11 rad, 2e-10 rad/s; the integrators' error)
    assert np.max(np.abs(q - y[:, ACTUATED])) <= 1e-8
    assert np.max(np.abs(qd - yd[:, ACTUATED])) <= 1e-8 * np.max(np.abs(qd))


def _balanced(p: Parallelogram, decoupled: bool) -> Parallelogram:
    """Link 2 statically balanced by link 4's counterweight, m2 lc2 + m3 l2 = m4 lc4 (notes
    p. 10: g2 = 0), and for the decoupled design then lc3 from m3 l2 lc3 = m4 l1 lc4 (p. 9)."""
    m, lc = p.masses, list(p.com)
    lc[3] = (m[1] * lc[1] + m[2] * p.l2) / m[3]
    if decoupled:
        lc[2] = m[3] * p.l1 * lc[3] / (m[2] * p.l2)
    return replace(p, com=tuple(lc))


@pytest.mark.parametrize("decoupled", [False, True])
def test_parallelogram_free_motion_is_the_constrained_trees(decoupled: bool) -> None:
    """Under gravity, every rest configuration has q2 - q1 = 0 or pi (g depends on cos q1 and
    cos q2 only), where the cut tree is singular: with link 2 balanced, link 1 swings about
    -pi/2 while link 2 stays near 0, and the parallelogram keeps away from flattening (in the
    decoupled design link 2 then turns at its constant initial rate, notes p. 10)."""
    p = _balanced(_random_parallelogram(np.random.default_rng(3), decoupled=False), decoupled)
    chain, tree = p.chain(), p.tree()
    y0, yd0 = p.state(np.array([-np.pi / 2 + 0.6, 0.0]), np.array([0.0, 0.3]))
    reference, got = _free_motion(tree, chain, y0, yd0)
    assert np.min(np.abs(np.sin(got[:, 1] - got[:, 0]))) > 0.5
    _check_free_motion(tree, chain, reference, got)


def test_five_bar_free_motion_is_the_constrained_trees() -> None:
    """The five-bar hanging (its stable rest, away from singularities) swings freely."""
    bar = _random_five_bar(np.random.default_rng(1), hanging=True)
    chain, tree = bar.chain(), bar.tree()
    y0 = bar.state(bar.q0 + np.array([0.15, -0.1]))
    reference, got = _free_motion(tree, chain, y0, _velocity(tree, y0, np.array([0.5, 0.3])))
    for y in reference[:, :4]:  # regular all along (measured: cond(A_p) <= 8)
        assert np.linalg.cond(_constraint(tree, y, np.zeros(4))[0][:, PASSIVE]) < 100
    _check_free_motion(tree, chain, reference, got)


def _straight_path_gap(bar: FiveBar, q: np.ndarray) -> float:
    """How close the straight path from the assembly to q comes to the inner workspace
    boundary |P2 - P1| = |b1 - b2| (the couplers folded onto each other: A_p singular, where the
    two assembly modes meet) [m]."""
    b1, b2 = bar.couplers
    gaps = []
    for s in np.linspace(0.0, 1.0, 201):
        qs = bar.q0 + s * (q - bar.q0)
        P1 = bar.cranks[0] * np.array([np.cos(qs[0]), np.sin(qs[0])])
        P2 = np.array([bar.d, 0.0]) + bar.cranks[1] * np.array([np.cos(qs[1]), np.sin(qs[1])])
        gaps.append(np.linalg.norm(P2 - P1) - abs(b1 - b2))
    return float(min(gaps))


def _check_assembly_mode(bar: FiveBar, q: np.ndarray) -> None:
    chain, tree = bar.chain(), bar.tree()
    expected = _closure_points(tree, bar.state(q))[0]
    got = _closure_points(tree, chain.tree_motion(q).y[0])[0]
    assert np.max(np.abs(got - expected)) <= 1e-12


def test_five_bar_keeps_its_assembly_mode_near_the_inner_boundary() -> None:
    """On the straight path from the assembly to q the couplers stay >= 15 mm from folding onto
    each other (cond(A_p) = 29 at q), so the assembly's mode continues to q: C on the same side
    of P1 -> P2. dynid e0c3690 (Newton alone on each 0.25 rad continuation step) put C 0.77 m
    away, at (-0.362, -0.710) instead of (0.346, -1.003); 9d1adf3's tangent predictor fixed it."""
    bar = _random_five_bar(np.random.default_rng(12), hanging=True)
    q = np.array([-1.25424057, -1.84661435])
    assert _straight_path_gap(bar, q) > 0.015
    _check_assembly_mode(bar, q)


def test_five_bar_follows_its_assembly_mode_close_to_the_inner_boundary() -> None:
    """q is regular (cond(A_p) = 38) and the straight path from the assembly stays >= 9 mm from
    the inner workspace boundary (the couplers folded onto each other). dynid d007fa2 refused it
    ("could not be followed without jumping") after 4 halvings of its continuation steps for the
    whole batch; from ccc0c68 a jumping sample alone is followed again, up to 64 times finer.
    On a 31 x 31 grid of +-0.15 rad around q (759 closable configurations) every q whose path
    stays > 1 mm from the boundary is solved in the assembly's mode (672 of 672; was: 11 of 69
    refused at 3-10 mm, 16 of 18 at 1-3 mm), 4 of 15 closer are refused, and the 72 whose path
    crosses the boundary are refused; none is answered in the other mode (see the next test)."""
    bar = _random_five_bar(np.random.default_rng(12), hanging=True)
    q = np.array([-1.22424057, -1.79661435])
    assert _straight_path_gap(bar, q) > 0.009
    _check_assembly_mode(bar, q)


def test_five_bar_never_answers_in_the_other_assembly_mode() -> None:
    """Paths that pass within 0.7 mm of the inner boundary, or cross it: before the check of
    det(A_p)'s sign along the path (the assembly modes are separated by det(A_p) = 0), dynid
    tunnelled to the other mode at all of these q with tangents that agreed, and put C 0.52-0.98
    m from where the assembly's mode has it. Now the paths that cross (negative gap) or pass
    within 0.07 mm are refused, the others solved in the assembly's mode."""
    bar = _random_five_bar(np.random.default_rng(12), hanging=True)
    chain, tree = bar.chain(), bar.tree()
    refused = [
        (-1.14424057, -1.88661435),  # the path crosses the boundary (gap -0.15 mm)
        (-1.13424057, -1.89661435),  # passes 0.07 mm from it
        (-1.09424057, -1.92661435),  # crosses (-0.55 mm)
        (-1.08424057, -1.93661435),  # crosses
        (-1.07424057, -1.94661435),  # crosses
    ]
    solved = [
        (-1.12424057, -1.90661435),  # passes 0.26 mm from it
        (-1.11424057, -1.91661435),  # 0.47 mm
        (-1.10424057, -1.92661435),  # 0.65 mm
    ]
    for q in refused:
        assert _straight_path_gap(bar, np.array(q)) < 1e-4
        with pytest.raises(ValueError, match="cannot be closed along the path"):
            chain.tree_motion(np.array(q))
    for q in solved:
        expected = _closure_points(tree, bar.state(np.array(q)))[0]
        got = _closure_points(tree, chain.tree_motion(np.array(q)).y[0])[0]
        assert np.max(np.abs(got - expected)) <= 1e-9, (q, got, expected)
