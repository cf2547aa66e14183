"""Smooth Stribeck friction on the real KUKA LWR4+ logs (docs/real_data.md, "Smooth Stribeck
friction").

The setup of tests/test_real_data_friction.py (train on measurements_1, validate on
measurements_2, from sample 500; rigid body + rotor + offsets, WLS; the physical fit with the
prior examples/kuka_lwr4_urdf_prior.json), with friction="stribeck". What the section states:

- unconstrained, the Stribeck model lowers the validation error of A5, A6 and A7 below the
  symmetric Coulomb + viscous model's (21.9 -> 18.3, 29.8 -> 26.6, 21.7 -> 10.5 %), with
  coefficients no friction has (negative Coulomb or viscous levels on A3, A5, A7);
- physically consistent (every Stribeck coefficient >= 0, the scales of the unconstrained
  estimate), it lowers A5 by about 6 points (25.0 -> 19.1 %) and leaves A6, A7 within 2 %;
- the velocity scales lie within their bounds [1e-3, 1] rad/s.

The tables are guarded at rtol 0.05 (as in tests/test_real_data.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.identification.log_identification import identify_log, validate_log
from real_logs import lwr4_logs

PRIOR = Path(__file__).parent.parent / "examples" / "kuka_lwr4_urdf_prior.json"
COMMON = {"rotor": True, "offset": True, "method": "wls"}

#: Validation relative RMS per joint, measured (guards, rtol 0.05): the symmetric baselines of
#: tests/test_real_data_friction.py, then the Stribeck fits.
SYMMETRIC = np.array([0.1483, 0.0086, 0.0741, 0.0207, 0.2189, 0.2976, 0.2165])
STRIBECK = np.array([0.1394, 0.0081, 0.0748, 0.0199, 0.1831, 0.2662, 0.1051])
PHYSICAL_SYMMETRIC = np.array([0.2249, 0.0089, 0.0868, 0.0214, 0.2505, 0.3513, 0.8605])
PHYSICAL_STRIBECK = np.array([0.2238, 0.0083, 0.0883, 0.0213, 0.1914, 0.3469, 0.8428])


@pytest.fixture(scope="module")
def logs():
    return lwr4_logs()


@pytest.fixture(scope="module")
def stribeck(logs):
    return identify_log(logs[0], dynid.models.kuka_lwr4(), friction="stribeck", **COMMON)


def test_the_unconstrained_fit_lowers_the_wrist_errors(logs, stribeck):
    metrics = validate_log(stribeck, logs[1])
    np.testing.assert_allclose(metrics["relative_rms"], STRIBECK, rtol=0.05)
    assert np.all(metrics["relative_rms"][4:] < SYMMETRIC[4:])
    block = stribeck.blocks[0]
    scales = np.concatenate([block.vc, block.vs])
    assert block.estimated and np.all((scales >= 1e-3) & (scales <= 1.0))
    where = stribeck.identification_model.slice("stribeck_friction")
    assert stribeck.theta[where].min() < 0  # no friction: the section's caveat


def test_the_physical_fit_lowers_a5(logs, stribeck):
    pytest.importorskip("cvxpy")
    physical = identify_log(
        logs[0], dynid.models.kuka_lwr4(), friction="stribeck", physical=True, prior=PRIOR, **COMMON
    )
    assert physical.blocks == stribeck.blocks  # the scales of the unconstrained estimate
    where = physical.identification_model.slice("stribeck_friction")
    assert physical.theta[where].min() >= -1e-6
    metrics = validate_log(physical, logs[1])
    np.testing.assert_allclose(metrics["relative_rms"], PHYSICAL_STRIBECK, rtol=0.05)
    assert metrics["relative_rms"][4] < 0.8 * PHYSICAL_SYMMETRIC[4]
    assert np.all(metrics["relative_rms"][5:] < 1.02 * PHYSICAL_SYMMETRIC[5:])
