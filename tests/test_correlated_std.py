"""Correlation-robust standard deviations of identify_log (docs/identification.md, "Correlated
residuals"): independent noise leaves the least-squares result unchanged; a low-passed log's
residuals are correlated and the standard deviations then reported are calibrated (RMS z-score
over seeds in [0.7, 1.3], against the truth of the simulated arm), where the
independent-samples ones are not; the streaming long-run covariance equals the in-memory one."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.identification.identify import least_squares
from dynid.identification.log_identification import identify_log
from dynid.identification.serial_correlation import LongRunAccumulator, long_run_covariance
from dynid.logs import Log
from test_log_identification import fourier_log


def _arm() -> dynid.Robot:
    robot = dynid.models.planar_2r()
    robot.Fv = [0.3, 0.2]
    return robot


def _noisy(robot: dynid.Robot, seed: int) -> Log:
    log = fourier_log(robot, seed % 3, seconds=20.0, fs=200.0)
    tau = log.tau + np.random.default_rng(seed + 50).normal(scale=0.1, size=log.tau.shape)
    return Log(t=log.t, q=log.q, qd=log.qd, qdd=log.qdd, tau=tau)


def test_independent_noise_keeps_the_least_squares_std() -> None:
    robot = _arm()
    log = _noisy(robot, 0)
    result = identify_log(log, robot, friction=True, method="ols")
    assert not any("correlated" in note for note in result.training["notes"])
    Y = result.regressor(log.q, log.qd, log.qdd)
    reference = least_squares(Y, log.tau, method="ols")  # the same rows, solved on their own
    np.testing.assert_allclose(result.std, reference.std, rtol=1e-10)


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_filtered_logs_get_calibrated_std(method) -> None:
    robot = _arm()
    base = dynid.base_parameters(robot, "torque", friction=True)
    truth = base.beta @ robot.parameter_vector(False, True)
    robust, independent = [], []
    for seed in range(20):
        log = _noisy(robot, seed)
        result = identify_log(
            log, robot, friction=True, method=method, preparation={"cutoff": 10.0}
        )
        assert any("residuals are correlated in time" in n for n in result.training["notes"])
        Y = result.regressor(result.log.q, result.log.qd, result.log.qdd)
        white = least_squares(Y, result.log.tau, method=method)  # independent-samples std
        robust.append((result.theta - truth) / result.std)
        independent.append((white.theta - truth) / white.std)
    assert 0.7 <= np.sqrt(np.mean(np.square(robust))) <= 1.3
    assert np.sqrt(np.mean(np.square(independent))) > 2.0  # what the old std claimed


def test_the_streaming_long_run_covariance_equals_the_whole_one() -> None:
    rng = np.random.default_rng(3)
    segments = [
        np.cumsum(rng.normal(size=(900, 4)), axis=0) * 0.02 + rng.normal(size=(900, 4)),
        rng.normal(size=(411, 4)),
    ]
    for width in (1, 9, 60):
        accumulator = LongRunAccumulator(4, width)
        for segment in segments:
            for start in range(0, len(segment), 101):
                accumulator.add(segment[start : start + 101])
            accumulator.end_segment()
        expected = long_run_covariance(segments, width)
        np.testing.assert_allclose(accumulator.omega, expected, rtol=1e-12, atol=1e-12)
