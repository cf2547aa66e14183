"""Bounds on the dynamic terms (notes p. 4) against closed forms of a 2R and an RP arm.

The references are the textbook models written out here (notes pp. 22-24 and 10 for the 2R;
the polar RP arm by hand), maximised analytically or, for the Coriolis norm, over the single
direction angle of qd by a dense grid refined with SciPy: independent of dynid.bounds.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize

import dynid
from dynid.model.bounds import dynamic_bounds

G0 = 9.81
L1, L2, LC1, LC2, M1, M2, I1, I2 = 1.0, 0.8, 0.45, 0.35, 3.0, 2.0, 0.25, 0.11


def max_over_directions(matrix_of_direction) -> float:
    """max over unit qd = (cos p, sin p) of the spectral norm of matrix_of_direction(qd)."""

    def f(p: float) -> float:
        return np.linalg.norm(matrix_of_direction(np.array([np.cos(p), np.sin(p)])), 2)

    grid = np.linspace(0.0, 2 * np.pi, 20001)
    best = grid[np.argmax([f(p) for p in grid])]
    res = scipy.optimize.minimize_scalar(
        lambda p: -f(p),
        bounds=(best - 1e-3, best + 1e-3),
        method="bounded",
        options={"xatol": 1e-12},
    )
    return -res.fun


def two_link() -> dynid.Robot:
    return dynid.models.planar_2r(l1=L1, l2=L2, lc1=LC1, lc2=LC2, m1=M1, m2=M2, I1=I1, I2=I2)


def test_planar_2r_matches_the_closed_form():
    # Notes pp. 22-24: M = [[a1 + 2 a2 c2, a3 + a2 c2], [a3 + a2 c2, a3]] with
    # a1 = I1 + m1 lc1^2 + I2 + m2 (l1^2 + lc2^2), a2 = m2 l1 lc2, a3 = I2 + m2 lc2^2. Over
    # c2 in [-1, 1] the trace grows and the determinant a1 a3 - a3^2 - a2^2 c2^2 shrinks with
    # c2 -> 1, so lambda_max is largest and lambda_min = det / lambda_max smallest at q2 = 0.
    # Gravity (p. 10): g = (A cos q1 + B cos(q1 + q2), B cos(q1 + q2)), A = (m1 lc1 + m2 l1) g0,
    # B = m2 lc2 g0: max ||g|| = sqrt((A + B)^2 + B^2) (cosines both 1). Christoffel S =
    # a2 sin q2 [[-q2d, -(q1d + q2d)], [q1d, 0]]: k4 = a2 max_{|qd|=1} ||[[-q2d, -q1d-q2d],
    # [q1d, 0]]||. Tolerances: k0, k1, k6 1e-10 relative (smooth maxima, the optimiser reaches
    # them to ~1e-8 in q, ~1e-16 in value); k4 1e-8 relative (a norm maximised over 4 variables).
    a1 = I1 + M1 * LC1**2 + I2 + M2 * (L1**2 + LC2**2)
    a2, a3 = M2 * L1 * LC2, I2 + M2 * LC2**2
    eig = np.linalg.eigvalsh(np.array([[a1 + 2 * a2, a3 + a2], [a3 + a2, a3]]))
    A, B = (M1 * LC1 + M2 * L1) * G0, M2 * LC2 * G0
    k4 = a2 * max_over_directions(lambda u: np.array([[-u[1], -u[0] - u[1]], [u[0], 0.0]]))

    bounds = dynamic_bounds(two_link(), 2000, seed=3)
    assert bounds.k0.value == pytest.approx(eig[0], rel=1e-10)
    assert bounds.k1.value == pytest.approx(eig[1], rel=1e-10)
    assert bounds.k6.value == pytest.approx(np.hypot(A + B, B), rel=1e-10)
    assert bounds.k4.value == pytest.approx(k4, rel=1e-8)
    assert bounds.as_dict() == {k: getattr(bounds, k).value for k in ("k0", "k1", "k4", "k6")}
    # The sampled values alone are on the right side of the true extremes (estimates from
    # inside: k0 too high, the others too low).
    assert bounds.k0.sampled >= eig[0] and bounds.k1.sampled <= eig[1]
    assert bounds.k6.sampled <= np.hypot(A + B, B) and bounds.k4.sampled <= k4 * (1 + 1e-12)


def test_attaining_points_reproduce_the_values_and_lie_in_the_ranges():
    # The reported q (and unit qd) give back the value through the robot's own terms (1e-12),
    # and lie within qlim.
    robot = dynid.models.kuka_lwr4()
    b = dynamic_bounds(robot, 1000, seed=1)
    for item in (b.k0, b.k1, b.k4, b.k6):
        assert np.all(item.q >= robot.qlim[:, 0]) and np.all(item.q <= robot.qlim[:, 1])
    eig0 = np.linalg.eigvalsh(robot.mass_matrix(b.k0.q))
    eig1 = np.linalg.eigvalsh(robot.mass_matrix(b.k1.q))
    assert b.k0.value == pytest.approx(eig0[0], rel=1e-12)
    assert b.k1.value == pytest.approx(eig1[-1], rel=1e-12)
    assert np.linalg.norm(b.k4.qd) == pytest.approx(1.0, rel=1e-12)
    assert b.k4.value == pytest.approx(
        np.linalg.norm(robot.coriolis_matrix(b.k4.q, b.k4.qd), 2), rel=1e-12
    )
    assert b.k6.value == pytest.approx(np.linalg.norm(robot.gravity(b.k6.q)), rel=1e-12)
    assert b.samples == 1000 and b.starts == 2
    np.testing.assert_array_equal(b.qlim, robot.qlim)


def test_more_samples_never_give_a_worse_estimate():
    # Same seed: the samples and the local-optimisation starts of N samples are a prefix of
    # those of 2N, so k0 never rises and k1, k4, k6 never fall (exact comparisons).
    robot = dynid.models.kuka_lwr4()
    previous = None
    for samples in (500, 1000, 2000):
        for optimize in (False, True):
            b = dynamic_bounds(robot, samples, optimize=optimize, seed=7)
            if optimize:
                assert b.k0.value <= b.k0.sampled and b.k1.value >= b.k1.sampled
                assert b.k4.value >= b.k4.sampled and b.k6.value >= b.k6.sampled
        if previous is not None:
            assert b.k0.value <= previous.k0.value and b.k0.sampled <= previous.k0.sampled
            for name in ("k1", "k4", "k6"):
                now, before = getattr(b, name), getattr(previous, name)
                assert now.value >= before.value and now.sampled >= before.sampled, name
        previous = b


def polar_arm(mass2: float, offset: float, q2_range: tuple[float, float]) -> dynid.Robot:
    """R joint about the base z axis, then a P joint along z1, which lies in the base x-y plane;
    gravity along -y (a vertical plane). Link 2's CoM on the prismatic axis at q2 + offset."""
    robot = dynid.Robot.from_dh(
        [[0, np.pi / 2, 0, 0], [0, 0, 0, 0]],
        "RP",
        gravity=(0.0, -G0, 0.0),
        qlim=[[-np.pi, np.pi], list(q2_range)],
    )
    robot.set_link(0, 1.5, (0, 0, 0), np.diag([0.02, 0.03, 0.04]))
    robot.set_link(1, mass2, (0, 0, offset), np.diag([0.05, 0.06, 0.02]))
    return robot


def test_prismatic_polar_arm_matches_the_closed_form():
    # With r = q2 + offset the distance of link 2's CoM from the joint-1 axis (z0 is the y axis
    # of frames 1 and 2): M = diag(I1yy + I2yy + m2 r^2, m2), M12 = 0 (the prismatic axis meets
    # the joint-1 axis); g = m2 g0 (r sin q1, -cos q1); Christoffel S = m2 r [[q2d, q1d],
    # [-q1d, 0]]. Extremes over r in [r_min, r_max] from qlim: at the range ends. 1e-10 relative
    # (k4 1e-8).
    m2, offset, (low, high) = 2.0, 0.1, (0.2, 1.2)
    robot = polar_arm(m2, offset, (low, high))
    r_min, r_max = low + offset, high + offset
    inertia = 0.03 + 0.06
    k0 = min(inertia + m2 * r_min**2, m2)
    k1 = max(inertia + m2 * r_max**2, m2)
    k6 = m2 * G0 * max(r_max, 1.0)
    k4 = m2 * r_max * max_over_directions(lambda u: np.array([[u[1], u[0]], [-u[0], 0.0]]))
    # The closed form is the model: check it at a few points first (1e-12).
    for q in robot.random_configurations(5, seed=2):
        r = q[1] + offset
        M = np.diag([inertia + m2 * r**2, m2])
        np.testing.assert_allclose(robot.mass_matrix(q), M, rtol=0, atol=1e-12)
        g = m2 * G0 * np.array([r * np.sin(q[0]), -np.cos(q[0])])
        np.testing.assert_allclose(robot.gravity(q), g, rtol=0, atol=1e-12)
    b = dynamic_bounds(robot, 1500, seed=0)
    assert b.k0.value == pytest.approx(k0, rel=1e-10)
    assert b.k1.value == pytest.approx(k1, rel=1e-10)
    assert b.k6.value == pytest.approx(k6, rel=1e-10)
    assert b.k4.value == pytest.approx(k4, rel=1e-8)
    assert b.k1.q[1] == pytest.approx(high, abs=1e-12)  # the range end, not beyond


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"robot": "LWR"}, r"^robot: expected a dynid.Robot"),
        ({"samples": 100}, r"^samples: expected an integer >= 500"),
        ({"samples": 1000.0}, r"^samples: expected an integer"),
        ({"samples": True}, r"^samples: expected an integer"),
        ({"samples_per_start": 0}, r"^samples_per_start: expected an integer >= 1"),
        ({"optimize": 1}, r"^optimize: expected True or False"),
        ({"seed": -1}, r"^seed: expected an integer >= 0"),
        ({"seed": 1.5}, r"^seed: expected an integer"),
    ],
)
def test_bad_arguments_are_value_errors_naming_them(kwargs, match):
    args = {"robot": dynid.models.planar_2r(), "samples": 1000, **kwargs}
    robot = args.pop("robot")
    with pytest.raises(ValueError, match=match):
        dynamic_bounds(robot, **args)


def test_results_compare_by_value():
    # Same arguments, same seed: equal results (arrays compared element by element, no
    # "ambiguous truth value"); another seed differs.
    robot = dynid.models.planar_2r()
    a, b = dynamic_bounds(robot, 500, seed=1), dynamic_bounds(robot, 500, seed=1)
    assert a == b and a.k4 == b.k4
    assert a != dynamic_bounds(robot, 500, seed=2)
