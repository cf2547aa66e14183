"""KUKA LWR4+ against Pinocchio 4.1 on the FloBaRoID URDFs (tests/data/kuka_lwr4_dh.json).

The JSON gives standard and modified DH tables equivalent to the URDF, the URDF inertias in
dynid order about each DH frame origin, and one sample (q, qd, qdd) with Pinocchio's rnea,
g and M (rigid body only, gravity (0, 0, -9.81)). The JSON stores ~16 significant digits,
so the tolerance is 1e-9 absolute (N m, kg m^2); the values are O(0.01..50).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid

DATA = json.loads((Path(__file__).parent / "data" / "kuka_lwr4_dh.json").read_text())
ATOL = 1e-9
KEYS = {
    "standard": ("a", "alpha", "d", "theta_offset"),
    "modified": ("a_prev", "alpha_prev", "d", "theta_offset"),
}


def robot_from_json(source: str, convention: str, flat: bool) -> dynid.Robot:
    table = DATA["dh"][convention]
    dh = [[row[k] for k in KEYS[convention]] for row in table["rows"]]
    params = np.asarray(DATA["params"][source][convention], dtype=float)
    return dynid.Robot.from_dh(
        dh,
        joint_types=table["joint_types"],
        convention=convention,
        gravity=tuple(DATA["check_sample"][source]["gravity"]),
        params=params.ravel() if flat else params,
    )


@pytest.mark.parametrize("flat", [False, True], ids=["params_n_by_10", "params_flat"])
@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("source", ["kuka_lwr4.urdf (HEAD)", "kuka_lwr4_e6c077e.urdf"])
def test_matches_pinocchio(source: str, convention: str, flat: bool) -> None:
    sample = DATA["check_sample"][source]
    robot = robot_from_json(source, convention, flat)
    q, qd, qdd = (np.asarray(sample[k], dtype=float) for k in ("q", "qd", "qdd"))
    np.testing.assert_allclose(robot.rnea(q, qd, qdd), sample["tau_rnea"], rtol=0, atol=ATOL)
    np.testing.assert_allclose(robot.gravity(q), sample["g"], rtol=0, atol=ATOL)
    np.testing.assert_allclose(robot.mass_matrix(q), sample["M"], rtol=0, atol=ATOL)
    # Pinocchio's c = tau_rnea - M qdd - g, so dynid's coriolis must close the balance
    np.testing.assert_allclose(
        np.asarray(sample["M"]) @ qdd + robot.coriolis(q, qd) + np.asarray(sample["g"]),
        sample["tau_rnea"],
        rtol=0,
        atol=ATOL,
    )
