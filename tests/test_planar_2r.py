"""Planar 2R arm against the lecture notes' closed-form model, element by element.

Standard DH rows [l1, 0, 0, 0], [l2, 0, 0, 0]; link i's CoM on its axis at lc_i from
joint i, i.e. at (lc_i - l_i, 0, 0) in frame i (which sits at the distal end); I_i is
the z inertia about the CoM. Gravity (0, -g0, 0) lies in the plane of motion.

Tolerance: |got - expected| <= 1e-12 * max(1, max|expected|) per array (TOL below),
i.e. 1e-12 relative to the size of the quantity (entries are O(1..100)).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import dynid

TOL = 1e-12
L1, L2, LC1, LC2, M1, M2, I1, I2 = 1.0, 0.8, 0.45, 0.35, 3.0, 2.0, 0.25, 0.11
G0 = 9.81


def build_from_dh(gravity: tuple[float, float, float] = (0.0, -G0, 0.0)) -> dynid.Robot:
    """The same arm built here from its DH table (independent of dynid.models)."""
    robot = dynid.Robot.from_dh([[L1, 0, 0, 0], [L2, 0, 0, 0]], joint_types="RR", gravity=gravity)
    # rod-like links: Ixx small, Iyy = Izz = I_i (triangle inequalities hold); only Izz acts
    # in-plane
    robot.set_link(0, M1, [LC1 - L1, 0, 0], np.diag([0.01, I1, I1]))
    robot.set_link(1, M2, [LC2 - L2, 0, 0], np.diag([0.01, I2, I2]))
    return robot


def build_from_models(gravity: tuple[float, float, float] = (0.0, -G0, 0.0)) -> dynid.Robot:
    from dynid.model import models

    return models.planar_2r(
        l1=L1, l2=L2, lc1=LC1, lc2=LC2, m1=M1, m2=M2, I1=I1, I2=I2, gravity=gravity
    )


BUILDERS: dict[str, Callable[..., dynid.Robot]] = {
    "from_dh": build_from_dh,
    "models": build_from_models,
}


@pytest.fixture(params=sorted(BUILDERS))
def build(request: pytest.FixtureRequest) -> Callable[..., dynid.Robot]:
    return BUILDERS[request.param]


def states(count: int = 12) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(7)
    out = [
        (np.zeros(2), np.zeros(2), np.zeros(2)),
        (np.array([0.0, np.pi / 2]), np.ones(2), -np.ones(2)),
    ]
    for _ in range(count):
        out.append((rng.uniform(-np.pi, np.pi, 2), rng.uniform(-3, 3, 2), rng.uniform(-5, 5, 2)))
    return out


def assert_close(got: np.ndarray, expected: np.ndarray, tol: float = TOL) -> None:
    got = np.asarray(got, dtype=float)
    expected = np.asarray(expected, dtype=float)
    assert got.shape == expected.shape
    scale = max(1.0, float(np.max(np.abs(expected), initial=0.0)))
    np.testing.assert_allclose(got, expected, rtol=0, atol=tol * scale)


def closed_form_B(q: np.ndarray) -> np.ndarray:
    c2 = np.cos(q[1])
    b11 = I1 + M1 * LC1**2 + I2 + M2 * (L1**2 + LC2**2 + 2 * L1 * LC2 * c2)
    b12 = I2 + M2 * (LC2**2 + L1 * LC2 * c2)
    b22 = I2 + M2 * LC2**2
    return np.array([[b11, b12], [b12, b22]])


def closed_form_c(q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    h = M2 * L1 * LC2 * np.sin(q[1])
    return np.array([-h * (2 * qd[0] * qd[1] + qd[1] ** 2), h * qd[0] ** 2])


def closed_form_S(q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Christoffel factorization (notes): S = [[-h qd2, -h (qd1 + qd2)], [h qd1, 0]]."""
    h = M2 * L1 * LC2 * np.sin(q[1])
    return np.array([[-h * qd[1], -h * (qd[0] + qd[1])], [h * qd[0], 0.0]])


def closed_form_g(q: np.ndarray, g0: float = G0) -> np.ndarray:
    c1, c12 = np.cos(q[0]), np.cos(q[0] + q[1])
    return np.array([g0 * ((M1 * LC1 + M2 * L1) * c1 + M2 * LC2 * c12), g0 * M2 * LC2 * c12])


@pytest.mark.parametrize("state", states())
def test_mass_matrix_closed_form(build: Callable[..., dynid.Robot], state) -> None:
    q, _, _ = state
    assert_close(build().mass_matrix(q), closed_form_B(q))


@pytest.mark.parametrize("state", states())
def test_coriolis_closed_form(build: Callable[..., dynid.Robot], state) -> None:
    q, qd, _ = state
    robot = build()
    assert_close(robot.coriolis(q, qd), closed_form_c(q, qd))
    assert_close(robot.coriolis_matrix(q, qd), closed_form_S(q, qd))


@pytest.mark.parametrize("state", states())
def test_gravity_closed_form(build: Callable[..., dynid.Robot], state) -> None:
    q, _, _ = state
    assert_close(build().gravity(q), closed_form_g(q))


def test_horizontal_plane_has_no_gravity(build: Callable[..., dynid.Robot]) -> None:
    robot = build(gravity=(0.0, 0.0, -G0))  # gravity normal to the plane of motion
    for q, _, _ in states(4):
        assert_close(robot.gravity(q), np.zeros(2))


@pytest.mark.parametrize("state", states())
def test_rnea_closed_form(build: Callable[..., dynid.Robot], state) -> None:
    q, qd, qdd = state
    expected = closed_form_B(q) @ qdd + closed_form_c(q, qd) + closed_form_g(q)
    assert_close(build().rnea(q, qd, qdd), expected)


@pytest.mark.parametrize("state", states())
def test_energies_closed_form(build: Callable[..., dynid.Robot], state) -> None:
    q, qd, _ = state
    robot = build()
    assert_close(robot.kinetic_energy(q, qd), 0.5 * qd @ closed_form_B(q) @ qd)
    s1, s12 = np.sin(q[0]), np.sin(q[0] + q[1])
    # U = -sum m g^T p_c with g = (0, -g0, 0): U = g0 * sum m y_c
    assert_close(robot.potential_energy(q), G0 * (M1 * LC1 * s1 + M2 * (L1 * s1 + LC2 * s12)))


@pytest.mark.parametrize("state", states())
def test_fkine_closed_form(build: Callable[..., dynid.Robot], state) -> None:
    q, _, _ = state
    c1, s1 = np.cos(q[0]), np.sin(q[0])
    c12, s12 = np.cos(q[0] + q[1]), np.sin(q[0] + q[1])
    expected = np.array(
        [
            [c12, -s12, 0, L1 * c1 + L2 * c12],
            [s12, c12, 0, L1 * s1 + L2 * s12],
            [0, 0, 1, 0],
            [0, 0, 0, 1],
        ]
    )
    assert_close(build().fkine(q), expected)


@pytest.mark.parametrize("state", states())
def test_jacobian_closed_form(build: Callable[..., dynid.Robot], state) -> None:
    q, _, _ = state
    c1, s1 = np.cos(q[0]), np.sin(q[0])
    c12, s12 = np.cos(q[0] + q[1]), np.sin(q[0] + q[1])
    expected = np.array(
        [
            [-L1 * s1 - L2 * s12, -L2 * s12],
            [L1 * c1 + L2 * c12, L2 * c12],
            [0, 0],
            [0, 0],
            [0, 0],
            [1, 1],
        ]
    )
    assert_close(build().jacobian(q), expected)
