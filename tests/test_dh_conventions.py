"""The same arm in standard DH and in modified DH must give identical dynamics.

The modified description is derived here from the standard one, independently of dynid:

- modified row i = (a_{i-1}, alpha_{i-1}, d_i, theta_i) with a_0 = alpha_0 = 0;
- standard frame i = modified frame i * Tx(a_i) Rx(alpha_i) (Rx and Tx commute), so the last
  row's Tx(a_n) Rx(alpha_n) moves into the tool: tool_mod = Tx(a_n) Rx(alpha_n) tool_std;
- link i's CoM and inertia are carried from standard frame i to modified frame i by that
  rigid transform: com_mod = R com_std + p, Ic_mod = R Ic_std R^T, then Steiner about the
  new origin (reference_model.steiner).

Tolerance: 1e-10 relative (max |diff| / max(1, max |value|)).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
import reference_model as ref
from conftest import make_arm, random_arm, random_state

TOL = 1e-10
DATA = Path(__file__).parent / "data" / "kuka_lwr4_dh.json"


def std_to_modified(arm: ref.Arm) -> ref.Arm:
    assert arm.convention == "standard"
    n = arm.n
    dh = np.zeros((n, 4))
    dh[:, 2:] = arm.dh[:, 2:]  # d_i, theta_i stay on row i
    dh[1:, :2] = arm.dh[:-1, :2]  # a_{i-1}, alpha_{i-1} move down one row
    com, inertia = np.empty((n, 3)), np.empty((n, 3, 3))
    for i in range(n):
        a, alpha = arm.dh[i, :2]
        rot = ref.rot_x(alpha)[:3, :3]
        com[i] = rot @ arm.com[i] + np.array([a, 0.0, 0.0])
        rotated = rot @ arm.inertia_com[i] @ rot.T
        inertia[i] = 0.5 * (rotated + rotated.T)
    a_n, alpha_n = arm.dh[-1, :2]
    return ref.Arm(
        dh=dh,
        joint_types=arm.joint_types,
        convention="modified",
        mass=arm.mass.copy(),
        com=com,
        inertia_com=inertia,
        Ia=arm.Ia.copy(),
        Fv=arm.Fv.copy(),
        Fs=arm.Fs.copy(),
        gravity=arm.gravity.copy(),
        base=arm.base.copy(),
        tool=ref.trans(a_n, 0, 0) @ ref.rot_x(alpha_n) @ arm.tool,
    )


def rel_err(got: np.ndarray, expected: np.ndarray) -> float:
    got, expected = np.asarray(got, dtype=float), np.asarray(expected, dtype=float)
    assert got.shape == expected.shape
    return float(np.max(np.abs(got - expected)) / max(1.0, float(np.max(np.abs(expected)))))


def assert_same_dynamics(
    std: dynid.Robot, mod: dynid.Robot, types: str, rng: np.random.Generator
) -> None:
    for _ in range(4):
        q, qd, qdd = random_state(rng, types)
        for name, args in [
            ("fkine", (q,)),
            ("jacobian", (q,)),
            ("rnea", (q, qd, qdd)),
            ("mass_matrix", (q,)),
            ("gravity", (q,)),
            ("coriolis_matrix", (q, qd)),
            ("kinetic_energy", (q, qd)),
            ("potential_energy", (q,)),
        ]:
            err = rel_err(getattr(mod, name)(*args), getattr(std, name)(*args))
            assert err <= TOL, (
                f"{name}: standard and modified differ by {err:.3g} at q={q.tolist()}"
            )


def load_json() -> dict:
    return json.loads(DATA.read_text())


def json_arm(source: str, convention: str) -> ref.Arm:
    data = load_json()
    table = data["dh"][convention]
    keys = (
        ("a", "alpha", "d", "theta_offset")
        if convention == "standard"
        else ("a_prev", "alpha_prev", "d", "theta_offset")
    )
    dh = np.array([[row[k] for k in keys] for row in table["rows"]], dtype=float)
    links = [
        ref.params_to_physical(np.asarray(p, dtype=float))
        for p in data["params"][source][convention]
    ]
    return ref.Arm(
        dh=dh,
        joint_types=table["joint_types"],
        convention=convention,
        mass=np.array([link[0] for link in links]),
        com=np.array([link[1] for link in links]),
        inertia_com=np.array([link[2] for link in links]),
    )


@pytest.mark.parametrize("via_set_link", [True, False], ids=["set_link", "params"])
@pytest.mark.parametrize("case", ["lwr", "json_head", "random_prismatic"])
def test_standard_equals_modified(case: str, via_set_link: bool, rng: np.random.Generator) -> None:
    if case == "lwr":
        arm = make_arm("lwr")
    elif case == "json_head":
        arm = json_arm("kuka_lwr4.urdf (HEAD)", "standard")
    else:
        arm = random_arm(np.random.default_rng(99), 6, "standard", "RPPRPR")
    mod = std_to_modified(arm)
    assert_same_dynamics(arm.robot(via_set_link), mod.robot(via_set_link), arm.joint_types, rng)


def test_helper_reproduces_json_modified_description() -> None:
    """Sanity check of this file's conversion on the JSON, which gives both forms (1e-12)."""
    for source in ("kuka_lwr4.urdf (HEAD)", "kuka_lwr4_e6c077e.urdf"):
        converted = std_to_modified(json_arm(source, "standard"))
        given = json_arm(source, "modified")
        np.testing.assert_allclose(converted.dh, given.dh, atol=1e-15)
        np.testing.assert_allclose(converted.tool, np.eye(4), atol=1e-15)  # a_7 = alpha_7 = 0
        np.testing.assert_allclose(converted.params, given.params, atol=1e-12)


@pytest.mark.parametrize("source", ["kuka_lwr4.urdf (HEAD)", "kuka_lwr4_e6c077e.urdf"])
def test_json_reference_arm_both_tables(source: str, rng: np.random.Generator) -> None:
    """The JSON's two explicit descriptions (tables and params as given) agree in dynid."""
    data = load_json()
    robots = {}
    for convention in ("standard", "modified"):
        arm = json_arm(source, convention)
        robots[convention] = dynid.Robot.from_dh(
            arm.dh,
            joint_types=arm.joint_types,
            convention=convention,
            params=np.asarray(data["params"][source][convention], dtype=float),
        )
    assert_same_dynamics(robots["standard"], robots["modified"], "R" * 7, rng)
