"""The real KUKA LWR4+ logs (tests/data/measurements_{1,2}.npz, FloBaRoID; docs/real_data.md).

Identify on measurements_1 with the DH table of dynid.models.kuka_lwr4() (rigid body, rotor,
viscous and Coulomb friction, one torque offset per joint; WLS), skipping the first 500 samples
(the start-up transient, as FloBaRoID's configuration does) and no further filtering (the logs
are already low-passed at 2-3 Hz); validate on measurements_2. The bounds below are met by the
correct pipeline with a margin (its validation errors are at most 0.8 of them) and broken by
each broken one: time-shuffled torques, the table read as modified DH, and the sign of one
joint's q (and qd, qdd) flipped, for each of joints 1-4 (docs/real_data.md explains why flips
of the wrist joints 5-7 cannot be detected with these logs).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.identification.log_identification import identify_log, validate_log
from dynid.logs import Log, load_log
from dynid.model.model_files import load_model

DATA = Path(__file__).parent / "data"
EXAMPLES = Path(__file__).parent.parent / "examples"
SKIP = 500
OPTIONS = {"rotor": True, "friction": True, "offset": True, "method": "wls"}

#: What the correct pipeline scores on measurements_2 (relative RMS error per joint, fraction),
#: and the bounds of the test: about 1.3 times that. EXPECTED is only a regression guard
#: (rtol 0.05 below): the BOUNDS are the test. A tighter pin (it was rtol 2e-3) fails on any
#: legitimate numerical change — another LAPACK, a different but equivalent scaling or
#: factorisation in the least squares, a reordered sum — while a 5 % change of a validation
#: error is already a real change of the fit worth looking at.
EXPECTED = np.array([0.1483, 0.00862, 0.0741, 0.0207, 0.2189, 0.2976, 0.2165])
BOUNDS = np.array([0.19, 0.011, 0.096, 0.027, 0.28, 0.38, 0.28])

#: Joint torque limits of the arm (N m, the URDF's), for FloBaRoID's "NRMS".
TORQUE_LIMITS = np.array([176.0, 176.0, 100.0, 100.0, 100.0, 38.0, 38.0])


@pytest.fixture(scope="module")
def logs() -> tuple[Log, Log]:
    return (
        load_log(DATA / "measurements_1.npz", skip=SKIP),
        load_log(DATA / "measurements_2.npz", skip=SKIP),
    )


@pytest.fixture(scope="module")
def lwr() -> dynid.Robot:
    return dynid.models.kuka_lwr4()


@pytest.fixture(scope="module")
def correct(logs, lwr):
    result = identify_log(logs[0], lwr, **OPTIONS)
    return result, validate_log(result, logs[1])


def worst(relative_rms: np.ndarray) -> float:
    """The largest ratio of a joint's relative RMS error to its bound (> 1: the test fails)."""
    return float(np.max(np.asarray(relative_rms) / BOUNDS))


def test_correct_pipeline_meets_the_bounds_with_margin(correct):
    result, metrics = correct
    assert result.count == 62 and result.rank == 69  # 62 base parameters + 7 offsets
    np.testing.assert_allclose(metrics["relative_rms"], EXPECTED, rtol=0.05)  # guard, see EXPECTED
    assert worst(metrics["relative_rms"]) < 0.8
    assert worst(result.training["metrics"]["relative_rms"]) < 0.8
    # FloBaRoID's "NRMS": the mean over joints of RMS error / (2 x torque limit), in percent;
    # it reports about 0.2 % on this validation log.
    nrms = 100 * np.mean(metrics["rms"] / (2 * TORQUE_LIMITS))
    assert nrms < 0.2


def _flip(log: Log, joint: int) -> Log:
    sign = np.ones(log.n)
    sign[joint] = -1.0
    return log.replace(q=log.q * sign, qd=log.qd * sign, qdd=log.qdd * sign)


@pytest.mark.parametrize(
    "variant",
    [
        "shuffled torques",
        "read as modified DH",
        "q1 flipped",
        "q2 flipped",
        "q3 flipped",
        "q4 flipped",
    ],
)
def test_broken_pipelines_fail_the_bounds(logs, lwr, variant):
    train, check = logs
    robot = lwr
    if variant == "shuffled torques":  # the same permutation of time for every joint
        order = np.random.default_rng(0).permutation(train.T)
        train = train.replace(tau=train.tau[order])
    elif variant == "read as modified DH":
        robot = dynid.Robot.from_dh(lwr.dh, lwr.joint_types, "modified", lwr.gravity_vector)
    else:  # the data's sign convention differs from the model's for one joint
        joint = int(variant[1]) - 1
        train, check = _flip(train, joint), _flip(check, joint)
    result = identify_log(train, robot, **OPTIONS)
    assert worst(validate_log(result, check)["relative_rms"]) > 1.25


def test_the_data_follow_the_dh_table_of_kuka_lwr4(logs, correct):
    """The arm's own tables (base-to-shoulder 0.3105 m on row 1, flange 0.078 m on row 7,
    standard and modified DH) have the same base parameters and give the same fit as the
    paper's table: d1 moves frame 0 along the vertical first axis, d7 frame 7 along the last
    axis, which only re-expresses link 7's parameters."""
    train, check = logs
    paper, metrics = correct
    for name in ("kuka_lwr4plus_dh.json", "kuka_lwr4plus_modified_dh.json"):
        result = identify_log(train, load_model(EXAMPLES / name), **OPTIONS)
        assert (result.count, result.rank) == (paper.count, paper.rank)
        np.testing.assert_allclose(
            result.predict(check), paper.predict(check), rtol=0, atol=1e-8 * np.abs(check.tau).max()
        )
        np.testing.assert_allclose(
            validate_log(result, check)["relative_rms"], metrics["relative_rms"], rtol=1e-7
        )


def test_gravity_model_matches_the_measured_sign_and_zero(logs, lwr):
    """Joints 2-4 carry the gravity load: the measured torque follows g(q) of kuka_lwr4() (made-up
    but plausible masses) with correlation > 0.99, against the data's own q. With that joint's
    sign flipped the correlation is lower than 0.5, and shifting its zero by more than a degree
    worsens the fit tau ~ a g(q) + b."""
    train = logs[0]
    gravity = lwr.gravity(train.q)
    for j in (1, 2, 3):
        assert np.corrcoef(gravity[:, j], train.tau[:, j])[0, 1] > 0.99
        flipped = lwr.gravity(_flip(train, j).q)
        assert np.corrcoef(flipped[:, j], train.tau[:, j])[0, 1] < 0.5
        shifts = np.radians(np.arange(-10.0, 10.5, 0.5))
        errors = []
        for shift in shifts:
            q = train.q.copy()
            q[:, j] += shift
            A = np.column_stack([lwr.gravity(q)[:, j], np.ones(train.T)])
            fit = np.linalg.lstsq(A, train.tau[:, j], rcond=None)[0]
            errors.append(np.sqrt(np.mean((A @ fit - train.tau[:, j]) ** 2)))
        assert abs(np.degrees(shifts[int(np.argmin(errors))])) <= 1.0


def test_reference_tables_of_the_data_file_match_the_examples():
    """examples/kuka_lwr4plus*.json hold the rows of tests/data/kuka_lwr4_dh.json."""
    source = json.loads((DATA / "kuka_lwr4_dh.json").read_text())
    for kind, name in (
        ("standard", "kuka_lwr4plus_dh.json"),
        ("modified", "kuka_lwr4plus_modified_dh.json"),
    ):
        example = json.loads((EXAMPLES / name).read_text())
        assert example["rows"] == source["dh"][kind]["rows"]
        assert example["convention"] == kind
