"""Cartesian keep-out of the exciting trajectory (issue 21, item 1; docs/excitation.md,
"Cartesian keep-out"): floor, workspace box, capsules of non-adjacent links.

Independent computations: the frame origins from the standard DH product written here; the
segment distance against a brute-force minimum over both segments; the constraint Jacobian
against central differences; the optimised trajectory against every limit on a grid 100x
denser than the optimiser's samples.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.main import main
from dynid.excitation import FourierTrajectory, load_trajectory, optimize_excitation
from dynid.excitation.cartesian import (
    KeepOut,
    KeepOutConstraint,
    _segment_distance,
    capsule_pairs,
    points,
)

SEED = 1127


@pytest.fixture(scope="module")
def ur5() -> dynid.Robot:
    robot = dynid.models.ur5()
    robot.qlim = np.tile([-2.3, 2.3], (robot.n, 1))  # a UR5 as often limited in a lab
    return robot


def dh_origins(robot, q) -> np.ndarray:
    """Base, DH frames 1..n and tool origins by the standard DH product A_i = Rz Tz Tx Rx."""
    pose, found = np.asarray(robot.base).copy(), [np.asarray(robot.base)[:3, 3]]
    for (a, alpha, d, theta), qi in zip(robot.dh, q):
        ct, st = np.cos(theta + qi), np.sin(theta + qi)
        ca, sa = np.cos(alpha), np.sin(alpha)
        A = np.array(
            [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
             [0, sa, ca, d], [0, 0, 0, 1]]
        )  # fmt: skip
        pose = pose @ A
        found.append(pose[:3, 3])
    found.append((pose @ robot.tool)[:3, 3])
    return np.array(found)


def test_points_are_the_dh_frame_origins_and_the_tool(ur5) -> None:
    assert ur5.convention == "standard"
    q = np.random.default_rng(SEED).uniform(-2, 2, (5, ur5.n))
    for k in range(5):
        np.testing.assert_allclose(points(ur5, q)[k], dh_origins(ur5, q[k]), atol=1e-12)


def test_segment_distance_matches_a_brute_force_minimum() -> None:
    rng = np.random.default_rng(SEED + 1)
    P = rng.normal(size=(40, 4, 3))
    P[::7, 1] = P[::7, 0]  # some segments are points
    P[3, 3] = P[3, 2] + 2.0 * (P[3, 1] - P[3, 0])  # parallel
    distance, s, u, _ = _segment_distance(P, np.array([[0, 2]]))
    grid = np.linspace(0.0, 1.0, 801)
    for k in range(40):
        A = P[k, 0] + np.outer(grid, P[k, 1] - P[k, 0])
        B = P[k, 2] + np.outer(grid, P[k, 3] - P[k, 2])
        brute = np.linalg.norm(A[:, None] - B[None], axis=2).min()
        assert distance[k, 0] <= brute + 1e-12  # a true minimum is never above a sampled one
        assert brute - distance[k, 0] <= 1e-4 * (1 + np.abs(P[k]).max())
        closest = P[k, 0] + s[k, 0] * (P[k, 1] - P[k, 0]) - P[k, 2] - u[k, 0] * (P[k, 3] - P[k, 2])
        np.testing.assert_allclose(np.linalg.norm(closest), distance[k, 0], atol=1e-12)


def test_pairs_leave_out_links_that_touch_by_construction(ur5) -> None:
    radii, pairs = capsule_pairs(ur5, KeepOut(radii=0.05, margin=0.03), np.zeros(ur5.n))
    assert radii.tolist() == [0.05] * 7
    pairs = {tuple(p) for p in pairs.tolist()}
    assert (0, 2) in pairs  # the base column and the forearm: can meet, can be apart
    assert all(j >= i + 2 for i, j in pairs)  # never adjacent
    # the wrist segment 4 and the tool point (UR5: d5, d6 perpendicular about one point) are
    # never farther apart than sqrt(d5^2 + d6^2) = 0.125 < 0.05 + 0.05 + 0.03
    assert (3, 6) not in pairs
    with pytest.raises(ValueError, match="radii: expected one radius or 7"):
        capsule_pairs(ur5, KeepOut(radii=[0.1, 0.2]), np.zeros(ur5.n))


def test_keep_out_jacobian_matches_central_differences(ur5) -> None:
    rng = np.random.default_rng(SEED + 2)
    traj = FourierTrajectory(
        2 * np.pi / 10, 0.3 * rng.normal(size=(6, 3)), 0.3 * rng.normal(size=(6, 3)),
        rng.uniform(-1, 1, 6),
    )  # fmt: skip
    keep_out = KeepOut(floor=0.0, box=(-0.7, 0.7, -0.7, 0.7, -1, 1), radii=0.05, margin=0.03)
    t = np.linspace(0.0, 10.0, 17, endpoint=False)
    constraint = KeepOutConstraint(ur5, keep_out, t, traj.base_frequency, 3, traj.q0)
    x = traj.to_vector()
    J = constraint.jacobian(x)
    h = 1e-6
    for k in range(x.size):
        step = np.zeros(x.size)
        step[k] = h
        difference = (constraint.value(x + step) - constraint.value(x - step)) / (2 * h)
        np.testing.assert_allclose(J[:, k], difference, rtol=0, atol=1e-7)
    # the floor rows are the heights z of frames 1..n and the tool less the margin
    z = np.array([dh_origins(ur5, q)[1:, 2] for q in traj.evaluate(t)[0]])
    rows = constraint.value(x).reshape(17, -1)  # per sample: floor, box faces, capsule pairs
    np.testing.assert_allclose(rows[:, :7], z - 0.03, atol=1e-12)


KEEP_OUT = KeepOut(floor=0.0, box=(-0.7, 0.7, -0.7, 0.7, -1.0, 1.0), radii=0.05, margin=0.03)
SMALL = {"harmonics": 2, "period": 8.0, "samples": 40, "seed": 5, "maxiter": 15}


@pytest.fixture(scope="module")
def kept_out(ur5):
    return optimize_excitation(ur5, **SMALL, at_rest=True, keep_out=KEEP_OUT)


def test_every_limit_and_the_keep_out_hold_on_a_grid_100_times_denser(ur5, kept_out) -> None:
    radii, pairs = capsule_pairs(ur5, KEEP_OUT, kept_out.initial.q0)
    for traj in (kept_out.trajectory, kept_out.initial):
        t = traj.period * np.arange(4000) / 4000
        q, qd, qdd = traj.evaluate(t)
        span = 4.6
        assert np.all(np.abs(q) <= 2.3 - 0.02 * span)
        assert np.abs(qd).max() <= 1.0 and np.abs(qdd).max() <= 2.0
        P = np.array([dh_origins(ur5, qk) for qk in q])  # (T, n + 2, 3), independent
        moving = P[:, 1:]
        assert moving[..., 2].min() >= 0.0
        assert np.all(np.abs(moving[..., :2]) <= 0.7) and np.all(np.abs(moving[..., 2]) <= 1.0)
        distance = _segment_distance(P, pairs)[0]  # checked against brute force above
        assert np.all(distance >= radii[pairs[:, 0]] + radii[pairs[:, 1]])
    assert kept_out.condition_after < kept_out.condition_before


def test_the_keep_out_matters(ur5, kept_out) -> None:
    free = optimize_excitation(ur5, **SMALL, at_rest=True)
    q = free.trajectory.evaluate(np.linspace(0, 8.0, 4001))[0]
    P = np.array([dh_origins(ur5, qk) for qk in q])[:, 1:]
    outside = (P[..., 2] < 0).any() or (np.abs(P[..., :2]) > 0.7).any()
    assert outside  # without it this start leaves the box or goes below the floor


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"floor": [1.0, 2.0]}, "floor"),
        ({"box": (0, 1, 0, 1, 1, 0)}, "box"),
        ({"box": (0, 1)}, "box"),
        ({"radii": -0.1}, "radii"),
        ({"margin": -1.0}, "margin"),
        ({"floor": np.nan}, "floor"),
    ],
)
def test_bad_keep_out_raises_value_error_naming_the_field(kwargs, field) -> None:
    with pytest.raises(ValueError, match=field):
        KeepOut(**kwargs)


def test_a_keep_out_the_arm_cannot_leave_is_an_error(ur5) -> None:
    # frame 1's origin is fixed at z = 0.089: a floor above it holds at no configuration
    with pytest.raises(ValueError, match=r"keep_out: .*floor: frame 1 origin"):
        optimize_excitation(ur5, harmonics=2, samples=30, maxiter=0, keep_out=KeepOut(floor=0.1))
    with pytest.raises(ValueError, match="keep_out"):
        optimize_excitation(ur5, harmonics=2, samples=30, maxiter=0, keep_out="floor")


def test_cli_keep_out_options(tmp_path, capsys) -> None:
    out = tmp_path / "ur5"
    argv = ["excite", "--model", "ur5", "--q-min=-2.3", "--q-max", "2.3", "--harmonics", "2"]
    argv += ["--samples", "40", "--maxiter", "3", "--rate", "100", "--ros-rate", "10"]
    argv += ["--floor", "0", "--box", "-0.7", "0.7"]
    argv += ["-0.7", "0.7", "-1", "1", "--capsule-radius", "0.05", "--output", str(out)]
    assert main(argv) == 0
    plan = load_trajectory(out)
    assert plan.limits["keep_out"] == {
        "floor": 0.0,
        "box": [-0.7, 0.7, -0.7, 0.7, -1.0, 1.0],
        "capsule_radii": [0.05],
        "margin": 0.05,
    }
    q = plan.evaluate(np.linspace(0.0, plan.duration, 4001))[0]
    P = np.array([dh_origins(dynid.models.ur5(), qk) for qk in q])[:, 1:]
    assert P[..., 2].min() >= 0.0 and np.abs(P[..., :2]).max() <= 0.7
    assert (
        main([*argv[:-2], "--box", "0", "1", "0", "1", "1", "0", "--output", str(out / "x")]) == 2
    )
    assert "--box: expected xmin" in capsys.readouterr().err
