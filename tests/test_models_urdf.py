"""models.panda(), ur5(), ur10() against their published sources and Pinocchio.

- panda: the link parameters equal the CSV of Gaz et al. 2019 (read here with the csv module) in
  physical form; its DH frames are the link frames of the franka_description URDF
  (tests/data/urdf/panda.urdf, read by Pinocchio) and its tool the flange panda_link8; and
  Pinocchio's model of that URDF with Gaz's inertias put in gives the same dynamics.
- ur5, ur10: Pinocchio on the URDF shipped in the package, and the DH lengths published by
  Universal Robots.
Tolerances: 1e-12 relative (exact maths, double rounding); 1e-10 relative in
``assert_matches_pinocchio`` (as in test_urdf.py).
"""

from __future__ import annotations

import csv
import re
from importlib.resources import files

import numpy as np
import pinocchio as pin
import pytest

import dynid
from pinocchio_urdf import DATA, assert_matches_pinocchio, relative_error
from reference_model import params_to_physical

TOL = 1e-12


def gaz_rows() -> list[dict[str, float]]:
    text = files("dynid").joinpath("data", "franka_panda_gaz2019.csv").read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(lines)]


def test_panda_parameters_are_the_published_ones() -> None:
    robot = dynid.models.panda()
    rows = gaz_rows()
    assert len(rows) == robot.n == 7 and robot.convention == "modified"
    assert robot.is_physically_consistent()  # the "feasible" set of the paper
    for params, row in zip(robot.params, rows):
        mass, com, inertia = params_to_physical(params)
        assert mass == pytest.approx(row["m"], rel=TOL)
        np.testing.assert_allclose(com, [row["cx"], row["cy"], row["cz"]], rtol=0, atol=TOL)
        expected = [
            [row["Ixx"], row["Ixy"], row["Ixz"]],
            [row["Ixy"], row["Iyy"], row["Iyz"]],
            [row["Ixz"], row["Iyz"], row["Izz"]],
        ]
        np.testing.assert_allclose(inertia, expected, rtol=0, atol=TOL)
    np.testing.assert_array_equal(robot.Ia, 0.0)
    np.testing.assert_array_equal(robot.Fv, 0.0)


def _panda_pinocchio(with_gaz_inertias: bool) -> tuple[pin.Model, pin.Data]:
    full = pin.buildModelFromUrdf(str(DATA / "panda.urdf"))
    fingers = [full.getJointId(f"panda_finger_joint{k}") for k in (1, 2)]
    model = pin.buildReducedModel(full, fingers, pin.neutral(full))
    if with_gaz_inertias:  # joint frames = link frames panda_link1..7
        for jid, row in enumerate(gaz_rows(), start=1):
            inertia = np.array(
                [
                    [row["Ixx"], row["Ixy"], row["Ixz"]],
                    [row["Ixy"], row["Iyy"], row["Iyz"]],
                    [row["Ixz"], row["Iyz"], row["Izz"]],
                ]
            )
            model.inertias[jid] = pin.Inertia(
                row["m"], np.array([row["cx"], row["cy"], row["cz"]]), inertia
            )
    return model, model.createData()


def test_panda_frames_are_the_urdf_link_frames() -> None:
    robot = dynid.models.panda()
    model, data = _panda_pinocchio(False)
    for q in robot.random_configurations(8, seed=11):
        pin.framesForwardKinematics(model, data, q)
        frame = robot.base.copy()
        for i in range(7):  # modified DH frame i = URDF panda_link{i+1}
            a, alpha, d, theta = robot.dh[i]
            ca, sa, ct, st = (
                np.cos(alpha),
                np.sin(alpha),
                np.cos(theta + q[i]),
                np.sin(theta + q[i]),
            )
            frame = (
                frame
                @ np.array([[1, 0, 0, a], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1]])
                @ np.array([[ct, -st, 0, 0], [st, ct, 0, 0], [0, 0, 1, d], [0, 0, 0, 1]])
            )
            urdf_frame = data.oMf[model.getFrameId(f"panda_link{i + 1}")].homogeneous
            assert relative_error(frame, urdf_frame) < TOL
        flange = data.oMf[model.getFrameId("panda_link8")].homogeneous
        assert relative_error(robot.fkine(q), flange) < TOL


def test_panda_dynamics_equal_pinocchio_with_the_published_inertias() -> None:
    robot = dynid.models.panda()
    model, data = _panda_pinocchio(True)
    rng = np.random.default_rng(5)
    for _ in range(8):
        q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 7))
        assert relative_error(robot.rnea(q, qd, qdd), pin.rnea(model, data, q, qd, qdd)) < TOL
        M = np.triu(pin.crba(model, data, q))
        assert relative_error(robot.mass_matrix(q), M + np.triu(M, 1).T) < TOL


@pytest.mark.parametrize(
    ("factory", "file", "lengths"),
    [
        # Universal Robots, "DH parameters for calculations of kinematics and dynamics":
        # d1, |a2|, |a3|, d4, d5, d6 [m]
        (dynid.models.ur5, "ur5.urdf", (0.089159, 0.425, 0.39225, 0.10915, 0.09465, 0.0823)),
        (dynid.models.ur10, "ur10.urdf", (0.1273, 0.612, 0.5723, 0.163941, 0.1157, 0.0922)),
    ],
)
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_ur_models(factory, file: str, lengths: tuple, convention: str) -> None:
    robot = factory(convention)
    text = files("dynid").joinpath("data", file).read_text(encoding="utf-8")
    assert_matches_pinocchio(robot, text, None, "tool0")
    assert robot.is_physically_consistent()
    if convention == "standard":
        d1, a2, a3, d4, d5, d6 = lengths
        np.testing.assert_allclose(np.abs(robot.dh[:, 0]), [0, a2, a3, 0, 0, 0], atol=1e-12)
        np.testing.assert_allclose(np.abs(robot.dh[:, 2]), [d1, 0, 0, d4, d5, d6], atol=1e-12)
    np.testing.assert_allclose(robot.base, np.eye(4), atol=1e-15)


def test_the_installed_package_ships_its_data() -> None:
    # wheel.packages = ["python/dynid"] ships every file of the folder, not only .py ones
    for name in ("franka_panda_gaz2019.csv", "ur5.urdf", "ur10.urdf", "README.md"):
        assert files("dynid").joinpath("data", name).is_file(), name


def test_info_prints_rounding_residue_as_zero_and_keeps_real_small_values():
    """`dynid info` on the UR5 read from its URDF printed alpha = -6.12323e-17 (-3.508e-15°) and a
    product of inertia of 1.704e-100 (issue 22). Residue below 1e-9 of its scale reads 0 (never
    -0); a value that is small but real (a light link's inertia) is printed as it is."""
    from dynid.export.summary import model_summary

    robot = dynid.models.ur5()
    assert np.abs(robot.dh[:, 1] % (np.pi / 2)).min() < 1e-15  # the residue is there...
    text = model_summary(robot)
    assert not re.search(r"e-(1[0-9]|[2-9][0-9]|1[0-9][0-9])\b", text), text  # ...not shown
    assert "-0 " not in text and "-0.0," not in text
    light = dynid.models.planar_2r()
    light.set_link(1, mass=1e-3, com=[1e-4, 0, 0], inertia_com=np.diag([1e-9, 2e-9, 3e-9]))
    row = next(line for line in model_summary(light).splitlines() if "link 2:" in line)
    assert "0.001" in row and "1e-07" in row, row  # mx = m * 1e-4
