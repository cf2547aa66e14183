"""Capsule radii from a URDF's collision geometry (dynid.model.urdf.collision, ``dynid excite
--capsule-radius urdf``): each link's largest cylinder, sphere or capsule radius, a box's half
diagonal of its two shorter sides; the segments mapped to the links they lie on in both DH
conventions; a link with meshes only refused naming it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from dynid.cli import main
from dynid.model.urdf.collision import segment_radii

LINK = """  <link name="{name}">
    <inertial><origin xyz="0 0 0.1"/><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    {collision}
  </link>"""
JOINT = """  <joint name="j{k}" type="revolute"><parent link="{parent}"/><child link="{child}"/>
    <origin xyz="0 0 0.3" rpy="{rpy}"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="50" velocity="2"/></joint>"""


def _urdf(collisions: dict[str, str]) -> str:
    names = ["base", "l1", "l2", "l3"]
    links = [LINK.format(name=n, collision=collisions.get(n, "")) for n in names]
    rpys = ["0 0 0", "1.5707963267948966 0 0", "0 0 0"]
    joints = [
        JOINT.format(k=k + 1, parent=names[k], child=names[k + 1], rpy=rpys[k]) for k in range(3)
    ]
    return '<robot name="arm">\n' + "\n".join(links + joints) + "\n</robot>"


GEOMETRY = {
    "base": '<collision><geometry><cylinder radius="0.12" length="0.2"/></geometry></collision>',
    "l1": '<collision><geometry><box size="0.3 0.06 0.08"/></geometry></collision>'
    '<collision><geometry><sphere radius="0.04"/></geometry></collision>',
    "l2": '<collision><geometry><cylinder radius="0.05" length="0.3"/></geometry></collision>',
    "l3": '<collision><geometry><sphere radius="0.03"/></geometry></collision>'
    '<collision><geometry><mesh filename="hand.stl"/></geometry></collision>',
}


def test_radii_per_segment_in_both_conventions(tmp_path) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(_urdf(GEOMETRY))
    box = 0.5 * np.hypot(0.06, 0.08)  # the box's two shorter sides: 0.05
    np.testing.assert_allclose(segment_radii(path, "standard"), [box, 0.05, 0.03, 0.03])
    np.testing.assert_allclose(segment_radii(path, "modified"), [0.12, box, 0.05, 0.03])


def test_meshes_only_are_refused_naming_the_link(tmp_path) -> None:
    geometry = dict(
        GEOMETRY, l2='<collision><geometry><mesh filename="a.stl"/></geometry></collision>'
    )
    with pytest.raises(ValueError, match="link 'l2': meshes only"):
        segment_radii(_urdf(geometry), "standard")
    bad = dict(GEOMETRY, l2='<collision><geometry><cylinder radius="-1"/></geometry></collision>')
    with pytest.raises(ValueError, match=r"link 'l2': <cylinder radius='-1'>"):
        segment_radii(_urdf(bad), "standard")


def test_excite_takes_them_from_the_urdf(tmp_path) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(_urdf(GEOMETRY))
    out = tmp_path / "plan"
    argv = ["excite", "--model", str(path), "--harmonics", "2", "--period", "4", "--maxiter", "10",
            "--capsule-radius", "urdf", "--no-report", "--output", str(out)]  # fmt: skip
    assert main(argv) == 0
    limits = json.loads((out / "trajectory.json").read_text())["limits"]
    recorded = json.dumps(limits)
    for radius in segment_radii(path, "standard"):
        assert repr(float(radius))[:6] in recorded
    assert main(["excite", "--model", "planar_2r", "--capsule-radius", "urdf",
                 "--output", str(tmp_path / "x")]) == 2  # fmt: skip
