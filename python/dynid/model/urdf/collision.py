"""The radius of each link's collision geometry in a URDF: the capsules of ``dynid excite``'s
keep-out (issue 21, item 1: "a minimum distance between non-adjacent links modelled as capsules
(radii from options or the URDF collision geometry)").

A link's radius is the largest of its ``<collision><geometry>`` elements': a ``<cylinder
radius>`` or ``<sphere radius>`` (a ``<capsule radius>``, which some URDFs carry, too) is its
radius; a ``<box size="x y z">`` counts as the cylinder about its longest side that holds it,
half the diagonal of the two shorter sides. A ``<mesh>`` has no radius that could be read
without loading the mesh: a link with meshes only has none (a ValueError names it, so that the
radius is given with ``--capsule-radius`` instead).

The capsules of the keep-out lie along the segments between consecutive DH frame origins
(:mod:`dynid.excitation.cartesian`): segment i (1..n) lies on the link moved by joint i in the
standard convention (frame i sits on link i), on the link before it in the modified one (frame
i - 1 and frame i both sit on joints of link i - 1, the base link for i = 1); segment n + 1, to
the tool point, on the last link.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .tree import _text, read_tree, serial_chain


def segment_radii(
    urdf: str | Path, convention: str, base_link: str | None = None, tip_link: str | None = None
) -> NDArray[np.float64]:
    """(n + 1,) capsule radii [m] of the keep-out's segments for the URDF's chain from
    ``base_link`` to ``tip_link`` in ``convention`` (module docstring). ValueError naming a
    link whose collision geometry gives no radius."""
    tree = read_tree(urdf)
    chain = serial_chain(tree, base_link, tip_link)
    movable = [joint for joint in chain if joint.type != "fixed"]
    root = _root(urdf)
    links = [movable[0].parent] + [joint.child for joint in movable]  # base, link 1 .. link n
    n = len(movable)
    # standard: segment i on link i; modified: on link i - 1 (the base for i = 1)
    first = 1 if convention == "standard" else 0
    owners = [*links[first : first + n], links[n]]
    return np.array([_radius(root, name) for name in owners])


def _root(urdf: str | Path) -> ET.Element:
    return ET.fromstring(_text(urdf))  # read_tree has checked the XML


def _radius(root: ET.Element, link: str) -> float:
    element = next((e for e in root.findall("link") if e.get("name") == link), None)
    radii, meshes = [], 0
    for collision in [] if element is None else element.findall("collision"):
        for geometry in collision.findall("geometry"):
            for shape in geometry:
                if shape.tag in ("cylinder", "sphere", "capsule"):
                    radii.append(_number(shape, "radius", link))
                elif shape.tag == "box":
                    size = sorted(_numbers(shape, "size", link))
                    radii.append(0.5 * float(np.hypot(size[0], size[1])))
                elif shape.tag == "mesh":
                    meshes += 1
    if not radii:
        what = "meshes only" if meshes else "no <collision> geometry"
        raise ValueError(
            f"link {link!r}: {what}, no radius to read (give the capsules' radii with "
            "--capsule-radius R)"
        )
    return max(radii)


def _number(shape: ET.Element, name: str, link: str) -> float:
    values = _numbers(shape, name, link)
    if len(values) != 1:
        raise ValueError(f"link {link!r}: <{shape.tag} {name}> expected one number")
    return values[0]


def _numbers(shape: ET.Element, name: str, link: str) -> list[float]:
    try:
        values = [float(v) for v in (shape.get(name) or "").split()]
    except ValueError:
        values = []
    if not values or not all(np.isfinite(values)) or min(values) < 0:
        raise ValueError(
            f"link {link!r}: <{shape.tag} {name}={shape.get(name)!r}> expected numbers >= 0"
        )
    return values
