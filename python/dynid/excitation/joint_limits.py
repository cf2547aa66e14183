"""Joint velocity and torque limits from a URDF's ``<limit velocity effort>`` (issue 21).

The model itself (``Robot``) holds only the position limits ``qlim``; ``dynid excite`` reads a
URDF's velocity and effort limits here, by joint name. A URDF requires both attributes on
revolute and prismatic joints, but files in the wild write ``0`` (dynid's own exporter before
issue 21 did, to mean "unknown"): 0, a missing attribute and a continuous joint without
``<limit>`` all give NaN, "not given", for the caller's default to fill.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray


def urdf_velocity_effort(
    urdf: str | Path, joint_names: Sequence[str]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(velocity, effort) limits of the joints ``joint_names`` in ``urdf``, NaN where not given
    (see the module); ValueError naming the joint for a negative or non-numeric value."""
    try:
        root = ET.parse(urdf).getroot()
    except ET.ParseError as exc:
        raise ValueError(f"urdf: malformed XML: {exc}") from None
    joints = {j.get("name"): j for j in root.findall("joint")}
    velocity = np.full(len(joint_names), np.nan)
    effort = np.full(len(joint_names), np.nan)
    for k, name in enumerate(joint_names):
        joint = joints.get(name)
        limit = None if joint is None else joint.find("limit")
        if limit is None:
            continue
        for values, key in ((velocity, "velocity"), (effort, "effort")):
            text = limit.get(key)
            if text is None:
                continue
            try:
                value = float(text)
            except ValueError:
                value = math.nan
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(
                    f"urdf: joint {name!r} <limit {key}={text!r}>: expected a number >= 0"
                )
            values[k] = value if value > 0.0 else math.nan
    return velocity, effort
