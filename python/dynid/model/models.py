"""Ready-made robot models: the KUKA LWR-IV, the lecture's planar 2R, the PUMA 560, the Franka
Emika Panda (Gaz et al. 2019) and the Universal Robots UR5 and UR10 (from their URDFs), and the
lecture's closed-chain parallelogram robot (``planar_parallelogram``, a :class:`dynid.ClosedChain`).

Each factory returns a fresh :class:`dynid.Robot` built with ``Robot.from_dh``.
Units are SI, angles in radians, standard inertial parameters as in docs/conventions.md,
"Inertial parameters".
"""

from __future__ import annotations

from collections.abc import Sequence
from importlib.resources import files
from pathlib import Path

import numpy as np

from .. import _core
from .parallelogram import planar_parallelogram
from .robot import Robot

__all__ = [
    "kuka_lwr4",
    "panda",
    "planar_2r",
    "planar_parallelogram",
    "puma560",
    "ur5",
    "ur10",
]

_DEG = np.pi / 180.0

# KUKA LWR-IV, one row per link, CoM and inertia in DH frame i (frames of `kuka_lwr4`):
#   mass [kg], CoM x y z [m], inertia about the CoM Ixx Iyy Izz Ixy Ixz Iyz [kg m^2]
# (tensor entries, Ixy = -integral of x*y dm). Plausible values, not identified ones:
# masses follow the real arm (~2.5 kg per arm link, lighter wrist, ~15 kg in total);
# every CoM has three non-zero components and every tensor non-zero products so that
# no parameter vanishes by symmetry and identification tests exercise all columns.
_LWR4_LINKS = np.array([
    # m     cx      cy      cz      Ixx      Iyy      Izz      Ixy      Ixz      Iyz
    [2.85,  0.004, -0.072,  0.058, 0.0192,  0.0061,  0.0168,  0.0004, -0.0003,  0.0011],
    [2.75, -0.003,  0.058,  0.071, 0.0187,  0.0160,  0.0049, -0.0002,  0.0004, -0.0012],
    [2.60,  0.005,  0.069,  0.062, 0.0176,  0.0052,  0.0154,  0.0003,  0.0002,  0.0009],
    [2.55, -0.004, -0.061,  0.068, 0.0171,  0.0148,  0.0047,  0.0002, -0.0003,  0.0010],
    [1.85,  0.003, -0.063,  0.009, 0.0108,  0.0031,  0.0094, -0.0002,  0.0001, -0.0006],
    [1.70,  0.002,  0.004,  0.061, 0.0046,  0.0043,  0.0039,  0.0001, -0.0001,  0.0002],
    [0.45, -0.001,  0.002,  0.065, 0.00052, 0.00047, 0.00071, 0.00004, 0.00003, -0.00005],
])  # fmt: skip

# Link-side drive terms of the LWR-IV model (plausible, not published): reflected rotor
# inertia Ia [kg m^2], viscous Fv [N m s/rad] and Coulomb Fs [N m] friction per joint.
_LWR4_IA = np.array([0.32, 0.30, 0.21, 0.19, 0.11, 0.08, 0.07])
_LWR4_FV = np.array([0.90, 0.85, 0.55, 0.50, 0.30, 0.25, 0.15])
_LWR4_FS = np.array([1.10, 1.00, 0.60, 0.55, 0.45, 0.35, 0.20])

# PUMA 560, Corke & Armstrong-Helouvry (ICRA 1994), as in the Robotics Toolbox
# `mdl_puma560` ("params of 8/95"), one row per link:
#   a [m], alpha [rad], d [m], mass [kg], CoM x y z [m] in frame i,
#   Ixx Iyy Izz about the CoM [kg m^2] (products zero)
_PUMA_LINKS = np.array([
    # a       alpha       d        m      cx       cy       cz      Ixx      Iyy      Izz
    [0.0,     np.pi / 2,  0.0,     0.0,   0.0,     0.0,     0.0,    0.0,     0.35,    0.0],
    [0.4318,  0.0,        0.0,     17.4, -0.3638,  0.006,   0.2275, 0.13,    0.524,   0.539],
    [0.0203, -np.pi / 2,  0.15005, 4.8,  -0.0203, -0.0141,  0.070,  0.066,   0.086,   0.0125],
    [0.0,     np.pi / 2,  0.4318,  0.82,  0.0,     0.019,   0.0,    1.8e-3,  1.3e-3,  1.8e-3],
    [0.0,    -np.pi / 2,  0.0,     0.34,  0.0,     0.0,     0.0,    0.3e-3,  0.4e-3,  0.3e-3],
    [0.0,     0.0,        0.0,     0.09,  0.0,     0.0,     0.032,  0.15e-3, 0.15e-3, 0.04e-3],
])  # fmt: skip
# joint limits [deg], lower and upper per joint (same source)
_PUMA_QLIM_DEG = np.array(
    [[-160, 160], [-45, 225], [-225, 45], [-110, 170], [-100, 100], [-266, 266]]
)

# PUMA 560 drives, motor side: rotor inertia Jm [kg m^2], gear ratio G, viscous friction
# B [N m s/rad] and Coulomb friction Tc+ / Tc- [N m], per joint (same source).
_PUMA_DRIVES = np.array([
    # Jm       G          B         Tc+      Tc-
    [200e-6, -62.6111,  1.48e-3,  0.395,   -0.435],
    [200e-6, 107.815,   0.817e-3, 0.126,   -0.071],
    [200e-6, -53.7063,  1.38e-3,  0.132,   -0.105],
    [33e-6,   76.0364,  71.2e-6,  11.2e-3, -16.9e-3],
    [33e-6,   71.923,   82.6e-6,  9.26e-3, -14.5e-3],
    [33e-6,   76.686,   36.7e-6,  3.96e-3, -10.5e-3],
])  # fmt: skip


def kuka_lwr4() -> Robot:
    """KUKA LWR-IV with plausible, deliberately non-symmetric inertial parameters.

    Kinematics from Table I of Gaz, Flacco, De Luca, "Identifying the dynamic
    model used by the KUKA LWR: a reverse engineering approach", ICRA 2014: standard DH,
    all a_i = 0 and theta offsets 0, alpha = [pi/2, -pi/2, -pi/2, pi/2, pi/2, -pi/2, 0],
    d_3 = d1 = 0.4 m and d_5 = d2 = 0.39 m. As in the paper, frame 0 sits at the shoulder
    (the origin of frame 1) and frame 7 at the wrist centre (the origin of frame 6), so the
    base-to-shoulder 0.3105 m and the flange offset 0.078 m of the real arm are left out.
    Gravity is (0, 0, -9.81); joint limits are +-170 deg for joints 1, 3, 5, 7 and +-120 deg
    for joints 2, 4, 6, as in the arm's URDF (FloBaRoID ``kuka_lwr4.urdf``).

    The inertial parameters are invented but physically consistent (``set_link`` checks
    each link): masses of 0.45-2.85 kg, 14.75 kg in total, close to the URDF of the real
    arm; CoM offsets with all three components non-zero; full inertia tensors about the
    CoM with non-zero products. They are not the values KUKA's controller uses.

    Small plausible drive terms are set too: ``Ia`` (reflected rotor inertia), ``Fv`` and
    ``Fs`` (link-side viscous and Coulomb friction). For the pure rigid-body arm of the
    paper, use ``robot.rigid_body()`` (a copy with the drive terms zeroed).

    Returns
    -------
    Robot
        A 7-DOF robot named ``"KUKA LWR-IV"``.
    """
    alpha = np.array([1, -1, -1, 1, 1, -1, 0]) * (np.pi / 2)
    d = [0.0, 0.0, 0.4, 0.0, 0.39, 0.0, 0.0]
    dh = np.column_stack([np.zeros(7), alpha, d, np.zeros(7)])
    limit = np.array([170, 120, 170, 120, 170, 120, 170]) * _DEG
    robot = Robot.from_dh(
        dh,
        joint_types="R" * 7,
        convention="standard",
        gravity=(0.0, 0.0, -9.81),
        qlim=np.column_stack([-limit, limit]),
        name="KUKA LWR-IV",
    )
    for i, (m, cx, cy, cz, ixx, iyy, izz, ixy, ixz, iyz) in enumerate(_LWR4_LINKS):
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        robot.set_link(i, m, (cx, cy, cz), inertia)
    robot.Ia = _LWR4_IA.copy()
    robot.Fv = _LWR4_FV.copy()
    robot.Fs = _LWR4_FS.copy()
    return robot


def planar_2r(
    l1: float = 1.0,
    l2: float = 1.0,
    lc1: float = 0.5,
    lc2: float = 0.5,
    m1: float = 1.0,
    m2: float = 1.0,
    I1: float | None = None,
    I2: float | None = None,
    gravity: Sequence[float] = (0.0, -9.81, 0.0),
    convention: str = "standard",
) -> Robot:
    """Planar 2R arm of the lecture notes ("Dynamic model of robots", Robotics 2, pp. 22-24).

    Standard DH rows ``[l1, 0, 0, 0]`` and ``[l2, 0, 0, 0]``, both joints revolute about the
    base z axis, motion in the base x-y plane. The default gravity (0, -9.81, 0) makes it a
    vertical plane (g0 = 9.81 along -y, the notes' model); pass ``(0, 0, -9.81)`` for a
    horizontal plane, where gravity does no work. No drive terms (Ia = Fv = Fs = 0).

    The CoM of link i lies on the link axis at ``lc_i`` from joint i. Standard DH puts frame
    i at the distal end of link i, so in frame i the CoM is ``(lc_i - l_i, 0, 0)``.

    Parameters
    ----------
    l1, l2 : float
        Link lengths [m].
    lc1, lc2 : float
        Distances of the CoMs from joints 1 and 2 [m] (the notes' d1, d2).
    m1, m2 : float
        Link masses [kg], > 0.
    I1, I2 : float, optional
        Inertia about the CoM around z [kg m^2], > 0; default ``m l^2 / 12`` (thin rod).
        Only Izz enters planar motion, but ``set_link`` needs a full, physically consistent
        tensor: we use ``diag(0.01 Izz, Izz, Izz)``, a slender rod along x (a tiny but
        positive axial inertia, so it is positive definite and meets the triangle
        inequalities).
    gravity : sequence of 3 float
        Gravity in the base frame [m/s^2].
    convention : {"standard", "modified"}
        ``"modified"`` describes the same arm with frames at the joints (rows ``[0, 0, 0, 0]``,
        ``[l1, 0, 0, 0]``, tool ``Tx(l2)``, CoM ``(lc_i, 0, 0)``): the frames of the notes'
        linear parametrisation, whose base parameters in the vertical plane are
        ``mx1 + l1*m2``, ``Izz1 + l1**2*m2``, ``mx2``, ``Izz2`` (the notes' a1..a4) and ``my1``,
        ``my2`` (zero here: the CoMs are on the link axes); see docs/base_parameters.md.

    Returns
    -------
    Robot
        A 2-DOF robot named ``"planar 2R"``.

    Raises
    ------
    ValueError
        From ``set_link`` if a mass or inertia is not positive.
    """
    if convention == "standard":
        dh, tool = [[l1, 0.0, 0.0, 0.0], [l2, 0.0, 0.0, 0.0]], None
    elif convention == "modified":
        dh, tool = [[0.0, 0.0, 0.0, 0.0], [l1, 0.0, 0.0, 0.0]], np.eye(4)
        tool[0, 3] = l2
    else:
        raise ValueError(f"convention: expected 'standard' or 'modified', got {convention!r}")
    robot = Robot.from_dh(
        dh,
        joint_types="RR",
        convention=convention,
        gravity=tuple(gravity),
        tool=tool,
        name="planar 2R",
    )
    for i, (length, lc, m, izz) in enumerate(((l1, lc1, m1, I1), (l2, lc2, m2, I2))):
        izz = m * length**2 / 12.0 if izz is None else izz
        # Frame i sits at the distal end of link i in standard DH, at joint i in modified DH.
        com_x = lc - length if convention == "standard" else lc
        robot.set_link(i, m, (com_x, 0.0, 0.0), np.diag([0.01 * izz, izz, izz]))
    return robot


def puma560() -> Robot:
    """Unimation PUMA 560 with the consensus parameters of Corke and Armstrong-Helouvry.

    Source: P. Corke and B. Armstrong-Helouvry, "A search for consensus among model
    parameters reported for the PUMA 560 robot", Proc. IEEE ICRA 1994, pp. 1608-1613, in
    the form of the Robotics Toolbox's ``mdl_puma560`` (standard DH, "params of 8/95");
    joint limits there from Wang & Chen, IEEE Trans. RA 7(4), 1991. d_1 = 0 as in that
    model (the shoulder at the origin; the Python toolbox's ``Puma560`` adds the 0.672 m
    pedestal as d_1, which changes the pose but not the dynamics). Gravity (0, 0, -9.81).

    Drive terms are reflected from the motor side to the link side:
    ``Ia = Jm G^2``, ``Fv = B G^2`` and ``Fs = |G| (|Tc+| + |Tc-|) / 2``. The toolbox stores
    an asymmetric Coulomb friction ``Tc = [Tc+, Tc-]``, applied for positive and negative
    velocity respectively (its inline comment says "[-,+]", but the values and the toolbox's
    own test torques fit [+, -]); dynid's Coulomb model ``Fs sign(qd)`` is symmetric, so the mean
    of the two magnitudes is used. Zero ``Ia``, ``Fv``, ``Fs`` for the rigid-body arm alone.

    The published parameters are kept as they are, which makes
    ``robot.is_physically_consistent()`` False: link 1 has m = 0 (no mass was reported; it
    does not enter the dynamics, only its inertia 0.35 kg m^2 about the joint-1 axis does,
    and its Ixx = Izz = 0) and link 3's inertia violates the triangle inequality
    (Ixx + Izz = 0.0785 < Iyy = 0.086). ``set_link`` would refuse both, so all links are
    given as standard parameters (Steiner applied by the core, without the check).

    Returns
    -------
    Robot
        A 6-DOF robot named ``"PUMA 560"``; its nominal pose in the toolbox is
        ``qn = [0, pi/4, pi, 0, pi/4, 0]``.
    """
    links = _PUMA_LINKS
    dh = np.column_stack([links[:, 0], links[:, 1], links[:, 2], np.zeros(6)])
    # The core's Steiner transform (docs/conventions.md, "Inertial parameters"), which unlike
    # set_link does not check consistency.
    params = np.array(
        [_core.standard_parameters(row[3], row[4:7], np.diag(row[7:10])) for row in links]
    )
    robot = Robot.from_dh(
        dh,
        joint_types="R" * 6,
        convention="standard",
        gravity=(0.0, 0.0, -9.81),
        params=params,
        qlim=_PUMA_QLIM_DEG * _DEG,
        name="PUMA 560",
    )
    jm, gear, visc, tc_pos, tc_neg = _PUMA_DRIVES.T
    robot.Ia = jm * gear**2
    robot.Fv = visc * gear**2
    robot.Fs = np.abs(gear) * (np.abs(tc_pos) + np.abs(tc_neg)) / 2.0
    return robot


# Franka Emika Panda, modified DH (Craig) rows (a_{i-1}, alpha_{i-1}, d_i, theta_i) of Gaz et al.
# 2019 (``matlab/utils/Load_Franka_DH.m``); flange d = 0.107 m after joint 7.
_PANDA_DH = np.array([
    [0.0,     0.0,         0.333, 0.0],
    [0.0,    -np.pi / 2,   0.0,   0.0],
    [0.0,     np.pi / 2,   0.316, 0.0],
    [0.0825,  np.pi / 2,   0.0,   0.0],
    [-0.0825, -np.pi / 2,  0.384, 0.0],
    [0.0,     np.pi / 2,   0.0,   0.0],
    [0.088,   np.pi / 2,   0.0,   0.0],
])  # fmt: skip
_PANDA_FLANGE = 0.107
# Joint limits [rad] of the Panda (Franka Control Interface documentation, "Robot and interface
# specifications"; the same numbers are in franka_description's URDF).
_PANDA_QLIM = np.array([
    [-2.8973, 2.8973], [-1.7628, 1.7628], [-2.8973, 2.8973], [-3.0718, -0.0698],
    [-2.8973, 2.8973], [-0.0175, 3.7525], [-2.8973, 2.8973],
])  # fmt: skip
# Franka's "Robot and interface specifications" (frankaemika.github.io/docs/control_parameters):
# the maximum joint torques [N m] and velocities [rad/s] of the arm (libfranka's limits).
_PANDA_EFFORT = np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0])
_PANDA_VELOCITY = np.array([2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61])


def panda() -> Robot:
    """Franka Emika Panda with the feasible dynamic parameters identified by Gaz et al.

    Source: C. Gaz, M. Cognetti, A. Oliva, P. Robuffo Giordano, A. De Luca, "Dynamic
    Identification of the Franka Emika Panda Robot With Retrieval of Feasible Parameters Using
    Penalty-Based Optimization", IEEE Robotics and Automation Letters 4(4), pp. 4147-4154, 2019;
    supplementary material Tables VIII and IX, column p-hat (the retrieved feasible parameters:
    mass, centre of mass and inertia about it, per link), shipped as
    ``dynid/data/franka_panda_gaz2019.csv`` (provenance in ``dynid/data/README.md``).

    Kinematics: the paper's modified DH (Craig) table, a_3 = 0.0825, a_4 = -0.0825,
    a_6 = 0.088, d_1 = 0.333, d_3 = 0.316, d_5 = 0.384 m, frame 0 = ``panda_link0`` of the
    franka_description URDF (whose link frames are these DH frames), and the flange
    (``panda_link8``, 0.107 m along z_7) as the tool transform. Joint limits from Franka's
    specifications. c1z is 0 (the paper marks it as not influencing the dynamics). The paper's
    friction model (sigmoids) has no place in Fv, Fs: the drive terms are zero.

    Returns
    -------
    Robot
        A 7-DOF robot named ``"Franka Emika Panda"`` (modified DH).
    """
    table = np.loadtxt(
        _data_file("franka_panda_gaz2019.csv"), delimiter=",", comments="#", skiprows=7
    )
    tool = np.eye(4)
    tool[2, 3] = _PANDA_FLANGE
    robot = Robot.from_dh(
        _PANDA_DH,
        joint_types="R" * 7,
        convention="modified",
        gravity=(0.0, 0.0, -9.81),
        tool=tool,
        qlim=_PANDA_QLIM,
        name="Franka Emika Panda",
        # franka_description's joint names, as libfranka's ROS driver publishes them
        joint_names=[f"panda_joint{j}" for j in range(1, 8)],
    )
    robot.link_names = [f"panda_link{j}" for j in range(1, 8)]
    robot.effort_limits, robot.velocity_limits = _PANDA_EFFORT, _PANDA_VELOCITY
    for i, (_, m, cx, cy, cz, ixx, ixy, ixz, iyy, iyz, izz) in enumerate(table):
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        robot.set_link(i, m, (cx, cy, cz), inertia)
    return robot


def ur5(convention: str = "standard") -> Robot:
    """Universal Robots UR5, read with ``Robot.from_urdf`` from its URDF (shipped as
    ``dynid/data/ur5.urdf``).

    Source: ``ur5_robot.urdf`` of ros-industrial/universal_robot ``ur_description`` (BSD), as in
    example-robot-data 6.0.0 (provenance in ``dynid/data/README.md``): kinematics of Universal
    Robots' published DH parameters (d1 = 0.089159, a2 = -0.425, a3 = -0.39225,
    d4 = 0.10915, d5 = 0.09465, d6 = 0.0823 m), the link masses published by Universal Robots
    (3.7, 8.393, 2.275, 1.219, 1.219, 0.1879 kg) with the URDF's cylinder-approximation
    inertias. The chain runs from the URDF root (``world``) to ``tool0`` (the tool flange, as
    the tool transform); q is the URDF joint position, limits +-2 pi (elbow +-pi), no friction.
    """
    return _ur("ur5.urdf", "UR5", convention)


def ur10(convention: str = "standard") -> Robot:
    """Universal Robots UR10, read with ``Robot.from_urdf`` from its URDF (shipped as
    ``dynid/data/ur10.urdf``).

    Source: ``ur10_robot.urdf`` of ros-industrial/universal_robot ``ur_description`` (BSD), as in
    example-robot-data 6.0.0 (provenance in ``dynid/data/README.md``): kinematics of Universal
    Robots' published DH parameters (d1 = 0.1273, a2 = -0.612, a3 = -0.5723, d4 = 0.163941,
    d5 = 0.1157, d6 = 0.0922 m), the link masses published by Universal Robots (7.778, 12.93,
    3.87, 1.96, 1.96, 0.202 kg) with the URDF's cylinder-approximation inertias. The chain runs
    from the URDF root (``world``) to ``tool0``; q is the URDF joint position, limits +-2 pi
    (elbow +-pi), no friction.
    """
    return _ur("ur10.urdf", "UR10", convention)


def _ur(file: str, name: str, convention: str) -> Robot:
    robot = Robot.from_urdf(
        _data_file(file).read_text(encoding="utf-8"), tip_link="tool0", convention=convention
    )
    robot.name = name
    return robot


def _data_file(name: str) -> Path:
    # A path (the package is installed as files): np.loadtxt and read_text take it directly.
    return Path(str(files("dynid") / "data" / name))
