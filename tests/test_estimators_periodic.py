"""method="periodic" (Swevers et al. 1997): whole periods averaged, the noise covariance from
their scatter, weighted least squares on the averages.

Simulated LWR-IV (rotor, friction) along a 3-harmonic trajectory of period 5 s, 4 periods at
100 Hz, its exact torques plus white noise with a known covariance (different levels per joint,
correlated across joints). Checked against independent computations: the true base parameters
(beta @ pi), the injected covariance, a second implementation of the estimate kept here (the
test's own averaging, the C++ regressor reduced to the base columns, numpy's lstsq), the
trajectory's known period.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli import main as dynid_main
from dynid.export.result_files import load_result
from dynid.identification.estimators.period import detect_period, period_starts
from dynid.identification.log_identification import identify_log
from dynid.logs import Log
from test_log_identification import fourier_log

PERIOD = 5.0  # s: fourier_log's base frequency is 0.2 Hz
SEEDS = 24
SIGMA = np.array([0.05, 0.3, 0.1, 0.2, 0.04, 0.03, 0.02])  # N m per joint


def covariance() -> np.ndarray:
    """The injected noise covariance: SIGMA per joint, correlation 0.5 between neighbours."""
    C = np.eye(7) + 0.5 * (np.eye(7, k=1) + np.eye(7, k=-1))
    return C * np.outer(SIGMA, SIGMA)


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    return dynid.models.kuka_lwr4()


@pytest.fixture(scope="module")
def exact(lwr) -> Log:
    return fourier_log(lwr, 1, seconds=4 * PERIOD)


def noisy(log: Log, seed: int) -> Log:
    rng = np.random.default_rng(seed)
    noise = rng.normal(size=log.tau.shape) @ np.linalg.cholesky(covariance()).T
    return Log(t=log.t, q=log.q, qd=log.qd, qdd=log.qdd, tau=log.tau + noise, source=f"s{seed}")


@pytest.fixture(scope="module")
def fits(lwr, exact):
    return [
        identify_log(noisy(exact, seed), lwr, rotor=True, friction=True, method="periodic")
        for seed in range(SEEDS)
    ]


def test_unbiased_and_calibrated_over_seeds(lwr, fits):
    """The z-scores (estimate - truth) / std: RMS in [0.7, 1.3] over 24 seeds (and 62
    parameters), and each parameter's mean error over the seeds within 4.5 of its standard
    error std / sqrt(24) (no bias)."""
    truth = dynid.base_parameters(lwr, rotor=True, friction=True).values(lwr)
    z = np.array([(fit.theta - truth) / fit.std for fit in fits])
    rms = np.sqrt(np.mean(z**2))
    assert 0.7 <= rms <= 1.3, rms
    assert np.abs(z.mean(axis=0) * np.sqrt(SEEDS)).max() < 4.5
    assert all(fit.rank == truth.size and fit.method == "periodic" for fit in fits)


def test_the_noise_covariance_is_the_injected_one(fits):
    """The scatter's variance per joint, averaged over the seeds, equals SIGMA^2 within 4 of its
    sampling error sqrt(2 / (seeds * dof)) (dof = K (M - 1) = 500 * 3); the correlations of
    neighbours 0.5 within 4 / sqrt(seeds * dof)."""
    dof = fits[0].estimator["noise_dof"]
    assert dof == 500 * 3
    std = np.array([fit.estimator["noise_std"] for fit in fits])
    ratio = np.mean(std**2, axis=0) / SIGMA**2
    assert np.abs(ratio - 1).max() < 4 * np.sqrt(2 / (SEEDS * dof)), ratio
    rho = np.mean([np.diag(fit.estimator["noise_correlation"], 1) for fit in fits], axis=0)
    assert np.abs(rho - 0.5).max() < 4 * (1 - 0.25) / np.sqrt(SEEDS * dof), rho


def test_equals_the_weighted_fit_of_the_averaged_periods(lwr, exact):
    """A second implementation: average the 4 periods here, the per-joint variances of the
    scatter, the C++ regressor at the averaged states reduced to the base columns, rows
    weighted by sqrt(M) / sigma_j, numpy's lstsq; estimate to 1e-10, std (diagonal noise: the
    cross-joint terms taken as the estimated correlation) checked separately above."""
    log = noisy(exact, 99)
    fit = identify_log(log, lwr, rotor=True, friction=True, method="periodic")
    M, K = 4, 500
    index = np.arange(M)[:, None] * K + np.arange(K)
    q, qd, qdd, tau = (x[index].mean(axis=0) for x in (log.q, log.qd, log.qdd, log.tau))
    variance = np.sum((log.tau[index] - tau) ** 2, axis=(0, 1)) / (K * (M - 1))
    base = dynid.base_parameters(lwr, rotor=True, friction=True)
    Y = np.array([lwr.regressor(*s, rotor=True, friction=True) for s in zip(q, qd, qdd)])
    w = np.sqrt(M / variance)
    A = (base.reduce(Y) * w[:, None]).reshape(-1, base.count)
    theta, *_ = np.linalg.lstsq(A, (tau * w).reshape(-1), rcond=None)
    np.testing.assert_allclose(fit.theta, theta, rtol=0, atol=1e-10 * np.abs(theta).max())
    np.testing.assert_allclose(np.square(fit.estimator["noise_std"]), variance, rtol=1e-12)
    report = fit.estimator["logs"][0]
    assert report["periods"] == M and report["detected"] and report["samples_used"] == M * K
    assert report["period_s"] == pytest.approx(PERIOD, abs=1e-9)


def test_the_period_is_found_and_given_periods_agree(lwr, exact):
    """The detected period is the trajectory's 5 s; giving it gives the same fit; a period of
    a non-integer number of samples is cut at round(m P) (no drift)."""
    assert detect_period(exact.q) == (500, pytest.approx(1.0, abs=1e-12))
    log = noisy(exact, 3)
    found = identify_log(log, lwr, rotor=True, friction=True, method="periodic")
    given = identify_log(
        log, lwr, rotor=True, friction=True, method="periodic",
        estimator_options={"period": PERIOD},
    )  # fmt: skip
    np.testing.assert_array_equal(found.theta, given.theta)
    assert given.estimator["logs"][0]["detected"] is False
    np.testing.assert_array_equal(period_starts(1000, 333.4), [0, 333, 667])
    t = np.arange(3000)
    q = np.sin(2 * np.pi * t / 123.4)[:, None]
    assert detect_period(q)[0] == 123


def test_physical_fit_uses_the_whole_periods(lwr):
    """The physical fit of method periodic weighs joint j by 1 / sigma_j of the scatter and
    leaves out the samples after the last whole period: on 4.5 periods it equals the one on the
    first 4 periods alone (the extra half period changes it when it is not left out), and it
    stays within a few periodic std of the truth."""
    log = noisy(fourier_log(lwr, 1, seconds=4.5 * PERIOD), 5)
    first = Log(t=log.t[:2000], q=log.q[:2000], qd=log.qd[:2000], qdd=log.qdd[:2000],
                tau=log.tau[:2000])  # fmt: skip
    options = {"rotor": True, "friction": True, "physical": True}
    fit = identify_log(log, lwr, method="periodic", **options)
    alone = identify_log(first, lwr, method="periodic", **options)
    assert fit.estimator["logs"][0]["periods"] == 4 and fit.physical is not None
    scale = np.abs(alone.theta).max()
    np.testing.assert_allclose(fit.theta, alone.theta, rtol=0, atol=1e-6 * scale)
    wls = identify_log(log, lwr, method="wls", **options)
    assert np.abs(wls.theta - alone.theta).max() > 1e-4 * scale
    truth = dynid.base_parameters(lwr, rotor=True, friction=True).values(lwr)
    assert np.sqrt(np.mean(((fit.theta - truth) / fit.std) ** 2)) < 3.0


def test_non_periodic_and_short_logs_are_refused(lwr, exact):
    rng = np.random.default_rng(0)
    t = exact.t
    # a chirp per joint: its frequency grows with time, so q never repeats
    q = 0.5 * np.sin(2 * np.pi * (0.05 + 0.02 * t)[:, None] * t[:, None] * np.arange(1, 8) / 4)
    qd = np.gradient(q, t, axis=0)
    qdd = np.gradient(qd, t, axis=0)
    chirp = Log(t=t, q=q, qd=qd, qdd=qdd, tau=lwr.rnea(q, qd, qdd) + rng.normal(size=q.shape))
    with pytest.raises(ValueError, match=r"period: log 1 is not periodic: the autocorrelation"):
        identify_log(chirp, lwr, rotor=True, friction=True, method="periodic")
    short = noisy(fourier_log(lwr, 1, seconds=1.8 * PERIOD), 0)
    for options in ({"period": PERIOD}, None):  # given, and found (the log repeats once)
        with pytest.raises(ValueError, match=r"holds 1\.80 periods of 5 s; .* at least 2 whole"):
            identify_log(
                short, lwr, rotor=True, friction=True, method="periodic",
                estimator_options=options,
            )  # fmt: skip
    with pytest.raises(ValueError, match=r"period: the torques of joints .* repeat exactly"):
        identify_log(exact, lwr, rotor=True, friction=True, method="periodic")
    with pytest.raises(ValueError, match="period: expected a positive"):
        identify_log(noisy(exact, 0), lwr, method="periodic", estimator_options={"period": -1.0})
    gap = noisy(exact, 0)
    gap = Log(t=np.where(gap.t < 10, gap.t, gap.t + 0.5), q=gap.q, qd=gap.qd, qdd=gap.qdd,
              tau=gap.tau)  # fmt: skip
    with pytest.raises(ValueError, match=r"period: log 1's sample k is up to 2\d steps away"):
        identify_log(gap, lwr, method="periodic")
    with pytest.raises(ValueError, match="min_velocity: method 'periodic'"):
        identify_log(noisy(exact, 0), lwr, method="periodic", preparation={"min_velocity": 0.05})


def test_cli_period_flag(lwr, exact, tmp_path, capsys):
    log = noisy(exact, 1)
    path = tmp_path / "log.npz"
    np.savez(path, t=log.t, q=log.q, qd=log.qd, qdd=log.qdd, tau=log.tau)
    out = tmp_path / "out"
    code = dynid_main(
        ["identify", str(path), "--model", "kuka_lwr4", "--rotor", "--friction",
         "--method", "periodic", "--period", "5", "--output", str(out)]
    )  # fmt: skip
    assert code == 0
    result = load_result(out)
    assert result.estimator["options"] == {"period": 5.0}
    assert result.estimator["logs"][0]["periods"] == 4
    code = dynid_main(["identify", str(path), "--period", "5", "--output", str(tmp_path / "x")])
    assert code == 2 and "--period: not an option of --method wls" in capsys.readouterr().err


def test_the_real_lwr4_logs(lwr):
    """docs/real_data.md, "Estimators on real data": after the 500 skipped samples the LWR4+
    log holds 1.80 periods of its 12.57 s one-harmonic trajectory (refused); from sample 0 with
    the period given, two periods whose first holds the start-up transient: the held-out errors
    documented (guard rtol 0.05) and A2's scatter 2.3 N m, far above its noise."""
    from real_logs import DATA, lwr4_logs

    train, check = lwr4_logs()
    with pytest.raises(ValueError, match=r"holds 1\.80 periods of 12\.56 s"):
        identify_log(train, lwr, rotor=True, friction=True, offset=True, method="periodic")
    whole = dynid.load_log(DATA / "measurements_1.npz")
    fit = identify_log(
        whole, lwr, rotor=True, friction=True, offset=True, method="periodic",
        estimator_options={"period": 4 * np.pi},
    )  # fmt: skip
    documented = [0.185, 0.0301, 0.0857, 0.0290, 0.364, 0.240, 0.201]
    got = dynid.validate_log(fit, check)["relative_rms"]
    np.testing.assert_allclose(got, documented, rtol=0.05)
    assert fit.estimator["logs"][0]["periods"] == 2
    assert fit.estimator["noise_std"][1] == pytest.approx(2.34, rel=0.05)


def test_a_direction_no_period_excites_has_infinite_std():
    """The averaged system's solver (periodic._solve) on a matrix with two equal columns:
    rank p - 1, the minimum-norm estimate (the two share the coefficient equally, as numpy's
    lstsq gives), infinite std on those two and the others' (A^T A)^-1 as the full-rank
    system without the duplicate."""
    from dynid.identification.estimators.periodic import _solve

    rng = np.random.default_rng(2)
    B = rng.normal(size=(200, 3))
    A = np.column_stack([B, B[:, 2]])
    b = B @ [1.0, 2.0, 3.0] + 0.01 * rng.normal(size=200)
    theta, inverse, rank, _, free = _solve(A, b)
    assert rank == 3 and free.tolist() == [False, False, True, True]
    expected, *_ = np.linalg.lstsq(A, b, rcond=None)
    np.testing.assert_allclose(theta, expected, rtol=1e-12)
    # columns 0, 1 are orthogonal to the null direction (0, 0, 1, -1): their block of the
    # pseudo-inverse is that of the system with the duplicate removed
    np.testing.assert_allclose(inverse[:2, :2], np.linalg.inv(B.T @ B)[:2, :2], rtol=1e-10)
