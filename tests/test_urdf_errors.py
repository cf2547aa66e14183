"""Robot.from_urdf on URDFs it must refuse: a ValueError that names the joint, link or argument
(docs/urdf.md), never a silently wrong model; and the defaults for base_link and tip_link."""

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
    with pytest.raises(ValueError, match=r"link 'l2'.*joint 'j2'.*inertial.*check_physical"):
        dynid.Robot.from_urdf(text)
    assert not dynid.Robot.from_urdf(text, check_physical=False).params[1].any()  # to repair
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


def inertial(mass: str = "1", ixx: str = "0.1", iyy: str = "0.1", izz: str = "0.1") -> str:
    return (
        f'<inertial><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>'
    )


MASSLESS = inertial(mass="0", ixx="0", iyy="0", izz="0")


def with_link2(body: str, pad: str | None = None, extra: str = "") -> str:
    """The serial chain with link l2's inertial replaced by ``body`` and ``extra`` inside joint
    j2; with ``pad`` (an inertial, or ""), a link 'pad' is fixed between l2 and joint j3."""
    j3 = joint("j3", "l2" if pad is None else "pad", "l3")
    fixed = '<joint name="f" type="fixed"><parent link="l2"/><child link="pad"/></joint>'
    text = chain(
        joint("j1", "l0", "l1"),
        joint("j2", "l1", "l2", extra=extra),
        *([j3] if pad is None else [fixed, j3]),
        links="" if pad is None else f'<link name="pad">{pad}</link>',
    )
    return text.replace(f'<link name="l2">{INERTIAL}</link>', f'<link name="l2">{body}</link>')


@pytest.mark.parametrize(
    ("body", "pad", "reason"),
    [
        (inertial(mass="-1"), None, "mass -1.0 is not positive"),
        (MASSLESS, None, "mass 0.0 is not positive"),  # a frame between two joints: no body
        (inertial(ixx="-0.1"), None, "inertia about the centre of mass must be positive definite"),
        (inertial(izz="0.3"), None, "principal moments of inertia violate the triangle inequality"),
        (INERTIAL, inertial(mass="-2"), "mass -1.0 is not positive"),  # 1 kg - 2 kg
        (MASSLESS, inertial(mass="0.5", izz="0.3"), "principal moments"),  # pad's, merged
    ],
)
def test_a_body_that_to_urdf_refuses_is_refused_by_name(
    body: str, pad: str | None, reason: str
) -> None:
    """One rule (dynid.model.urdf.consistency) on both sides: the body from_urdf refuses (naming its
    link and joint, and the links merged into it) is the link to_urdf refuses, for the same
    reason; check_physical=False reads the file as it is."""
    text = with_link2(body, pad)
    merged = "" if pad is None else "; merged with 'pad'"
    with pytest.raises(
        ValueError,
        match=rf"^link 'l2' \(moved by joint 'j2'{merged}\) is not physically consistent "
        rf"\({reason}.*check_physical=False",
    ):
        dynid.Robot.from_urdf(text)
    robot = dynid.Robot.from_urdf(text, check_physical=False)
    assert robot.n == 3 and robot._link_inconsistency(1)  # link 2 as in the file
    assert not robot._link_inconsistency(0) and not robot._link_inconsistency(2)
    with pytest.raises(
        ValueError, match=rf"^robot: link 2 is not physically consistent \({reason}"
    ):
        robot.to_urdf()


@pytest.mark.parametrize(
    ("extra", "reason", "field", "value"),
    [
        ('<dynamics damping="-0.5"/>', r"negative damping \(Fv\) -0.5", "Fv", -0.5),
        ('<dynamics damping="0.2" friction="-0.1"/>', r"negative friction \(Fs\) -0.1", "Fs", -0.1),
        ('<!-- dynid: Ia="-0.3" -->', r"negative rotor inertia Ia -0.3", "Ia", -0.3),
    ],
)
def test_a_joint_that_to_urdf_refuses_is_refused_by_name(
    extra: str, reason: str, field: str, value: float
) -> None:
    text = with_link2(INERTIAL, extra=extra)
    with pytest.raises(ValueError, match=f"^joint 'j2' has {reason};.*check_physical=False"):
        dynid.Robot.from_urdf(text)
    robot = dynid.Robot.from_urdf(text, check_physical=False)
    assert getattr(robot, field)[1] == value
    with pytest.raises(ValueError, match=f"^robot: joint 2 has {reason};"):
        robot.to_urdf()
    setattr(robot, field, np.abs(getattr(robot, field)))  # repaired: written, read back
    assert getattr(dynid.Robot.from_urdf(robot.to_urdf()), field)[1] == -value


def test_massless_frames_merged_into_a_body_are_accepted() -> None:
    """A link of zero mass and inertia is a frame, not a body: fixed to a link with mass (tool0, a
    flange) or holding the mass on a link fixed to it, it is merged away; so is a point mass."""
    reference = dynid.Robot.from_urdf(chain(*SERIAL))
    for text in (with_link2(INERTIAL, MASSLESS), with_link2(MASSLESS, INERTIAL)):
        np.testing.assert_array_equal(dynid.Robot.from_urdf(text).params, reference.params)
    point_mass = dynid.Robot.from_urdf(with_link2(INERTIAL, inertial("0.5", "0", "0", "0")))
    assert point_mass.params[1, 0] == 1.5 and point_mass.is_physically_consistent()
    with pytest.raises(ValueError, match="check_physical: expected True or False"):
        dynid.Robot.from_urdf(chain(*SERIAL), check_physical="no")
