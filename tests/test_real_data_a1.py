"""Why the physical fit of the LWR4+ misses 1.25x of the unconstrained one on A1 with the strict
columns (docs/real_data.md, "Estimators on real data"): not the margin, partly the prior, and
at the root a negative inertia. Held-out ratios physical / unconstrained (WLS), guards at rtol
0.05 of the documented values; the freed-drive fit is built here from the C++ regressor
(rotor and friction columns moved to unconstrained extra columns), independent of identify_log.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.identification.log_identification import identify_log, validate_log
from dynid.identification.physical import physical_least_squares
from real_logs import lwr4_logs

PRIOR = Path(__file__).parent.parent / "examples" / "kuka_lwr4_urdf_prior.json"
OPTIONS = {"rotor": True, "friction": True, "offset": True, "method": "wls"}


@pytest.fixture(scope="module")
def setting():
    train, check = lwr4_logs()
    robot = dynid.models.kuka_lwr4()
    free = identify_log(train, robot, **OPTIONS)
    return train, check, robot, free, validate_log(free, check)["relative_rms"]


def ratio(setting, **options):
    train, check, robot, _, unconstrained = setting
    fit = identify_log(train, robot, **OPTIONS, physical=True, **options)
    return validate_log(fit, check)["relative_rms"] / unconstrained


def test_the_margin_plays_no_part_and_the_prior_costs_a1(setting):
    default = ratio(setting, prior=PRIOR)
    np.testing.assert_allclose(default[:6], [1.52, 1.03, 1.17, 1.03, 1.14, 1.18], rtol=0.05)
    weak = ratio(setting, prior=PRIOR, prior_weight=1e-7)
    np.testing.assert_allclose(weak[:6], [1.32, 1.05, 1.05, 1.03, 1.15, 1.18], rtol=0.05)
    assert weak[0] > 1.25  # even a prior that hardly pulls leaves A1 out of the bound


def test_a_negative_rotor_inertia_closes_the_a1_gap(setting):
    """Pseudo-inertia constraints kept, Ia, Fv, Fs unconstrained (extra columns): A1 within
    1.05 of the unconstrained fit, with negative inertias about joints 1-3: the base parameters
    Iyy1R, Iyy2R (which hold Ia1, Ia2; those alone are not identifiable) and Ia3 below
    -1 kg m^2 (documented -3.5, -2.4, -1.6)."""
    train, check, robot, free, unconstrained = setting
    n = robot.n

    def columns(log):
        Y = robot.regressor(log.q, log.qd, log.qdd, rotor=True, friction=True)
        offsets = np.broadcast_to(np.eye(n), (len(log.t), n, n))
        return np.concatenate([Y, offsets], axis=2)

    residual = train.tau - free.predict(train)
    weights = 1 / np.sqrt(np.mean(residual**2, axis=0))
    with pytest.warns(UserWarning, match="rank 69 < 71"):  # Ia1, Ia2 duplicate Iyy1R, Iyy2R
        fit = physical_least_squares(
            robot, columns(train), train.tau, weights=weights, extra_columns=4 * n
        )
    predicted = columns(check) @ fit.theta
    error = np.sqrt(np.mean((predicted - check.tau) ** 2, axis=0) / np.mean(check.tau**2, axis=0))
    assert error[0] / unconstrained[0] < 1.05
    base = dynid.base_parameters(robot, rotor=True, friction=True)
    values = base.beta @ np.concatenate([fit.params.reshape(-1), fit.extra[: 3 * n]])
    for name in ("Iyy1R", "Iyy2R", "Ia3"):
        assert values[base.names.index(name)] < -1.0, name
