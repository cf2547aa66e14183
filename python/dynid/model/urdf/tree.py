"""A URDF file read into links and joints, and the serial chain between two of its links.

Only what dynamics needs is read: each link's ``<inertial>``, each joint's type, parent, child,
``<origin>``, ``<axis>``, ``<limit lower upper>``, ``<dynamics damping friction>`` and whether it
has a ``<mimic>``. Geometry (visual, collision), transmissions and Gazebo tags are ignored; only
the ``<link>`` and ``<joint>`` elements directly under ``<robot>`` count (a ``<transmission>``
also holds ``<joint>`` elements).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..._checks import MAX_JOINTS

if TYPE_CHECKING:
    from typing_extensions import TypeAlias  # typing.TypeAlias is 3.10+

Array: TypeAlias = NDArray[np.float64]
MOVABLE = ("revolute", "continuous", "prismatic")
JOINT_TYPES = (*MOVABLE, "fixed", "floating", "planar")
#: The comment ``to_urdf`` writes inside a joint for its rotor inertia (no URDF field holds it).
ROTOR_COMMENT = re.compile(r'dynid:\s*Ia="([^"]*)"')


@dataclass
class Inertial:
    mass: float
    origin: Array  # (4, 4) pose of the centre-of-mass frame in the link frame
    inertia: Array  # (3, 3) about the centre of mass, axes of the centre-of-mass frame


@dataclass
class Joint:
    name: str
    type: str
    parent: str
    child: str
    origin: Array  # (4, 4) joint frame in the parent link frame
    axis: Array  # (3,) unit, joint frame axes (movable joints only)
    limits: tuple[float, float] | None
    velocity_limit: float  # <limit velocity>, inf when absent, 0 or UNLIMITED and above
    effort_limit: float  # <limit effort>, the same
    damping: float
    friction: float
    mimic: bool
    rotor_inertia: float  # from a dynid comment, else 0


@dataclass
class UrdfTree:
    name: str
    links: dict[str, Inertial | None]
    joints: dict[str, Joint]  # by child link name
    joint_names: set[str] = field(default_factory=set)
    # parent link -> its joints, in file order: indexed once, so that walking the tree is linear
    # in its size (scanning every joint for each link made a 100k-link file take ~20 minutes)
    _children: dict[str, list[Joint]] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._children = {}
        for joint in self.joints.values():
            self._children.setdefault(joint.parent, []).append(joint)

    @property
    def root(self) -> str:
        return next(name for name in self.links if name not in self.joints)

    def children(self, link: str) -> list[Joint]:
        return self._children.get(link, [])


def rpy_matrix(roll: float, pitch: float, yaw: float) -> Array:
    """URDF ``rpy``: fixed-axis rotations about x, then y, then z, i.e.
    R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr, cp, sp, cy, sy = (
        np.cos(roll),
        np.sin(roll),
        np.cos(pitch),
        np.sin(pitch),
        np.cos(yaw),
        np.sin(yaw),
    )
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])  # fmt: skip


def read_tree(urdf: str | Path) -> UrdfTree:
    """Parse a URDF given as a path or as the XML text. ValueError for malformed XML or content
    (naming the element); FileNotFoundError for a path that does not exist."""
    text = _text(urdf)
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    try:
        root = ET.fromstring(text, parser=parser)
    except ET.ParseError as exc:
        raise ValueError(f"urdf: malformed XML: {exc}") from None
    if root.tag != "robot":
        raise ValueError(f"urdf: expected a <robot> root element, got <{root.tag}>")
    links: dict[str, Inertial | None] = {}
    for element in root.findall("link"):
        name = _name(element, "link")
        if name in links:
            raise ValueError(f"urdf: two links named {name!r}")
        links[name] = _inertial(element.find("inertial"), name)
    if not links:
        raise ValueError("urdf: no <link> element")
    joints: dict[str, Joint] = {}
    names: set[str] = set()
    for element in root.findall("joint"):
        joint = _joint(element, links)
        if joint.name in names:
            raise ValueError(f"urdf: two joints named {joint.name!r}")
        if joint.child in joints:
            raise ValueError(
                f"urdf: link {joint.child!r} is the child of two joints "
                f"({joints[joint.child].name!r}, {joint.name!r}): not a tree"
            )
        names.add(joint.name)
        joints[joint.child] = joint
    tree = UrdfTree(root.get("name", "robot"), links, joints, names)
    roots = [name for name in links if name not in joints]
    if len(roots) != 1:
        raise ValueError(
            f"urdf: expected one root link (a link that is no joint's child), got "
            f"{len(roots)}: {roots[:5]} (a cycle or several trees)"
        )
    reached, stack = {roots[0]}, [roots[0]]
    while stack:
        for joint in tree.children(stack.pop()):
            reached.add(joint.child)
            stack.append(joint.child)
    if len(reached) != len(links):
        lost = [name for name in links if name not in reached]
        raise ValueError(
            f"urdf: links {lost[:5]} are not connected to the root {roots[0]!r} (a cycle of joints)"
        )
    return tree


def serial_chain(tree: UrdfTree, base_link: str | None, tip_link: str | None) -> list[Joint]:
    """The joints from ``base_link`` (default: the root) down to ``tip_link`` (default: the single
    leaf below a movable joint), fixed ones included, in order; at most MAX_JOINTS movable."""
    base = tree.root if base_link is None else _link_name(tree, base_link, "base_link")
    if tip_link is None:
        leaves = _moving_leaves(tree, base)
        if not leaves:
            raise ValueError(f"urdf: no movable joint below {base!r}")
        if len(leaves) != 1:
            found = ", ".join(repr(leaf) for leaf in leaves)
            raise ValueError(
                f"tip_link: the tree below {base!r} has {len(leaves)} leaves reached "
                f"through movable joints ({found}); pass tip_link= to choose one"
            )
        tip = leaves[0]
    else:
        tip = _link_name(tree, tip_link, "tip_link")
    chain: list[Joint] = []
    link = tip
    while link != base:
        if link not in tree.joints:
            raise ValueError(f"tip_link: {tip!r} is not below base_link {base!r}")
        chain.append(tree.joints[link])
        link = chain[-1].parent
    chain.reverse()
    for joint in chain:
        if joint.type in ("floating", "planar"):
            raise ValueError(
                f"joint {joint.name!r}: a {joint.type} joint is not a joint of a "
                "serial arm (only revolute, continuous, prismatic and fixed)"
            )
        if joint.mimic and joint.type in MOVABLE:
            raise ValueError(
                f"joint {joint.name!r}: a mimic joint (coupled to another) cannot be "
                "an independent DH joint"
            )
    movable = sum(joint.type in MOVABLE for joint in chain)
    if not movable:
        raise ValueError(f"urdf: no movable joint between {base!r} and {tip!r}")
    if movable > MAX_JOINTS:
        raise ValueError(
            f"urdf: the chain from {base!r} to tip_link {tip!r} has {movable} movable joints; "
            f"a robot read from a file (URDF or model file) has at most {MAX_JOINTS}"
        )
    return chain


def _moving_leaves(tree: UrdfTree, base: str) -> list[str]:
    leaves: list[str] = []
    stack = [(base, False)]
    while stack:
        link, moved = stack.pop()
        children = tree.children(link)
        if not children and moved:
            leaves.append(link)
        stack += [(j.child, moved or j.type in MOVABLE) for j in reversed(children)]
    return leaves


def _link_name(tree: UrdfTree, name: object, argument: str) -> str:
    if not isinstance(name, str) or name not in tree.links:
        known = ", ".join(list(tree.links)[:12])
        raise ValueError(
            f"{argument}: no link named {name!r} in the URDF (links: {known}"
            f"{', ...' if len(tree.links) > 12 else ''})"
        )
    return name


def _text(urdf: str | Path) -> str | bytes:
    if isinstance(urdf, Path) or (isinstance(urdf, str) and not urdf.lstrip().startswith("<")):
        path = Path(urdf)
        if not path.is_file():
            raise FileNotFoundError(f"urdf: no such file: {path}")
        return path.read_bytes()  # the parser honours the file's encoding declaration
    if isinstance(urdf, str):
        return urdf
    raise ValueError(f"urdf: expected a path or the URDF text, got {type(urdf).__name__}")


def _name(element: ET.Element, what: str) -> str:
    name = element.get("name")
    if not name:
        raise ValueError(f"urdf: a <{what}> without a name")
    return name


def _floats(
    element: ET.Element | None, attribute: str, count: int, default: str, where: str
) -> Array:
    text = default if element is None else element.get(attribute, default)
    try:
        values = np.array([float(v) for v in text.split()])
    except ValueError:
        values = np.array([])
    if values.shape != (count,) or not np.all(np.isfinite(values)):
        raise ValueError(f"{where}: {attribute}={text!r}, expected {count} finite numbers")
    return values


def _number(element: ET.Element, attribute: str, where: str, default: str | None = None) -> float:
    if element.get(attribute) is None and default is None:
        raise ValueError(f"{where}: missing attribute {attribute!r}")
    return float(_floats(element, attribute, 1, default or "", where)[0])


#: A velocity or effort limit written by dynid for a limit it does not know (URDF requires the
#: attributes, and 0 makes Gazebo, PyBullet and ros2_control refuse to move the joint); read
#: back, this value and anything above it mean no limit.
UNLIMITED = 1e6


def _rate_limit(limit: ET.Element, name: str, where: str) -> float:
    """<limit velocity|effort>: the value, or inf (no limit) when absent, 0 (what many URDFs
    write for "not given") or >= UNLIMITED; ValueError naming it when negative."""
    value = _number(limit, name, where, "0")
    if value < 0:
        raise ValueError(f"{where}: {name}={value}, expected a value >= 0")
    return np.inf if value == 0 or value >= UNLIMITED else value


def _origin(element: ET.Element | None, where: str) -> Array:
    pose = np.eye(4)
    pose[:3, :3] = rpy_matrix(*_floats(element, "rpy", 3, "0 0 0", f"{where} <origin>"))
    pose[:3, 3] = _floats(element, "xyz", 3, "0 0 0", f"{where} <origin>")
    return pose


def _inertial(element: ET.Element | None, link: str) -> Inertial | None:
    if element is None:
        return None
    where = f"link {link!r} <inertial>"
    mass_element = element.find("mass")
    inertia_element = element.find("inertia")
    if mass_element is None or inertia_element is None:
        raise ValueError(f"{where}: expected <mass> and <inertia>")
    mass = _number(mass_element, "value", f"{where} <mass>")
    i = {
        k: _number(inertia_element, k, f"{where} <inertia>")
        for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    }
    inertia = np.array(
        [
            [i["ixx"], i["ixy"], i["ixz"]],
            [i["ixy"], i["iyy"], i["iyz"]],
            [i["ixz"], i["iyz"], i["izz"]],
        ]
    )
    return Inertial(mass, _origin(element.find("origin"), where), inertia)


def _joint(element: ET.Element, links: dict[str, Inertial | None]) -> Joint:
    name = _name(element, "joint")
    where = f"joint {name!r}"
    kind = element.get("type")
    if kind not in JOINT_TYPES:
        raise ValueError(
            f"{where}: unknown type {kind!r}, expected one of {', '.join(JOINT_TYPES)}"
        )
    ends = {}
    for end in ("parent", "child"):
        tag = element.find(end)
        ends[end] = None if tag is None else tag.get("link")
        if ends[end] not in links:
            raise ValueError(
                f"{where}: <{end} link=...> names no link of the URDF (got {ends[end]!r})"
            )
    axis = _floats(element.find("axis"), "xyz", 3, "1 0 0", f"{where} <axis>")
    norm = float(np.linalg.norm(axis))
    if kind in MOVABLE:
        if norm < 1e-9:
            raise ValueError(f"{where}: <axis xyz> has zero length")
        axis = axis / norm
    limit = element.find("limit")
    limits = None
    if (
        kind in ("revolute", "prismatic")
        and limit is not None
        and (limit.get("lower") is not None or limit.get("upper") is not None)
    ):
        lower = _number(limit, "lower", f"{where} <limit>", "0")
        upper = _number(limit, "upper", f"{where} <limit>", "0")
        if not lower < upper:
            raise ValueError(
                f"{where}: <limit lower={lower} upper={upper}>, expected lower < upper"
            )
        limits = (lower, upper)
    velocity_limit = effort_limit = np.inf
    if kind in MOVABLE and limit is not None:
        velocity_limit = _rate_limit(limit, "velocity", f"{where} <limit>")
        effort_limit = _rate_limit(limit, "effort", f"{where} <limit>")
    dynamics = element.find("dynamics")
    damping = friction = 0.0
    if dynamics is not None:
        damping = _number(dynamics, "damping", f"{where} <dynamics>", "0")
        friction = _number(dynamics, "friction", f"{where} <dynamics>", "0")
    rotor = 0.0
    # ElementTree tags comments with the Comment factory itself; typeshed types tags as str.
    for comment in element.iter(ET.Comment):  # type: ignore[arg-type]
        match = ROTOR_COMMENT.search(comment.text or "")
        if match:
            rotor = _number(ET.Element("x", {"Ia": match.group(1)}), "Ia", f"{where} comment")
    parent, child = ends["parent"], ends["child"]
    assert parent is not None and child is not None  # both name links (checked above)
    return Joint(
        name,
        kind,
        parent,
        child,
        _origin(element.find("origin"), where),
        axis,
        limits,
        velocity_limit,
        effort_limit,
        damping,
        friction,
        element.find("mimic") is not None,
        rotor,
    )
