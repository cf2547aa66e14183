"""Independent NumPy reference model of a DH chain, for the tests only.

Nothing here calls dynid's algorithms. It follows the textbook route rather than the
recursive one the library uses:

- each DH row gives a homogeneous transform (docs/conventions.md, "DH tables", written out with
  explicit Rz, Tz, Tx, Rx matrices);
- the geometric Jacobian of a point on link i has the column [z_j x (p - o_j); z_j]
  for a revolute joint j <= i and [z_j; 0] for a prismatic one, z_j being the joint
  axis through o_j (z_{j-1} of the standard frame j-1, z_j of the modified frame j);
- the link inertia matrix is B(q) = sum_i m_i Jv_i^T Jv_i + Jw_i^T R_i Ic_i R_i^T Jw_i
  (lecture notes, kinetic energy of the links), M = B + diag(Ia);
- g(q) = -sum_i m_i Jv_i^T g0 (gradient of U = -sum_i m_i g0^T p_ci).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def rot_x(angle: float) -> Array:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]], dtype=float)


def rot_z(angle: float) -> Array:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=float)


def trans(x: float, y: float, z: float) -> Array:
    out = np.eye(4)
    out[:3, 3] = (x, y, z)
    return out


def skew(v: Array) -> Array:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def steiner(mass: float, com: Array, inertia_com: Array) -> Array:
    """Inertia about the frame origin from the inertia about the centre of mass."""
    com = np.asarray(com, dtype=float)
    return np.asarray(inertia_com, dtype=float) + mass * (
        com @ com * np.eye(3) - np.outer(com, com)
    )


def physical_to_params(mass: float, com: Array, inertia_com: Array) -> Array:
    """[m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz] about the frame origin (docs/conventions.md,
    "Inertial parameters")."""
    i_o = steiner(mass, com, inertia_com)
    h = mass * np.asarray(com, dtype=float)
    return np.array([mass, *h, i_o[0, 0], i_o[0, 1], i_o[0, 2], i_o[1, 1], i_o[1, 2], i_o[2, 2]])


def params_to_physical(p: Array) -> tuple[float, Array, Array]:
    """Inverse of physical_to_params (needs m != 0)."""
    m = float(p[0])
    com = np.asarray(p[1:4], dtype=float) / m
    i_o = np.array([[p[4], p[5], p[6]], [p[5], p[7], p[8]], [p[6], p[8], p[9]]], dtype=float)
    i_c = i_o - m * (com @ com * np.eye(3) - np.outer(com, com))
    return m, com, i_c


@dataclass
class Arm:
    """A DH arm given by its table and its links in physical form (frame i of `convention`)."""

    # (n, 4): [a, alpha, d, theta_offset] (modified: [a_{i-1}, alpha_{i-1}, d_i, theta_i])
    dh: Array
    joint_types: str
    convention: str
    mass: Array  # (n,)
    com: Array  # (n, 3) in link frame i
    inertia_com: Array  # (n, 3, 3) about the CoM, link frame i axes
    Ia: Array = field(default_factory=lambda: np.zeros(0))
    Fv: Array = field(default_factory=lambda: np.zeros(0))
    Fs: Array = field(default_factory=lambda: np.zeros(0))
    gravity: Array = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    base: Array = field(default_factory=lambda: np.eye(4))
    tool: Array = field(default_factory=lambda: np.eye(4))

    def __post_init__(self) -> None:
        n = len(self.joint_types)
        self.dh = np.asarray(self.dh, dtype=float).reshape(n, 4)
        for name in ("Ia", "Fv", "Fs"):
            if len(getattr(self, name)) == 0:
                setattr(self, name, np.zeros(n))

    @property
    def n(self) -> int:
        return len(self.joint_types)

    @property
    def params(self) -> Array:
        return np.array(
            [
                physical_to_params(self.mass[i], self.com[i], self.inertia_com[i])
                for i in range(self.n)
            ]
        )

    def robot(self, via_set_link: bool = True):  # -> dynid.Robot
        import dynid

        robot = dynid.Robot.from_dh(
            self.dh.tolist(),
            joint_types=self.joint_types,
            convention=self.convention,
            gravity=tuple(self.gravity),
            params=None if via_set_link else self.params,
            base=self.base,
            tool=self.tool,
        )
        if via_set_link:
            for i in range(self.n):
                robot.set_link(i, self.mass[i], self.com[i], self.inertia_com[i])
        robot.Ia = self.Ia
        robot.Fv = self.Fv
        robot.Fs = self.Fs
        return robot


def row_transform(arm: Arm, i: int, qi: float) -> Array:
    a, alpha, d, theta = arm.dh[i]
    if arm.joint_types[i] == "R":
        theta = theta + qi
    else:
        d = d + qi
    if arm.convention == "standard":
        return rot_z(theta) @ trans(0, 0, d) @ trans(a, 0, 0) @ rot_x(alpha)
    return rot_x(alpha) @ trans(a, 0, 0) @ rot_z(theta) @ trans(0, 0, d)


@dataclass
class Kinematics:
    frames: list[Array]  # world pose of link frame i, i = 1..n
    axes: Array  # (n, 3) world joint axes
    origins: Array  # (n, 3) a point on each joint axis
    tool: Array  # world pose of the tool


def kinematics(arm: Arm, q: Array) -> Kinematics:
    pose = np.array(arm.base, dtype=float)
    frames, axes, origins = [], [], []
    for i in range(arm.n):
        if arm.convention == "standard":
            axes.append(pose[:3, 2].copy())
            origins.append(pose[:3, 3].copy())
            pose = pose @ row_transform(arm, i, q[i])
        else:
            pose = pose @ row_transform(arm, i, q[i])
            axes.append(pose[:3, 2].copy())
            origins.append(pose[:3, 3].copy())
        frames.append(pose)
    return Kinematics(frames, np.array(axes), np.array(origins), pose @ arm.tool)


def point_jacobian(arm: Arm, kin: Kinematics, point: Array, upto: int) -> Array:
    """(6, n) geometric Jacobian [v; omega] of a point rigidly attached to link `upto` (1-based)."""
    jac = np.zeros((6, arm.n))
    for j in range(upto):
        z = kin.axes[j]
        if arm.joint_types[j] == "R":
            jac[:3, j] = np.cross(z, point - kin.origins[j])
            jac[3:, j] = z
        else:
            jac[:3, j] = z
    return jac


def com_world(kin: Kinematics, arm: Arm, i: int) -> Array:
    frame = kin.frames[i]
    return frame[:3, :3] @ arm.com[i] + frame[:3, 3]


def fkine(arm: Arm, q: Array) -> Array:
    return kinematics(arm, q).tool


def jacobian(arm: Arm, q: Array) -> Array:
    kin = kinematics(arm, q)
    return point_jacobian(arm, kin, kin.tool[:3, 3], arm.n)


def mass_matrix(arm: Arm, q: Array) -> Array:
    kin = kinematics(arm, q)
    m_q = np.diag(np.asarray(arm.Ia, dtype=float))
    for i in range(arm.n):
        jac = point_jacobian(arm, kin, com_world(kin, arm, i), i + 1)
        rot = kin.frames[i][:3, :3]
        i_world = rot @ arm.inertia_com[i] @ rot.T
        m_q += arm.mass[i] * jac[:3].T @ jac[:3] + jac[3:].T @ i_world @ jac[3:]
    return m_q


def gravity(arm: Arm, q: Array) -> Array:
    kin = kinematics(arm, q)
    g_q = np.zeros(arm.n)
    for i in range(arm.n):
        jac = point_jacobian(arm, kin, com_world(kin, arm, i), i + 1)
        g_q -= arm.mass[i] * jac[:3].T @ arm.gravity
    return g_q


def kinetic_energy(arm: Arm, q: Array, qd: Array) -> float:
    """1/2 sum (m |v_c|^2 + w^T I_c w) + 1/2 sum Ia qd^2, from the link velocities."""
    kin = kinematics(arm, q)
    energy = 0.5 * float(np.sum(np.asarray(arm.Ia) * qd**2))
    for i in range(arm.n):
        twist = point_jacobian(arm, kin, com_world(kin, arm, i), i + 1) @ qd
        rot = kin.frames[i][:3, :3]
        w_local = rot.T @ twist[3:]
        energy += (
            0.5 * arm.mass[i] * twist[:3] @ twist[:3] + 0.5 * w_local @ arm.inertia_com[i] @ w_local
        )
    return energy


def potential_energy(arm: Arm, q: Array) -> float:
    kin = kinematics(arm, q)
    return -sum(arm.mass[i] * arm.gravity @ com_world(kin, arm, i) for i in range(arm.n))


def friction(arm: Arm, qd: Array) -> Array:
    return np.asarray(arm.Fv) * qd + np.asarray(arm.Fs) * np.sign(qd)


def lagrange_torque(arm: Arm, q: Array, qd: Array, qdd: Array, h: float = 1e-6) -> Array:
    """tau = d/dt(dT/dqd) - dT/dq + dU/dq + friction, with M from mass_matrix above.

    d/dt(M qd) = M qdd + Mdot qd, Mdot by a central difference along qd;
    dT/dq_k = 1/2 qd^T dM/dq_k qd by central differences. Accuracy ~h^2 + eps/h.
    """
    m_q = mass_matrix(arm, q)
    m_dot = (mass_matrix(arm, q + h * qd) - mass_matrix(arm, q - h * qd)) / (2 * h)
    dt_dq = np.zeros(arm.n)
    for k in range(arm.n):
        e = np.zeros(arm.n)
        e[k] = h
        dm = (mass_matrix(arm, q + e) - mass_matrix(arm, q - e)) / (2 * h)
        dt_dq[k] = 0.5 * qd @ dm @ qd
    return m_q @ qdd + m_dot @ qd - dt_dq + gravity(arm, q) + friction(arm, qd)


def arm_of(robot) -> Arm:
    """The same arm as a dynid robot, in this reference model (no drive terms)."""
    links = [params_to_physical(p) for p in robot.params]
    return Arm(
        dh=np.array(robot.dh),
        joint_types=robot.joint_types,
        convention=robot.convention,
        mass=np.array([m for m, _, _ in links]),
        com=np.array([c for _, c, _ in links]),
        inertia_com=np.array([i for _, _, i in links]),
        gravity=np.array(robot.gravity_vector),
    )
