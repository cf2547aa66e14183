"""Robot.from_urdf on URDFs it must refuse: a ValueError that names the joint, link or argument
(SPEC 6), never a silently wrong model; and the defaults for base_link and tip_link."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid

DATA = Path(__file__).parent / "data" / "urdf"
INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
)


def chain(*joints: str, links: str = "") -> str:
    """A URDF: links l0..l3 with inertials (l0 the root) and the given joint elements."""
    body = "".join(f'<link name="l{i}">{INERTIAL}</link>' for i in range(4))
    return f'<robot name="t">{body}{links}{"".join(joints)}</robot>'


def joint(name: str, parent: str, child: str, kind: str = "revolute", extra: str = "") -> str:
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>{extra}'
        "</joint>"
    )


SERIAL = (joint("j1", "l0", "l1"), joint("j2", "l1", "l2"), joint("j3", "l2", "l3"))


def test_a_serial_chain_is_read() -> None:
    robot = dynid.Robot.from_urdf(chain(*SERIAL))
    assert robot.n == 3 and robot.name == "t"


def test_branched_tree_without_tip_link_names_tip_link() -> None:
    text = chain(joint("j1", "l0", "l1"), joint("j2", "l1", "l2"), joint("j3", "l1", "l3"))
    with pytest.raises(ValueError, match=r"tip_link.*'l2', 'l3'"):
        dynid.Robot.from_urdf(text)
    assert dynid.Robot.from_urdf(text, tip_link="l3").n == 2  # l2 held at 0 on link 1
    with pytest.raises(ValueError, match="tip_link"):
        dynid.Robot.from_urdf(DATA / "panda.urdf")  # two fingers


@pytest.mark.parametrize("kind", ["floating", "planar"])
def test_floating_and_planar_joints_are_named(kind: str) -> None:
    text = chain(joint("j1", "l0", "l1"), joint("free", "l1", "l2", kind), joint("j3", "l2", "l3"))
    with pytest.raises(ValueError, match=f"joint 'free'.*{kind}"):
        dynid.Robot.from_urdf(text)


def test_mimic_joint_on_the_chain_is_named() -> None:
    text = chain(
        joint("j1", "l0", "l1"),
        joint("j2", "l1", "l2", extra='<mimic joint="j1"/>'),
        joint("j3", "l2", "l3"),
    )
    with pytest.raises(ValueError, match=r"joint 'j2'.*mimic"):
        dynid.Robot.from_urdf(text)


def test_missing_inertial_names_the_link() -> None:
    text = chain(*SERIAL).replace(f'<link name="l2">{INERTIAL}</link>', '<link name="l2"/>')
    with pytest.raises(ValueError, match=r"link 'l2'.*joint 'j2'.*inertial"):
        dynid.Robot.from_urdf(text)
    # massless frames fixed to a moving link are fine (tool0, ee_link of industrial URDFs)
    text = chain(
        *SERIAL,
        '<joint name="f" type="fixed"><parent link="l3"/><child link="t"/></joint>',
        links='<link name="t"/>',
    )
    assert dynid.Robot.from_urdf(text).n == 3


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('<robot name="t"><link name="a"></robot>', "malformed XML"),
        ("<robot", "malformed XML"),
        ('<model name="t"/>', "<robot> root"),
        ('<robot name="t"/>', "no <link>"),
        (chain(joint("j1", "l0", "l1", "screw")), "joint 'j1': unknown type 'screw'"),
        (chain(joint("j1", "l0", "nowhere")), "joint 'j1'.*child"),
        (
            chain(joint("j1", "l0", "l1").replace('xyz="0 0 1"', 'xyz="0 0 0"')),
            "joint 'j1'.*zero length",
        ),
        (
            chain(joint("j1", "l0", "l1").replace('xyz="0 0 1"', 'xyz="0 1"')),
            "joint 'j1' <axis>.*3 finite numbers",
        ),
        (
            chain(joint("j1", "l0", "l1").replace('lower="-1"', 'lower="2"')),
            "joint 'j1'.*lower < upper",
        ),
        (
            chain(*SERIAL).replace('<mass value="1"/>', '<mass value="heavy"/>', 1),
            "link 'l0' <inertial> <mass>",
        ),
        (chain(*SERIAL).replace(' ixy="0"', "", 1), "link 'l0'.*'ixy'"),
        (chain(*SERIAL, joint("j4", "l3", "l1")), "link 'l1' is the child of two joints"),
        (chain(joint("j1", "l0", "l1"), joint("j2", "l2", "l3")), "one root link"),
        (chain(*SERIAL).replace('<link name="l1">', '<link name="l2">', 1), "two links named 'l2'"),
        (chain(*SERIAL[:2], joint("j1", "l2", "l3")), "two joints named 'j1'"),
        (
            chain(*(joint(f"f{i}", f"l{i}", f"l{i + 1}", "fixed") for i in range(3))),
            "no movable joint",
        ),
        (
            chain(joint("j1", "l0", "l1"), joint("j2", "l2", "l3"), joint("j3", "l3", "l2")),
            "not connected to the root",
        ),
    ],
)
def test_malformed_urdf_is_a_value_error(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        dynid.Robot.from_urdf(text)


def test_file_encoding_and_declaration_are_honoured(tmp_path: Path) -> None:
    text = chain(*SERIAL).replace('name="t"', 'name="bras articulé"', 1)
    path = tmp_path / "latin1.urdf"
    path.write_bytes(b'<?xml version="1.0" encoding="iso-8859-1"?>\n' + text.encode("latin-1"))
    assert dynid.Robot.from_urdf(path).name == "bras articulé"
    declared = '<?xml version="1.0" encoding="utf-8"?>\n' + text
    assert dynid.Robot.from_urdf(declared).name == "bras articulé"


def test_bad_arguments_are_named(tmp_path: Path) -> None:
    text = chain(*SERIAL)
    with pytest.raises(ValueError, match="base_link: no link named 'nope'"):
        dynid.Robot.from_urdf(text, base_link="nope")
    with pytest.raises(ValueError, match="tip_link: no link named 'nope'"):
        dynid.Robot.from_urdf(text, tip_link="nope")
    with pytest.raises(ValueError, match="tip_link: 'l1' is not below base_link 'l2'"):
        dynid.Robot.from_urdf(text, base_link="l2", tip_link="l1")
    with pytest.raises(ValueError, match="convention"):
        dynid.Robot.from_urdf(text, convention="craig")
    with pytest.raises(ValueError, match="urdf: expected a path or the URDF text"):
        dynid.Robot.from_urdf(42)
    with pytest.raises(FileNotFoundError, match="urdf: no such file"):
        dynid.Robot.from_urdf(tmp_path / "absent.urdf")
    with pytest.raises(ValueError, match="gravity"):
        dynid.Robot.from_urdf(text, gravity=(0, 0))


def test_base_link_and_tip_link_select_the_chain() -> None:
    full = dynid.Robot.from_urdf(DATA / "kuka_lwr4.urdf")
    explicit = dynid.Robot.from_urdf(DATA / "kuka_lwr4.urdf", tip_link="lwr_7_link")
    q = np.linspace(-1.0, 1.0, 7)
    np.testing.assert_array_equal(full.fkine(q), explicit.fkine(q))  # the single leaf
    # a sub-chain: joints 3..5 of the arm (base_link lwr_2_link, tip lwr_5_link)
    sub = dynid.Robot.from_urdf(
        DATA / "kuka_lwr4.urdf", base_link="lwr_2_link", tip_link="lwr_5_link"
    )
    assert sub.n == 3
    np.testing.assert_array_equal(sub.qlim, full.qlim[2:5])
    np.testing.assert_array_equal(sub.Fv, full.Fv[2:5])
