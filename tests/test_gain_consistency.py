"""The block-jackknife check of the drive gains' standard deviations (issue 22, item 5):
overconfident deviations of a model that misses a torque are warned about, honest ones are not.

References: the merged triangular factors against the factor of all rows at once; the jackknife
against least squares on the row subsets by numpy.linalg.lstsq; the drive gains against the
true gains of a simulated UR5 whose friction the model does or does not contain."""

from __future__ import annotations

import warnings

import numpy as np

import dynid
from dynid.identification._qr import GroupedTriangularFactors
from dynid.identification.gain_consistency import RATIO_LIMIT, block_edges, jackknife_std
from dynid.identification.identify import solve_factors
from dynid.logs import Log


def test_merged_factors_are_those_of_all_rows_whatever_their_scales() -> None:
    rng = np.random.default_rng(0)
    n, p = 3, 5
    parts, whole = [], GroupedTriangularFactors(n, p, (0, 1, 2))
    for scale in (0.7, 1e3, 2e-4, 0.0, 37.0):  # exponents 0, 10, -12, none, 6
        A, b = rng.normal(size=(40, n, p)) * scale, rng.normal(size=(40, n)) * scale * 3
        part = GroupedTriangularFactors(n, p, (0, 1, 2))
        part.add(A, b)
        whole.add(A, b)
        parts.append(part)
    merged = GroupedTriangularFactors.merged(parts)
    assert (merged.a_exp, merged.b_exp, merged.samples) == (whole.a_exp, whole.b_exp, 200)
    for j in range(n):  # R^T R = [A b]^T [A b]: independent of the rows' order and R's signs
        Rm, Rw = merged.factors[j], whole.factors[j]
        np.testing.assert_allclose(
            Rm.T @ Rm, Rw.T @ Rw, rtol=1e-12, atol=1e-12 * np.abs(Rw).max() ** 2
        )


def test_the_jackknife_equals_least_squares_on_the_row_subsets() -> None:
    rng = np.random.default_rng(1)
    n, p, T = 2, 3, 240
    A = rng.normal(size=(T, n, p))
    b = A @ np.array([1.0, -2.0, 0.5]) + 0.1 * rng.normal(size=(T, n))
    blocks = []
    for lo, hi in block_edges(T, 6):
        block = GroupedTriangularFactors(n, p, (0, 1))
        block.add(A[lo:hi], b[lo:hi])
        blocks.append(block)

    def refit(part: GroupedTriangularFactors) -> np.ndarray:
        names = ["a", "b", "c"]
        fit = solve_factors(part, method="ols", names=names, on_rank_deficient="raise",
                            rank_tolerance=1e-12, excluded=())  # fmt: skip
        return fit.theta

    spread = jackknife_std(blocks, refit)
    estimates = []
    for lo, hi in block_edges(T, 6):
        keep = np.r_[0:lo, hi:T]
        estimates.append(np.linalg.lstsq(A[keep].reshape(-1, p), b[keep].ravel(), rcond=None)[0])
    x = np.array(estimates)
    expected = np.sqrt(5 / 6 * np.sum((x - x.mean(0)) ** 2, axis=0))
    assert spread is not None
    np.testing.assert_allclose(spread, expected, rtol=1e-9)


def test_block_edges_cover_the_samples_in_order() -> None:
    assert block_edges(10, 3) == [(0, 3), (3, 6), (6, 10)]
    assert block_edges(2, 4) == [(0, 1), (1, 2)]


# A UR5 whose drives have gains K, viscous and Coulomb friction, and optionally a Stribeck peak
# near zero velocity (Coulomb level 6 N m at rest falling to 3 within 0.05 rad/s), which the
# identification model (rotor, Fv, Fs sign(qd)) lacks.
K = np.array([13.0, 13.0, 9.0, 4.0, 4.0, 4.0])
PAYLOAD = {"mass": 4.0, "com": [0.05, 0.02, 0.08], "inertia": np.diag([0.003, 0.003, 0.002])}


def current_run(robot: dynid.Robot, seed: int, stribeck: bool) -> Log:
    rng = np.random.default_rng(seed)
    n, w = robot.n, 2 * np.pi * 0.1
    t = np.arange(0.0, 30.0, 1 / 250)[:, None]
    q, qd, qdd = (np.zeros((t.size, n)) for _ in range(3))
    for k in range(1, 6):
        a, c = rng.normal(scale=0.6 / k, size=(2, n))
        s, co = np.sin(k * w * t), np.cos(k * w * t)
        q += (a * s - c * co) / (k * w)
        qd += a * co + c * s
        qdd += k * w * (c * co - a * s)
    coulomb = 3.0 + (3.0 * np.exp(-((qd / 0.05) ** 2)) if stribeck else 0.0)
    tau = robot.rnea(q, qd, qdd) + 2.0 * qd + coulomb * np.sign(qd)
    current = tau / K
    current += 0.02 * rng.normal(size=current.shape) * np.sqrt(np.mean(current**2, 0))
    return Log(t=t[:, 0], q=q, tau=current, source=f"run {seed}")


def drive_gains(
    stribeck: bool,
) -> tuple[dynid.DriveGainIdentification, list[warnings.WarningMessage]]:
    robot = dynid.models.ur5()
    loaded = robot.with_payload(PAYLOAD["mass"], np.array(PAYLOAD["com"]), PAYLOAD["inertia"])
    unloaded_runs = [current_run(robot, 1, stribeck), current_run(robot, 2, stribeck)]
    loaded_runs = [current_run(loaded, 3, stribeck), current_run(loaded, 4, stribeck)]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = dynid.identify_drive_gains(
            robot, unloaded_runs, loaded_runs, payload=PAYLOAD, rotor=True, friction=True
        )
    return fit, caught


def test_unmodelled_friction_makes_the_gains_overconfident_and_is_warned_about() -> None:
    fit, caught = drive_gains(stribeck=True)
    errors = np.abs(fit.gains - K) / fit.gains_std
    assert errors.max() > 4  # the problem: the errors exceed what the deviations say
    assert any("block jackknife" in str(w.message) for w in caught)
    blocks = np.array(fit.result.drive_gains["gains_std_blocks"])
    assert np.all(np.abs(fit.gains - K) < 3 * blocks)  # the jackknife's deviations cover them
    assert (blocks / fit.gains_std).max() > RATIO_LIMIT


def test_a_model_that_holds_gets_no_warning_and_consistent_deviations() -> None:
    fit, caught = drive_gains(stribeck=False)
    assert not [w for w in caught if "block jackknife" in str(w.message)]
    blocks = np.array(fit.result.drive_gains["gains_std_blocks"])
    ratio = blocks / fit.gains_std
    assert np.all((ratio > 0.2) & (ratio < RATIO_LIMIT))
    assert np.all(np.abs(fit.gains - K) < 4 * fit.gains_std)


def test_one_block_gives_no_jackknife() -> None:
    block = GroupedTriangularFactors(1, 1, (0,))
    block.add(np.ones((3, 1, 1)), np.ones((3, 1)))
    assert jackknife_std([block], lambda f: np.zeros(1)) is None
