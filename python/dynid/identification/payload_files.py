"""A known payload from the command line (``dynid identify --current --payload FILE|NUMBERS``).

FILE is a JSON or YAML file holding either the payload's physical description in the last DH
frame n::

    {"mass": 1.5, "com": [0.0, 0.0, 0.08], "inertia": [[0.004, 0, 0], [0, 0.005, 0], [0, 0, 0.003]]}

(``inertia`` about the centre of mass, frame-n axes; omitted: a point mass), or its 10 standard
parameters about the origin of frame n (``{"parameters": [m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz,
Izz]}``), or these 10 numbers written inline, separated by commas (NUMBERS). The values are
checked by :func:`dynid.identify_drive_gains`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from ..model.model_files import read_structured

PathLike = Union[str, Path]

#: The keys a payload file may hold.
KEYS = ("mass", "com", "inertia", "parameters")


def load_payload(spec: PathLike) -> dict[str, Any] | NDArray[np.float64]:
    """The payload of ``spec`` (a file or 10 comma-separated numbers, module docstring): a
    mapping with mass, com (and inertia) or the (10,) standard parameters. ValueError naming
    ``payload`` (and the file) when it is neither."""
    path = Path(spec)
    if not path.is_file():
        text = str(spec)
        parts = text.split(",")
        if len(parts) != 10:
            raise ValueError(
                f"payload: {text!r} is neither a file nor 10 comma-separated numbers (m, mx, my, "
                "mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz in the last DH frame)"
            )
        try:
            return np.array([float(part) for part in parts])
        except ValueError:
            raise ValueError(f"payload: {text!r}: expected 10 numbers") from None
    try:
        data = read_structured(path)
    except ValueError as exc:
        raise ValueError(f"payload: {path}: {exc}") from None
    if not isinstance(data, dict) or not data or set(data) - set(KEYS):
        raise ValueError(
            f"payload: {path}: expected an object with mass, com (and inertia), or with "
            f"parameters (10 numbers), got {data if not isinstance(data, dict) else sorted(data)}"
        )
    if "parameters" in data:
        if len(data) != 1:
            raise ValueError(f"payload: {path}: give parameters alone, or mass, com and inertia")
        try:
            return np.array(data["parameters"], dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"payload: {path}: parameters: expected 10 numbers") from None
    return dict(data)
