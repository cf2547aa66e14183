"""An estimated payload written the way robot controllers take it (``dynid payload``;
docs/payload.md).

Every controller wants the payload in its flange (tool-mount) frame: the mass, the centre of mass
from the flange origin, and the inertia about the centre of mass with axes parallel to the
flange's (KUKA: along the principal axes, given by their orientation). dynid estimates the payload
in the last DH frame n and moves it into the model's tool frame (``robot.tool``, frame n -> tool:
c_tool = R^T (c - p), I_tool = R^T I R; ``dynid.estimate_payload(frame="tool")``). So the tool
transform of the model must be the flange the controller means: identity for dynid's UR5/UR10
(frame 6 is ``tool0``) and the LWR4, a 0.107 m offset for the Panda (its flange frame F). The
functions here take a :class:`~dynid.identification.payload.PayloadEstimate` in that tool frame.

- Franka (libfranka ``Robot::setLoad(load_mass, F_x_Cload, load_inertia)``, the same fields as
  franka_msgs' SetLoad): mass [kg], F_x_Cload the centre of mass in the flange frame [m],
  load_inertia the 3x3 inertia about it, column-major [kg m^2].
- Universal Robots (URScript ``set_target_payload(m, cog, inertia)``): m [kg], cog [m] from the
  tool flange, inertia [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] [kg m^2] about the centre of gravity, axes
  of the tool flange; the entries of the inertia matrix.
- KUKA (``LOAD_DATA[k]={M .., CM {X .., Y .., Z .., A .., B .., C ..}, J {X .., Y .., Z ..}}``):
  M [kg]; X, Y, Z the centre of mass in the flange frame [mm]; A, B, C [deg] the orientation of
  the principal axes of inertia (A about Z, then B about the new Y, then C about the newest X:
  R = Rz(A) Ry(B) Rx(C)); JX, JY, JZ the principal moments [kg m^2].
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..identification.payload import PayloadEstimate, physical_from_parameters
from ..model.model_files import model_to_dict
from ..model.robot import Robot

#: The files ``dynid payload`` writes (write_payload_files).
FILES = (
    "payload.json",
    "franka_endeffector.json",
    "urscript.txt",
    "kuka_load_data.txt",
    "model.json",
)


def controller_payload(
    estimate: PayloadEstimate,
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """(mass, com (3,), inertia about the com (3, 3)) of an estimate in the tool frame;
    ValueError when it is in frame n or holds no centre of mass / inertia (mass not
    significant, or estimated without the inertia)."""
    if estimate.frame != "tool":
        raise ValueError(
            "estimate: controllers take the payload in their flange frame; estimate it with "
            "frame='tool' (the model's tool transform from the last DH frame to the flange)"
        )
    if estimate.com is None or estimate.inertia is None:
        raise ValueError(
            f"estimate: no significant payload (mass {estimate.mass:.6g} +- "
            f"{estimate.mass_std:.2g} kg): no centre of mass or inertia to write"
        )
    return estimate.mass, np.asarray(estimate.com), np.asarray(estimate.inertia)


def franka_endeffector(estimate: PayloadEstimate) -> dict[str, Any]:
    """libfranka's ``setLoad`` arguments as JSON fields: mass, F_x_Cload, load_inertia (the
    3x3 inertia about the centre of mass, column-major)."""
    mass, com, inertia = controller_payload(estimate)
    return {
        "mass": mass,
        "F_x_Cload": com.tolist(),
        "load_inertia": inertia.flatten(order="F").tolist(),
    }


def urscript(estimate: PayloadEstimate) -> str:
    """The URScript line ``set_target_payload(m, [cx, cy, cz], [Ixx, Iyy, Izz, Ixy, Ixz,
    Iyz])``: kg, m, kg m^2 (the floats written in full, as Python's repr)."""
    mass, com, J = controller_payload(estimate)
    inertia = [J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]]
    return (
        f"set_target_payload({_number(mass)}, [{', '.join(map(_number, com))}], "
        f"[{', '.join(map(_number, inertia))}])"
    )


def principal_axes(inertia: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(moments (3,), R (3, 3)) with inertia = R diag(moments) R^T, R a rotation whose columns
    are the principal axes. Of the 24 right-handed orderings and signs of the eigenvectors, the
    one closest to the identity (largest trace): a load whose axes are the flange's gets R = E
    and its moments in x, y, z order."""
    moments, vectors = np.linalg.eigh(inertia)
    best: tuple[float, NDArray[np.float64], NDArray[np.float64]] | None = None
    for order in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            R = vectors[:, order] * np.array(signs)
            if np.linalg.det(R) < 0:
                continue
            if best is None or np.trace(R) > best[0] + 1e-12:
                best = (float(np.trace(R)), moments[list(order)], R)
    assert best is not None  # half of the 48 candidates are right-handed
    return best[1], best[2]


def kuka_angles(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """(A, B, C) [deg] of a rotation R = Rz(A) Ry(B) Rx(C) (KUKA's convention), B in
    [-90, 90]; at B = +-90 (gimbal lock) C = 0."""
    B = np.arctan2(-R[2, 0], np.hypot(R[0, 0], R[1, 0]))
    if np.hypot(R[0, 0], R[1, 0]) < 1e-12:
        A, C = np.arctan2(-R[0, 1], R[1, 1]), 0.0
    else:
        A, C = np.arctan2(R[1, 0], R[0, 0]), np.arctan2(R[2, 1], R[2, 2])
    return np.degrees([A, B, C])


def kuka_load_data(estimate: PayloadEstimate, index: int = 1) -> str:
    """KUKA load data: the ``LOAD_DATA[index]={M ..,CM {..},J {..}}`` line of $config.dat
    (M kg; CM: X, Y, Z mm, A, B, C deg of the principal axes; J: JX, JY, JZ kg m^2), preceded
    by comment lines (';') naming the frame and the values."""
    mass, com, inertia = controller_payload(estimate)
    moments, R = principal_axes(inertia)
    A, B, C = kuka_angles(R)
    x, y, z = 1000.0 * com
    line = (
        f"LOAD_DATA[{index}]={{M {_number(mass)},CM {{X {_number(x)},Y {_number(y)},"
        f"Z {_number(z)},A {_number(A)},B {_number(B)},C {_number(C)}}},"
        f"J {{X {_number(moments[0])},Y {_number(moments[1])},Z {_number(moments[2])}}}}}"
    )
    return (
        "; dynid payload: load data in the flange frame (the model's tool frame)\n"
        "; M [kg]; X, Y, Z [mm] centre of mass; A, B, C [deg] principal axes, R = Rz(A) Ry(B) "
        "Rx(C); JX, JY, JZ [kg m^2]\n" + line
    )


def loaded_model(robot: Robot, estimate: PayloadEstimate) -> Robot:
    """``robot`` carrying the estimated payload on its last link (``estimate.parameters``, in
    frame n, added by :meth:`dynid.Robot.with_payload`); ValueError when the estimate is not a
    possible rigid body."""
    if estimate.parameters.size != 10:
        raise ValueError("estimate: a payload-compensated model needs the inertia too")
    phi, _ = physical_from_parameters(estimate.parameters)
    inertia = np.zeros((3, 3))
    rows, cols = np.array([0, 0, 0, 1, 1, 2]), np.array([0, 1, 2, 1, 2, 2])
    inertia[rows, cols] = phi[4:]
    inertia[cols, rows] = phi[4:]
    return robot.with_payload(phi[0], phi[1:4], inertia)


def payload_record(estimate: PayloadEstimate, robot: Robot) -> dict[str, Any]:
    """payload.json: the estimate with its standard deviations (``as_dict``), the frame named
    and the tool transform from the last DH frame n that defines it."""
    record = estimate.as_dict()
    record["frame"] = estimate.frame
    record["frame_description"] = (
        "com and inertia (about the centre of mass) in the model's tool frame, which the "
        "controller files take as the flange frame; parameters (m, m c, inertia about the origin) "
        "in the last DH frame n"
        if estimate.frame == "tool"
        else "com, inertia and parameters in the last DH frame n"
    )
    record["tool"] = np.asarray(robot.tool).tolist()
    record["units"] = {"mass": "kg", "com": "m", "inertia": "kg m^2"}
    return _json_ready(record)


def write_payload_files(
    estimate: PayloadEstimate, robot: Robot, folder: Path
) -> tuple[list[str], list[str]]:
    """Write :data:`FILES` into ``folder`` (a staging folder of
    :func:`dynid.export.output_folder.output_folder`). Returns the files written and the
    reasons for those left out (model.json when the estimate is no possible rigid body)."""
    from ..model.model_files import dumps_json

    folder = Path(folder)
    written, skipped = [], []
    texts = {
        "payload.json": dumps_json(payload_record(estimate, robot)),
        "franka_endeffector.json": json.dumps(franka_endeffector(estimate), indent=2),
        "urscript.txt": urscript(estimate) + "\n",
        "kuka_load_data.txt": kuka_load_data(estimate) + "\n",
    }
    try:
        model = loaded_model(robot, estimate)
    except ValueError as exc:
        skipped.append(f"model.json: {exc}")
    else:
        texts["model.json"] = dumps_json(model_to_dict(model))
    for name, text in texts.items():
        (folder / name).write_text(text if text.endswith("\n") else text + "\n")
        written.append(name)
    return written, skipped


def _json_ready(value: Any) -> Any:
    """``value`` with every non-finite float (an unknown standard deviation: a fit without
    degrees of freedom for its noise) as None, which JSON can hold."""
    if isinstance(value, dict):
        return {k: _json_ready(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_json_ready(v) for v in value]
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def _number(value: float) -> str:
    """A float as its shortest exact decimal (repr), never in a numpy wrapper."""
    return repr(float(value))
