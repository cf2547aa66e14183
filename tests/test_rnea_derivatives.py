"""Analytic RNEA derivatives (docs/uses.md, "Analytic RNEA derivatives", issue 11 item 1) against
two independent computations.

- central finite differences of ``robot.rnea`` (step 1e-6: truncation ~1e-12, round-off ~1e-10
  relative), tolerance 1e-7 relative to the largest entry, on every reference arm (both DH
  conventions, prismatic joints, random base, tool and gravity, rotor inertia and friction);
- Pinocchio's ``computeRNEADerivatives`` on the same arm built as a Pinocchio model
  (bench/pinocchio_arm.py, no dynid code), tolerance 1e-10 relative. Pinocchio has no joint
  friction: dynid's dtau/dqd minus diag(Fv) is compared, which also checks how Fv enters.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pinocchio as pin  # the test extra's "pin"
import pytest

import dynid
from conftest import ARM_CASES, make_arm, random_state

# bench/pinocchio_arm.py: the Pinocchio model of a dynid DH arm, built without dynid's code
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
from pinocchio_arm import build_model

FD_STEP = 1e-6
FD_RTOL = 1e-7
PIN_RTOL = 1e-10


def finite_differences(robot: dynid.Robot, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
    n = robot.n
    dq, dqd = np.empty((n, n)), np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = FD_STEP
        dq[:, k] = (robot.rnea(q + e, qd, qdd) - robot.rnea(q - e, qd, qdd)) / (2 * FD_STEP)
        dqd[:, k] = (robot.rnea(q, qd + e, qdd) - robot.rnea(q, qd - e, qdd)) / (2 * FD_STEP)
    return dq, dqd


def assert_close(actual: np.ndarray, expected: np.ndarray, rtol: float) -> None:
    scale = max(1.0, np.abs(expected).max())
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rtol * scale)


@pytest.mark.parametrize("case", ARM_CASES)
def test_matches_central_finite_differences(case: str, rng: np.random.Generator) -> None:
    arm = make_arm(case)
    robot = arm.robot()
    for _ in range(3):
        q, qd, qdd = random_state(rng, arm)  # qd away from 0: Coulomb friction is flat there
        dq, dqd = robot.rnea_derivatives(q, qd, qdd)
        fd_q, fd_qd = finite_differences(robot, q, qd, qdd)
        assert dq.shape == dqd.shape == (robot.n, robot.n)
        assert_close(dq, fd_q, FD_RTOL)
        assert_close(dqd, fd_qd, FD_RTOL)


@pytest.mark.parametrize("case", ARM_CASES)
def test_matches_pinocchio_compute_rnea_derivatives(case: str, rng: np.random.Generator) -> None:
    arm = make_arm(case)
    robot = arm.robot()
    model = build_model(robot, pin)
    data = model.createData()
    for _ in range(5):
        q, qd, qdd = random_state(rng, arm)
        # the models agree (Pinocchio's rnea has no friction)
        assert_close(
            pin.rnea(model, data, q, qd, qdd), robot.rnea(q, qd, qdd) - robot.friction(qd), PIN_RTOL
        )
        dq_pin, dqd_pin, da_pin = (
            np.array(m) for m in pin.computeRNEADerivatives(model, data, q, qd, qdd)
        )
        dq, dqd = robot.rnea_derivatives(q, qd, qdd)
        assert_close(dq, dq_pin, PIN_RTOL)
        assert_close(dqd - np.diag(robot.Fv), dqd_pin, PIN_RTOL)
        # dtau/dqdd is M (Pinocchio fills the upper triangle)
        assert_close(np.triu(robot.mass_matrix(q)), np.triu(da_pin), PIN_RTOL)


def test_at_rest_dq_is_the_gravity_jacobian_and_dqd_the_viscous_friction() -> None:
    """qd = qdd = 0: dtau/dq = dg/dq (finite differences of robot.gravity, 1e-7 relative) and
    dtau/dqd = diag(Fv) exactly up to round-off (every velocity term is quadratic in qd)."""
    arm = make_arm("random_standard")
    robot = arm.robot()
    q, _, _ = random_state(np.random.default_rng(3), arm)
    zero = np.zeros(robot.n)
    dq, dqd = robot.rnea_derivatives(q, zero, zero)
    fd = np.column_stack(
        [
            (robot.gravity(q + FD_STEP * e) - robot.gravity(q - FD_STEP * e)) / (2 * FD_STEP)
            for e in np.eye(robot.n)
        ]
    )
    assert_close(dq, fd, FD_RTOL)
    np.testing.assert_allclose(dqd, np.diag(robot.Fv), rtol=0, atol=1e-13)


def test_coulomb_friction_and_rotor_inertia_do_not_enter() -> None:
    """Changing Fs and Ia leaves both derivatives unchanged (1e-12 absolute); changing Fv shifts
    dtau/dqd by exactly the diagonal change."""
    arm = make_arm("random_modified")
    robot = arm.robot()
    q, qd, qdd = random_state(np.random.default_rng(4), arm)
    dq, dqd = robot.rnea_derivatives(q, qd, qdd)
    robot.Fs = robot.Fs + 3.0
    robot.Ia = robot.Ia + 2.0
    robot.Fv = robot.Fv + np.arange(robot.n)
    dq2, dqd2 = robot.rnea_derivatives(q, qd, qdd)
    np.testing.assert_allclose(dq2, dq, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        dqd2 - dqd, np.diag(np.arange(robot.n, dtype=float)), rtol=0, atol=1e-12
    )


@pytest.mark.parametrize("threads", [1, 2])
def test_batch_equals_single_samples(threads: int) -> None:
    """(T, n, n) each, sample t bit-identical to the single call, on one or two threads."""
    arm = make_arm("lwr")
    robot = arm.robot()
    q, qd, qdd = random_state(np.random.default_rng(5), arm, count=1100)
    previous = dynid.get_threads()
    dynid.set_threads(threads)
    try:
        dq, dqd = robot.rnea_derivatives(q, qd, qdd)
    finally:
        dynid.set_threads(previous)
    assert dq.shape == dqd.shape == (1100, robot.n, robot.n)
    for t in (0, 549, 550, 1099):
        single_q, single_qd = robot.rnea_derivatives(q[t], qd[t], qdd[t])
        np.testing.assert_array_equal(dq[t], single_q)
        np.testing.assert_array_equal(dqd[t], single_qd)


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (lambda n: (np.zeros(n + 1), np.zeros(n), np.zeros(n)), "q"),
        (lambda n: (np.zeros(n), np.zeros(n - 1), np.zeros(n)), "qd"),
        (lambda n: (np.zeros((3, n)), np.zeros((3, n)), np.zeros((2, n))), "qdd"),
        (lambda n: (np.zeros(n), np.full(n, np.nan), np.zeros(n)), "qd"),
        (lambda n: (np.zeros(n), np.zeros(n), "x"), "qdd"),
    ],
)
def test_bad_input_raises_value_error_naming_argument(args, name: str) -> None:
    robot = make_arm("lwr").robot()
    with pytest.raises(ValueError, match=rf"^{name}:"):
        robot.rnea_derivatives(*args(robot.n))


def test_standard_and_modified_tables_of_the_same_arm_agree() -> None:
    """The KUKA LWR4 of the FloBaRoID URDF in both DH conventions (tests/data/kuka_lwr4_dh.json:
    equivalent tables and parameters, ~16 significant digits): the same derivatives to 1e-9
    relative, at the JSON's sample and at random states."""
    from test_reference_pinocchio import DATA, robot_from_json

    source = "kuka_lwr4.urdf (HEAD)"
    standard = robot_from_json(source, "standard", flat=False)
    modified = robot_from_json(source, "modified", flat=False)
    sample = DATA["check_sample"][source]
    states = [tuple(np.asarray(sample[k], dtype=float) for k in ("q", "qd", "qdd"))]
    states += [random_state(np.random.default_rng(9 + i), "R" * 7) for i in range(3)]
    for q, qd, qdd in states:
        for a, b in zip(
            standard.rnea_derivatives(q, qd, qdd), modified.rnea_derivatives(q, qd, qdd)
        ):
            assert_close(a, b, 1e-9)
