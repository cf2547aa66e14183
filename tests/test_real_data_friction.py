"""Asymmetric friction on the real KUKA LWR4+ logs (docs/real_data.md, "Asymmetric friction").

The setup of tests/test_real_data.py and tests/test_real_data_physical.py (train on
measurements_1, validate on measurements_2, from sample 500; rigid body + rotor, WLS; the
physical fit with the prior examples/kuka_lwr4_urdf_prior.json), with the friction model
"asymmetric" (Fv+, Fv-, Fs+, Fs-; with offsets Fv+, Fv-, Fs). What the section states:

- the unconstrained asymmetric fit lowers the validation error of A6 and A7 (29.8 -> 27.2 %,
  21.7 -> 12.8 %), not of A5, with viscous coefficients < 0 on A5-A7 (a "friction" that feeds
  energy in), which no friction is;
- on these logs every joint moves along one harmonic, so |qd_j| = w sqrt(A_j^2 - (q_j - c_j)^2)
  is a function of q_j: a viscous asymmetry acts as a position torque (close to cos q_j);
- the physically consistent fit (Fv+, Fv-, Fs+, Fs- >= 0) does not lower A5-A7 (at most 3.3 %
  of the error, A6);
- asymmetric friction with and without offsets give the same least-squares prediction (the
  offset is the Coulomb asymmetry on moving samples: dynid.friction_models).

The tables of the section are guarded at rtol 0.05 (as in tests/test_real_data.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.identification.log_identification import identify_log, validate_log
from real_logs import lwr4_logs

PRIOR = Path(__file__).parent.parent / "examples" / "kuka_lwr4_urdf_prior.json"
COMMON = {"rotor": True, "method": "wls"}
N = 7

#: Validation relative RMS per joint, measured (guards, rtol 0.05): the symmetric baselines of
#: tests/test_real_data.py and tests/test_real_data_physical.py, then the asymmetric fits.
SYMMETRIC = np.array([0.1483, 0.0086, 0.0741, 0.0207, 0.2189, 0.2976, 0.2165])
ASYMMETRIC = np.array([0.1492, 0.0086, 0.0742, 0.0205, 0.2225, 0.2721, 0.1276])
ASYMMETRIC_POSITION = np.array([0.1524, 0.0085, 0.0767, 0.0209, 0.2215, 0.2148, 0.0943])
PHYSICAL_SYMMETRIC = np.array([0.2249, 0.0089, 0.0868, 0.0214, 0.2505, 0.3513, 0.8605])
PHYSICAL_ASYMMETRIC = np.array([0.2477, 0.0088, 0.0866, 0.0214, 0.2537, 0.3383, 0.8655])
PHYSICAL_ASYMMETRIC_OFFSET = np.array([0.2257, 0.0089, 0.0879, 0.0213, 0.2516, 0.3397, 0.8549])
PHYSICAL_ASYMMETRIC_POSITION = np.array([0.1789, 0.0089, 0.0775, 0.0208, 0.2639, 0.2876, 0.1610])
GUARD = 0.05
WRIST = slice(4, 7)


@pytest.fixture(scope="module")
def logs():
    return lwr4_logs()


@pytest.fixture(scope="module")
def lwr():
    return dynid.models.kuka_lwr4()


@pytest.fixture(scope="module")
def least_squares(logs, lwr):
    train, _ = logs
    return {
        "symmetric": identify_log(train, lwr, friction=True, offset=True, **COMMON),
        "asymmetric": identify_log(train, lwr, friction="asymmetric", **COMMON),
        "asymmetric+offset": identify_log(train, lwr, friction="asymmetric", offset=True, **COMMON),
        "asymmetric+position": identify_log(
            train, lwr, friction="asymmetric", offset=True, position_torque=True, **COMMON
        ),
    }


def _physical(train, lwr, **options):
    return identify_log(train, lwr, physical=True, prior=PRIOR, **COMMON, **options)


@pytest.fixture(scope="module")
def physical(logs, lwr):
    train, _ = logs
    return {
        "asymmetric": _physical(train, lwr, friction="asymmetric"),
        "asymmetric+offset": _physical(train, lwr, friction="asymmetric", offset=True),
        "asymmetric+position": _physical(
            train, lwr, friction="asymmetric", offset=True, position_torque=True
        ),
    }


def _validation(result, logs):
    return validate_log(result, logs[1])["relative_rms"]


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    a, b = a - a.mean(), b - b.mean()
    return float(a @ b / np.sqrt((a @ a) * (b @ b)))


def test_least_squares_table(least_squares, logs):
    for key, expected in (
        ("symmetric", SYMMETRIC),
        ("asymmetric", ASYMMETRIC),
        ("asymmetric+offset", ASYMMETRIC),
        ("asymmetric+position", ASYMMETRIC_POSITION),
    ):
        np.testing.assert_allclose(
            _validation(least_squares[key], logs), expected, rtol=GUARD, err_msg=key
        )


def test_offsets_add_nothing_to_asymmetric_friction_in_least_squares(least_squares, logs):
    """Same column space (the offset is the Coulomb asymmetry while moving; no sample of these
    logs has qd exactly 0): the two predictions agree to 1e-8 of the largest torque, although
    the coefficients differ (Fs+, Fs- against Fs and off)."""
    check = logs[1]
    without, with_offset = least_squares["asymmetric"], least_squares["asymmetric+offset"]
    assert np.all(check.qd != 0) and np.all(logs[0].qd != 0)
    assert without.rank == with_offset.rank == without.theta.size == with_offset.theta.size
    difference = np.abs(without.predict(check) - with_offset.predict(check)).max()
    assert difference <= 1e-8 * np.abs(check.tau).max()


def test_unconstrained_gain_on_a6_a7_comes_with_negative_viscous_friction(least_squares, logs):
    """A6 and A7 drop (to 0.92 and 0.59 of the symmetric error), A5 does not (>= 1.0); the fit
    has Fv5+, Fv5-, Fv6-, Fv7- < 0. The residuals are correlated (model error), so the standard
    deviations are the correlation-robust ones, with which none of the four is significant
    (within 2.5 of them of 0; the independent-samples ones made them 4-22 below 0)."""
    ratio = _validation(least_squares["asymmetric"], logs) / SYMMETRIC
    assert ratio[4] >= 1.0 and ratio[5] < 0.95 and ratio[6] < 0.65
    result = least_squares["asymmetric"]
    assert any("residuals are correlated in time" in note for note in result.training["notes"])
    values = dict(zip(result.names, result.theta))
    stds = dict(zip(result.names, result.std))
    for name in ("Fv5+", "Fv5-", "Fv6-", "Fv7-"):
        assert -2.5 * stds[name] < values[name] < 0, (name, values[name], stds[name])


def test_on_these_logs_abs_qd_is_a_function_of_q(logs):
    """One harmonic per joint: |qd_j| = w sqrt(A_j^2 - (q_j - c_j)^2) (correlation > 0.999, c_j
    and A_j from the range of q_j), and correlates > 0.95 with cos q_j: the viscous asymmetry
    (Fv+ - Fv-) |qd_j| / 2 is, on these logs, a torque of position."""
    for log in logs:
        for j in range(N):
            q = log.q[:, j]
            centre, amplitude = 0.5 * (q.max() + q.min()), 0.5 * (q.max() - q.min())
            arc = np.sqrt(np.clip(amplitude**2 - (q - centre) ** 2, 0.0, None))
            speed = np.abs(log.qd[:, j])
            assert _correlation(speed, arc) > 0.999
            assert _correlation(speed, np.cos(q)) > 0.95


def test_residual_of_the_symmetric_fit_is_what_the_asymmetric_columns_take(least_squares, logs):
    """A7: the symmetric fit's residual correlates with |qd7| (< -0.6, training and validation);
    the asymmetric fit's validation residual does not (|r| < 0.15). Neither has a Coulomb-like
    residual left on the wrist: |correlation with sign qd_j| < 0.15 on validation."""
    for log in logs:
        residual = least_squares["symmetric"].predict(log) - log.tau
        assert _correlation(residual[:, 6], np.abs(log.qd[:, 6])) < -0.6
    check = logs[1]
    for key in ("symmetric", "asymmetric"):
        residual = least_squares[key].predict(check) - check.tau
        for j in range(4, 7):
            assert abs(_correlation(residual[:, j], np.sign(check.qd[:, j]))) < 0.15
    residual = least_squares["asymmetric"].predict(check) - check.tau
    assert abs(_correlation(residual[:, 6], np.abs(check.qd[:, 6]))) < 0.15


def test_physical_asymmetric_friction_does_not_lower_the_wrist_errors(physical, logs):
    """Fv+, Fv-, Fs+, Fs- >= 0: validation A5-A7 at 0.96-1.01 of the physical symmetric fit
    (> 0.95 asserted); every friction coefficient >= 0."""
    for key, expected in (
        ("asymmetric", PHYSICAL_ASYMMETRIC),
        ("asymmetric+offset", PHYSICAL_ASYMMETRIC_OFFSET),
        ("asymmetric+position", PHYSICAL_ASYMMETRIC_POSITION),
    ):
        got = _validation(physical[key], logs)
        np.testing.assert_allclose(got, expected, rtol=GUARD, err_msg=key)
        result = physical[key]
        friction = [v for name, v in zip(result.names, result.theta) if name.startswith("F")]
        assert len(friction) == (3 if "offset" in key or "position" in key else 4) * N
        assert min(friction) >= 0.0
    ratio = _validation(physical["asymmetric+offset"], logs) / PHYSICAL_SYMMETRIC
    assert np.all(ratio[WRIST] > 0.95)
