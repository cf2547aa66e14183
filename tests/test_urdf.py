"""Robot.from_urdf against independent readings of the same URDF.

- Pinocchio (urdfdom parser, its own tree and algorithms; tests/pinocchio_urdf.py) on real arms
  and on generated trees with skew, intersecting, parallel and coincident axes, prismatic
  joints, fixed joints and branches: rnea, mass matrix, gravity and the tip pose at random q,
  in both DH conventions, to 1e-10 relative (the maths is exact: what is left is rounding).
- The DH tables and DH-frame parameters of the LWR4 derived by hand (tests/data/kuka_lwr4_dh.json
  and the data README), and the 4x4 pseudo-inertia map J' = T J T^T for the inertial frame change.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import dynid
from dynid.model.urdf.reading import standard_parameters
from dynid.model.urdf.tree import read_tree
from pinocchio_urdf import (
    DATA,
    assert_matches_pinocchio,
    example_robot_data,
    reference,
    relative_error,
)

CONVENTIONS = ("standard", "modified")

# (file, base_link, tip_link): the real arms of issue 10
REAL = {
    "kuka_lwr4": (DATA / "kuka_lwr4.urdf", None, "lwr_7_link"),
    "kuka_lwr4_from_lwr_base": (DATA / "kuka_lwr4.urdf", "lwr_base_link", "lwr_7_link"),
    "panda_link8": (DATA / "panda.urdf", None, "panda_link8"),
    "panda_hand_tcp": (DATA / "panda.urdf", None, "panda_hand_tcp"),  # fingers held at 0
    "ur3": (DATA / "ur3.urdf", None, "tool0"),
    "ur5": (Path(dynid.__file__).parent / "data" / "ur5.urdf", "base_link", "tool0"),
    "ur10": (Path(dynid.__file__).parent / "data" / "ur10.urdf", None, "tool0"),
    "kinova": (DATA / "kinova_j2s6s200.urdf", None, "j2s6s200_end_effector"),
    "xarm7": (DATA / "xarm7.urdf", None, "link_eef"),
    "z1": (DATA / "z1.urdf", None, "link06"),  # the gripper held at 0
    "talos_left_arm": (
        "talos_data/robots/talos_left_arm.urdf",
        "arm_left_1_link",
        "wrist_left_ft_tool_link",
    ),
    "talos_from_link2": (
        "talos_data/robots/talos_left_arm.urdf",
        "arm_left_2_link",
        "gripper_left_base_link",
    ),  # base rotated: gravity re-expressed
}


def _text(path: Path | str) -> str:
    if isinstance(path, str):
        path = example_robot_data(path)
    return Path(path).read_text(encoding="utf-8")


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("case", sorted(REAL))
def test_real_arm_matches_pinocchio(case: str, convention: str) -> None:
    path, base_link, tip_link = REAL[case]
    text = _text(path)
    robot = dynid.Robot.from_urdf(text, base_link, tip_link, convention)
    assert robot.convention == convention
    ref = reference(text, base_link, tip_link)
    robot.gravity_vector = ref.gravity
    assert_matches_pinocchio(robot, text, base_link, tip_link)
    # <dynamics damping friction> -> Fv, Fs; <limit> -> qlim (Pinocchio's reading, exactly)
    np.testing.assert_array_equal(robot.Fv, ref.model.damping)
    np.testing.assert_array_equal(robot.Fs, ref.model.friction)
    for i, jid in enumerate(ref.joints):
        joint = ref.model.joints[jid]
        if joint.nq == 1:
            limits = (
                ref.model.lowerPositionLimit[joint.idx_q],
                ref.model.upperPositionLimit[joint.idx_q],
            )
            np.testing.assert_array_equal(robot.qlim[i], limits)
        else:  # continuous: one turn
            np.testing.assert_array_equal(robot.qlim[i], [-np.pi, np.pi])


# every real URDF of these tests, and example-robot-data's copies of the UR and Panda arms
REAL_FILES = sorted(
    {str(path) for path, _, _ in REAL.values()}
    | {
        "panda_description/urdf/panda.urdf",
        "ur_description/urdf/ur5_robot.urdf",
        "ur_description/urdf/ur10_robot.urdf",
        "ur_description/urdf/ur3_robot.urdf",
    }
)


@pytest.mark.parametrize("path", REAL_FILES)
def test_real_urdfs_pass_the_physical_check_on_every_chain(path: str) -> None:
    """The physical check (on by default) refuses nothing legitimate: every chain from the root
    to a leaf of a real arm's URDF reads, massless frames (world, base, tool0, flange, tcp) merged
    away; what it reads is consistent and to_urdf writes it (one rule on both sides). The leaves
    that are no chain are refused for what they are: fixed to the root, or behind a mimic
    finger joint."""
    text = _text(Path(path) if path.startswith("/") else path)
    tree = read_tree(text)
    chains, refused = 0, {}
    for leaf in (link for link in tree.links if not tree.children(link)):
        try:
            robot = dynid.Robot.from_urdf(text, tip_link=leaf)
        except ValueError as exc:
            refused[leaf] = str(exc)
            continue
        assert robot.is_physically_consistent(), leaf
        assert robot.to_urdf()
        chains += 1
    assert chains >= 1
    assert all("no movable joint" in why or "mimic" in why for why in refused.values()), refused


def test_path_and_text_give_the_same_robot() -> None:
    path = DATA / "kuka_lwr4.urdf"
    from_path = dynid.Robot.from_urdf(path)
    from_str_path = dynid.Robot.from_urdf(str(path))
    from_text = dynid.Robot.from_urdf(path.read_text())
    for other in (from_str_path, from_text):
        np.testing.assert_array_equal(other.dh, from_path.dh)
        np.testing.assert_array_equal(other.params, from_path.params)
    assert from_path.name == "kuka-lwr"


@pytest.mark.parametrize("convention", CONVENTIONS)
def test_lwr4_equals_the_hand_derived_tables(convention: str) -> None:
    # tests/data/kuka_lwr4_real_README.md gives the DH tables with frame 0 = lwr_base_link
    # (a = theta = 0); tests/data/kuka_lwr4_dh.json the URDF inertials in those frames
    # (derived and checked against Pinocchio independently of dynid; 16 digits stored).
    data = json.loads((Path(__file__).parent / "data" / "kuka_lwr4_dh.json").read_text())
    robot = dynid.Robot.from_urdf(
        DATA / "kuka_lwr4.urdf", base_link="lwr_base_link", convention=convention
    )
    h = np.pi / 2
    if convention == "standard":
        alpha_d = [[h, 0.3105], [-h, 0], [-h, 0.4], [h, 0], [h, 0.39], [-h, 0], [0, 0.078]]
    else:
        alpha_d = [[0, 0.3105], [h, 0], [-h, 0.4], [-h, 0], [h, 0.39], [h, 0], [-h, 0.078]]
    expected = np.column_stack([np.zeros(7), np.array(alpha_d), np.zeros(7)])
    np.testing.assert_allclose(robot.dh, expected, rtol=0, atol=1e-15)
    np.testing.assert_allclose(robot.base, np.eye(4), rtol=0, atol=1e-15)
    np.testing.assert_allclose(robot.tool, np.eye(4), rtol=0, atol=1e-15)
    params = np.asarray(data["params"]["kuka_lwr4.urdf (HEAD)"][convention])
    np.testing.assert_allclose(robot.params, params, rtol=0, atol=1e-14)


def _pseudo_inertia(params: np.ndarray) -> np.ndarray:
    """J = [[Sigma, h], [h^T, m]], Sigma = tr(I)/2 E - I (the second moments about the origin)."""
    m, h, i = params[0], params[1:4], params[4:]
    inertia = np.array([[i[0], i[1], i[2]], [i[1], i[3], i[4]], [i[2], i[4], i[5]]])
    out = np.zeros((4, 4))
    out[:3, :3] = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    out[:3, 3] = out[3, :3] = h
    out[3, 3] = m
    return out


def _from_pseudo_inertia(J: np.ndarray) -> np.ndarray:
    sigma = J[:3, :3]
    inertia = np.trace(sigma) * np.eye(3) - sigma
    return np.array(
        [
            J[3, 3],
            *J[:3, 3],
            inertia[0, 0],
            inertia[0, 1],
            inertia[0, 2],
            inertia[1, 1],
            inertia[1, 2],
            inertia[2, 2],
        ]
    )


def test_inertial_frame_change_is_the_pseudo_inertia_map(rng: np.random.Generator) -> None:
    # A body given about its CoM (h = 0) in its CoM frame C, seen from a frame F in which C has
    # pose T: its pseudo-inertia in F is T J_C T^T (exact map of the second moments).
    from conftest import random_inertia_com, random_pose

    for _ in range(20):
        mass = rng.uniform(0.1, 10.0)
        inertia = random_inertia_com(rng, mass)
        pose = random_pose(rng, 0.8)
        J_c = _pseudo_inertia(
            np.array([mass, 0, 0, 0, *inertia[0], *inertia[1, 1:], inertia[2, 2]])
        )
        expected = _from_pseudo_inertia(pose @ J_c @ pose.T)
        np.testing.assert_allclose(
            standard_parameters(mass, pose, inertia), expected, rtol=1e-13, atol=1e-15 * mass
        )


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("case", ["panda_hand_tcp", "kinova", "z1", "talos_from_link2"])
def test_link_parameters_are_pinocchios_inertias_in_dh_frames(case: str, convention: str) -> None:
    # Pinocchio keeps each joint's merged body inertia in the joint frame; DH frame i sits at
    # oMi(0)^-1 F_i(0) in it (F_i from the DH table): J_dh = X J_joint X^T with X = F_i^-1 oMi.
    path, base_link, tip_link = REAL[case]
    text = _text(path)
    robot = dynid.Robot.from_urdf(text, base_link, tip_link, convention)
    ref = reference(text, base_link, tip_link)
    pin.forwardKinematics(ref.model, ref.data, ref.configuration(np.zeros(robot.n)))
    frame = robot.base.copy()
    for i, jid in enumerate(ref.joints):
        frame = frame @ _dh_transform(robot.dh[i], convention)
        inertia = ref.model.inertias[jid]
        body = np.array(
            [
                inertia.mass,
                *(inertia.mass * inertia.lever),
                *inertia.inertia[0],
                *inertia.inertia[1, 1:],
                inertia.inertia[2, 2],
            ]
        )
        # Pinocchio's Inertia.inertia is about the CoM: to the joint origin first (pseudo-inertia
        # of a CoM-centred body moved by the lever).
        shift = np.eye(4)
        shift[:3, 3] = inertia.lever
        J_joint = shift @ _pseudo_inertia(np.array([body[0], 0, 0, 0, *body[4:]])) @ shift.T
        joint_pose = np.linalg.inv(ref.base_pose) @ ref.data.oMi[jid].homogeneous
        X = np.linalg.inv(frame) @ joint_pose
        expected = _from_pseudo_inertia(X @ J_joint @ X.T)
        np.testing.assert_allclose(
            robot.params[i], expected, rtol=0, atol=1e-12 * max(1.0, np.abs(expected).max())
        )


def _dh_transform(row: np.ndarray, convention: str) -> np.ndarray:
    a, alpha, d, theta = row
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(theta), np.sin(theta)
    rz = np.array([[ct, -st, 0, 0], [st, ct, 0, 0], [0, 0, 1, d], [0, 0, 0, 1]])
    rx = np.array([[1, 0, 0, a], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1]])
    return rz @ rx if convention == "standard" else rx @ rz


# ---- generated chains: every kind of consecutive axes, prismatic and fixed joints, branches --


def _vec(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def _inertial(rng: np.random.Generator) -> str:
    from conftest import random_inertia_com

    mass = float(rng.uniform(0.2, 5.0))
    i = random_inertia_com(rng, mass).tolist()
    return (
        f'<inertial><origin xyz="{_vec(rng.uniform(-0.3, 0.3, 3))}" '
        f'rpy="{_vec(rng.uniform(-np.pi, np.pi, 3))}"/><mass value="{mass!r}"/>'
        f'<inertia ixx="{i[0][0]!r}" ixy="{i[0][1]!r}" ixz="{i[0][2]!r}" iyy="{i[1][1]!r}" '
        f'iyz="{i[1][2]!r}" izz="{i[2][2]!r}"/></inertial>'
    )


def _unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def generated_urdf(seed: int) -> tuple[str, str]:
    """A random URDF and its tip link. Consecutive movable joints are, at random: skew, parallel
    (distinct lines), intersecting or coincident (same line); some chain links carry fixed
    children (merged) or a branch held at 0; the tip follows a fixed chain."""
    rng = np.random.default_rng(seed)
    parts = [
        '<robot name="generated">',
        '<link name="world"/>',
        f'<link name="base">{_inertial(rng)}</link>',
        (
            f'<joint name="mount" type="fixed"><parent link="world"/><child link="base"/>'
            f'<origin xyz="{_vec(rng.uniform(-1, 1, 3))}" rpy="{_vec(rng.uniform(-3, 3, 3))}"/>'
            "</joint>"
        ),
    ]
    parent, previous_axis = "base", None
    for k in range(int(rng.integers(2, 7))):
        kind = rng.choice(["revolute", "continuous", "prismatic"], p=[0.5, 0.2, 0.3])
        relation = (
            "skew"
            if previous_axis is None
            else rng.choice(["skew", "parallel", "intersecting", "coincident"])
        )
        xyz, rpy, axis = rng.uniform(-0.4, 0.4, 3), rng.uniform(-np.pi, np.pi, 3), _unit(rng)
        if relation == "parallel":  # same direction in the same frame, shifted
            rpy, axis = np.zeros(3), previous_axis
        elif relation == "intersecting":  # the new origin lies on the previous axis
            xyz = rng.uniform(-0.4, 0.4) * previous_axis
        elif relation == "coincident":
            xyz, rpy, axis = rng.uniform(-0.4, 0.4) * previous_axis, np.zeros(3), previous_axis
        if relation == "skew" and rng.random() < 0.4:  # a fixed link in between (merged)
            parts += [
                f'<link name="fixed{k}">{_inertial(rng)}</link>',
                (
                    f'<joint name="fix{k}" type="fixed"><parent link="{parent}"/>'
                    f'<child link="fixed{k}"/><origin xyz="{_vec(rng.uniform(-0.3, 0.3, 3))}" '
                    f'rpy="{_vec(rng.uniform(-3, 3, 3))}"/></joint>'
                ),
            ]
            parent = f"fixed{k}"
        limit = '<limit lower="-1.5" upper="2.5" effort="1" velocity="1"/>'
        parts += [
            f'<link name="link{k}">{_inertial(rng)}</link>',
            (
                f'<joint name="joint{k}" type="{kind}"><parent link="{parent}"/>'
                f'<child link="link{k}"/><origin xyz="{_vec(xyz)}" rpy="{_vec(rpy)}"/>'
                f'<axis xyz="{_vec(axis)}"/>{limit if kind != "continuous" else ""}'
                f'<dynamics damping="{float(rng.uniform(0, 2))!r}" '
                f'friction="{float(rng.uniform(0, 1))!r}"/>'
                "</joint>"
            ),
        ]
        if rng.random() < 0.3:  # a branch: a leaf held at 0 (revolute) or rigidly fixed
            branch = rng.choice(["revolute", "fixed"])
            parts += [
                f'<link name="branch{k}">{_inertial(rng)}</link>',
                (
                    f'<joint name="branch_joint{k}" type="{branch}"><parent link="link{k}"/>'
                    f'<child link="branch{k}"/><origin xyz="{_vec(rng.uniform(-0.3, 0.3, 3))}"/>'
                    f'<axis xyz="{_vec(_unit(rng))}"/>{limit}</joint>'
                ),
            ]
        parent, previous_axis = f"link{k}", axis
    for k in range(int(rng.integers(0, 3))):  # fixed chain after the last joint -> tool
        parts += [
            f'<link name="flange{k}">{_inertial(rng)}</link>',
            (
                f'<joint name="flange_joint{k}" type="fixed"><parent link="{parent}"/>'
                f'<child link="flange{k}"/><origin xyz="{_vec(rng.uniform(-0.3, 0.3, 3))}" '
                f'rpy="{_vec(rng.uniform(-3, 3, 3))}"/></joint>'
            ),
        ]
        parent = f"flange{k}"
    return "\n".join([*parts, "</robot>"]), parent


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("seed", range(25))
def test_generated_chain_matches_pinocchio(seed: int, convention: str) -> None:
    text, tip = generated_urdf(seed)
    robot = dynid.Robot.from_urdf(text, tip_link=tip, convention=convention)
    assert_matches_pinocchio(robot, text, None, tip, seed=seed)


def test_hand_made_skew_axis_and_prismatic_joint() -> None:
    # The brief's case: axis "0.6 0 0.8" under a non-zero rpy, then a prismatic joint along a
    # general axis, then a revolute joint parallel to the first, a fixed flange with a mass.
    def inertial(m: float, xyz: str) -> str:
        return (
            f'<inertial><origin xyz="{xyz}" rpy="0.1 -0.2 0.3"/><mass value="{m}"/>'
            '<inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.03" iyz="0.0015" izz="0.025"/>'
            "</inertial>"
        )

    text = f"""<robot name="hand_made">
      <link name="root"/>
      <link name="a">{inertial(2.0, "0.1 0.02 0.3")}</link>
      <link name="b">{inertial(1.5, "0 0.1 0.05")}</link>
      <link name="c">{inertial(1.0, "0.05 0 0.1")}</link>
      <link name="flange">{inertial(0.4, "0 0 0.02")}</link>
      <joint name="skew" type="revolute"><parent link="root"/><child link="a"/>
        <origin xyz="0.1 -0.2 0.3" rpy="0.4 -0.7 1.1"/><axis xyz="0.6 0 0.8"/>
        <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
      <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
        <origin xyz="0.2 0.1 0.4" rpy="-0.3 0.5 0.2"/><axis xyz="0 0.6 -0.8"/>
        <limit lower="-0.1" upper="0.3" effort="1" velocity="1"/>
        <dynamics damping="3.5" friction="1.25"/></joint>
      <joint name="parallel" type="continuous"><parent link="b"/><child link="c"/>
        <origin xyz="0.3 0 0.1" rpy="0 0 0"/><axis xyz="0 0.6 -0.8"/></joint>
      <joint name="to_flange" type="fixed"><parent link="c"/><child link="flange"/>
        <origin xyz="0 0.05 0.2" rpy="0.3 0.2 0.1"/></joint>
    </robot>"""
    for convention in CONVENTIONS:
        robot = dynid.Robot.from_urdf(text, convention=convention)
        assert robot.joint_types == "RPR"
        np.testing.assert_array_equal(robot.qlim, [[-2, 2], [-0.1, 0.3], [-np.pi, np.pi]])
        np.testing.assert_array_equal(robot.Fv, [0, 3.5, 0])
        np.testing.assert_array_equal(robot.Fs, [0, 1.25, 0])
        assert_matches_pinocchio(robot, text, None, "flange")


NEAR = (
    '<inertial><origin xyz="0.1 0.05 0.2" rpy="0.3 0.2 0.1"/><mass value="1.5"/>'
    '<inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="0.025"/></inertial>'
)


def _nearly_parallel_urdf(angle: float) -> str:
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    return f"""<robot name="p"><link name="r"/><link name="a">{NEAR}</link>
      <link name="b">{NEAR}</link><link name="c">{NEAR}</link>
      <joint name="j1" type="revolute"><parent link="r"/><child link="a"/>
        <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>{limit}</joint>
      <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
        <origin xyz="0.4 0.05 0.1" rpy="0 0 {angle!r}"/><axis xyz="0 1 0"/>{limit}</joint>
      <joint name="j3" type="revolute"><parent link="b"/><child link="c"/>
        <origin xyz="0.3 0 0" rpy="0.5 0 0"/><axis xyz="0 0 1"/>{limit}</joint></robot>"""


@pytest.mark.parametrize(
    ("angle", "tolerance"),
    # treated as parallel: errors ~angle; above 5e-6 rad the exact common normal, ~1/angle away:
    # errors ~eps / angle^2 (measured 1.6e-9, 7.8e-6, 7e-6, 9e-9, 3e-10 relative)
    [(1e-9, 1e-8), (4.9e-6, 2e-5), (5.1e-6, 2e-5), (1e-4, 1e-7), (1e-3, 1e-9)],
)
def test_nearly_parallel_axes_are_reported(angle: float, tolerance: float) -> None:
    text = _nearly_parallel_urdf(angle)
    for convention in CONVENTIONS:
        if angle < 1e-3:
            with pytest.warns(UserWarning, match=r"joints 'j1' and 'j2': axes .* from parallel"):
                robot = dynid.Robot.from_urdf(text, convention=convention)
        else:
            robot = dynid.Robot.from_urdf(text, convention=convention)
        ref = reference(text, None, "c")
        rigid = robot.rigid_body()
        for q, qd, qdd in np.random.default_rng(0).uniform(-3, 3, (5, 3, 3)):
            assert relative_error(rigid.rnea(q, qd, qdd), ref.rnea(q, qd, qdd)) < tolerance
            assert relative_error(rigid.fkine(q), ref.tip_pose(q)) < tolerance


@pytest.mark.parametrize("case", sorted(REAL))
def test_real_arms_and_exactly_parallel_axes_give_no_warning(case: str) -> None:
    import warnings

    path, base_link, tip_link = REAL[case]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dynid.Robot.from_urdf(_text(path), base_link, tip_link)
        dynid.Robot.from_urdf(_nearly_parallel_urdf(0.0))
