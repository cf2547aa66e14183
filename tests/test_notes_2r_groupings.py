"""The notes' 2R groupings (pp. 22-23; dynid.model.notes_2r_groupings): u = Y a equals the
inverse dynamics of dynid.models.planar_2r (1e-12) for random arms and states, the coefficients
equal the notes' closed forms in the notes' symbols (d_i, Ic_i), and the four coefficients
span the same torques as dynid's base parameters of an arm whose centres of mass lie on the
link axes."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.model.notes_2r_groupings import notes_2r_grouping


def _arm(seed: int, gravity=(0.0, -9.81, 0.0)):
    rng = np.random.default_rng(seed)
    l1, l2 = rng.uniform(0.3, 1.2, 2)
    lc1, lc2 = rng.uniform(0.1, 0.9, 2) * (l1, l2)
    m1, m2 = rng.uniform(0.5, 5.0, 2)
    I1, I2 = rng.uniform(0.01, 0.3, 2)
    robot = dynid.models.planar_2r(l1, l2, lc1, lc2, m1, m2, I1, I2, gravity=gravity)
    return robot, {
        "l1": l1,
        "l2": l2,
        "d1": lc1,
        "d2": lc2,
        "m1": m1,
        "m2": m2,
        "Ic1": I1,
        "Ic2": I2,
    }


def _states(seed: int, T: int = 50):
    return np.random.default_rng(seed + 100).uniform(-2, 2, (3, T, 2))


@pytest.mark.parametrize("name", ["notes_2r", "notes_2r_heuristic"])
@pytest.mark.parametrize("seed", range(4))
def test_y_a_is_the_inverse_dynamics(name, seed) -> None:
    robot, _ = _arm(seed)
    grouping = notes_2r_grouping(robot, name)
    q, qd, qdd = _states(seed)
    expected = robot.rnea(q, qd, qdd)
    got = grouping.regressor(q, qd, qdd) @ grouping.coefficients(robot)
    assert np.max(np.abs(got - expected)) <= 1e-12 * np.max(np.abs(expected))


def test_coefficients_are_the_notes_closed_forms() -> None:
    robot, s = _arm(7)
    g0 = 9.81
    four = notes_2r_grouping(robot).coefficients(robot)
    a1 = (
        s["Ic1"]
        + s["m1"] * s["d1"] ** 2
        + s["Ic2"]
        + s["m2"] * s["d2"] ** 2
        + s["m2"] * s["l1"] ** 2
    )
    expected = [
        a1,
        s["m2"] * s["d2"],
        s["Ic2"] + s["m2"] * s["d2"] ** 2,
        s["m1"] * s["d1"] + s["m2"] * s["l1"],
    ]
    np.testing.assert_allclose(four, expected, rtol=1e-12)
    five = notes_2r_grouping(robot, "notes_2r_heuristic").coefficients(robot)
    np.testing.assert_allclose(
        five,
        [a1, s["m2"] * s["l1"] * s["d2"], expected[2], g0 * expected[3], g0 * s["m2"] * s["d2"]],
        rtol=1e-12,
    )


def test_same_span_as_dynid_base_parameters() -> None:
    """On states of an arm with centres on the link axes, the 4 columns and dynid's base
    columns (whose my1, my2 multiply zero) predict the same torques, and least squares on the
    notes' columns recovers a exactly (p = 4 identifiable coefficients)."""
    robot, _ = _arm(3)
    grouping = notes_2r_grouping(robot)
    q, qd, qdd = _states(3, 400)
    tau = robot.rnea(q, qd, qdd)
    Y = grouping.regressor(q, qd, qdd).reshape(-1, 4)
    a, *_ = np.linalg.lstsq(Y, tau.reshape(-1), rcond=None)
    np.testing.assert_allclose(a, grouping.coefficients(robot), rtol=1e-10)
    assert np.linalg.matrix_rank(Y) == 4
    base = dynid.base_parameters(robot)
    Yb = robot.regressor(q, qd, qdd, columns=base.independent).reshape(-1, base.count)
    assert np.linalg.matrix_rank(np.hstack([Y, Yb])) == base.count  # 6: my1, my2 besides


def test_horizontal_plane_and_refusals() -> None:
    robot, _ = _arm(1, gravity=(0.0, 0.0, -9.81))
    grouping = notes_2r_grouping(robot)
    assert grouping.g0 == 0.0
    q, qd, qdd = _states(1)
    expected = robot.rnea(q, qd, qdd)
    got = grouping.regressor(q, qd, qdd) @ grouping.coefficients(robot)
    assert np.max(np.abs(got - expected)) <= 1e-12 * np.max(np.abs(expected))
    with pytest.raises(ValueError, match="robot: expected a planar 2R"):
        notes_2r_grouping(dynid.models.ur5())
    off = dynid.models.planar_2r()
    off.set_link(1, 1.0, (-0.5, 0.1, 0.0), np.diag([0.06, 0.06, 0.1]))
    with pytest.raises(ValueError, match="centre of mass on its link's axis"):
        notes_2r_grouping(off)
    with pytest.raises(ValueError, match="gravity"):
        notes_2r_grouping(dynid.models.planar_2r(gravity=(9.81, 0.0, 0.0)))
    with pytest.raises(ValueError, match="name: expected one of"):
        notes_2r_grouping(dynid.models.planar_2r(), "other")
