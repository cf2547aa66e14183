"""The SIMD batch kernels (samples in vector lanes, one translation unit per instruction set,
chosen at load time) against the scalar reference kernels, on every path this CPU can run.

A batch of T samples on a lane path (rnea, gravity, mass matrix, regressor) must equal T single
calls (which always run the scalar
kernels, themselves tested against Pinocchio and closed forms elsewhere) to 1e-12 relative to
the sample's largest entry (at least 1): the lane kernels do the same arithmetic, in another
order only where FMA contracts it, and compute sin/cos with their own reduction and polynomial.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from conftest import ARM_CASES, make_arm, random_arm, random_state
from dynid import _core

LANE_PATHS = [isa for isa in _core._supported_batch_isas() if isa != "scalar"]
RTOL = 1e-12


@pytest.fixture(params=LANE_PATHS)
def lane_path(request: pytest.FixtureRequest):
    """Forces one batch path for the test and restores the load-time choice afterwards."""
    before = _core._batch_isa()
    _core._set_batch_isa(request.param)
    yield request.param
    _core._set_batch_isa(before)


def per_sample(function, *arrays: np.ndarray) -> np.ndarray:
    """The single-call (scalar kernel) result of every sample, stacked."""
    return np.array([function(*(a[t] for a in arrays)) for t in range(arrays[0].shape[0])])


def assert_same(batch: np.ndarray, reference: np.ndarray) -> None:
    assert batch.shape == reference.shape
    axes = tuple(range(1, reference.ndim))
    scale = np.maximum(1.0, np.abs(reference).max(axis=axes, keepdims=True))
    error = np.abs(batch - reference) / scale
    assert error.max() <= RTOL, f"largest relative difference {error.max():.3g}"


def states(arm, count: int, seed: int, q_scale: float = 1.0):
    q, qd, qdd = random_state(np.random.default_rng(seed), arm, count)
    revolute = np.array([t == "R" for t in arm.joint_types])
    q = np.where(revolute, q * q_scale, q)
    return q, qd, qdd


def test_the_machine_runs_a_lane_path() -> None:
    # Any x86-64 or vector-extension build has at least the 2-lane path, chosen by default.
    assert "sse2" in _core._supported_batch_isas()
    assert _core._supported_batch_isas()[0] == "scalar"


@pytest.mark.parametrize("case", ARM_CASES)
@pytest.mark.parametrize("count", list(range(1, 18)))
def test_lanes_equal_single_calls_for_every_batch_size(
    lane_path: str, case: str, count: int
) -> None:
    # T = 1..17 covers partial vectors of every lane count (2, 4, 8) and several whole ones;
    # the arms cover both conventions, prismatic joints, base, tool, gravity, Ia, Fv, Fs.
    robot = make_arm(case).robot()
    q, qd, qdd = states(make_arm(case), count, seed=count)
    qd[0, 0] = 0.0  # sign(0) = 0 in the Coulomb term
    assert_same(robot.rnea(q, qd, qdd), per_sample(robot.rnea, q, qd, qdd))
    assert_same(robot.gravity(q), per_sample(robot.gravity, q))
    assert_same(robot.mass_matrix(q), per_sample(robot.mass_matrix, q))
    for rotor, friction in ((False, False), (True, False), (False, True), (True, True)):
        assert_same(
            robot.regressor(q, qd, qdd, rotor=rotor, friction=friction),
            per_sample(
                lambda *x, r=rotor, f=friction: robot.regressor(*x, rotor=r, friction=f), q, qd, qdd
            ),
        )
    columns = np.array([5, 0, 3 * robot.n, 10 * robot.n + 2, 10 * robot.n + 2])
    assert_same(
        robot.regressor(q, qd, qdd, rotor=True, friction=True, columns=columns),
        per_sample(
            lambda *x: robot.regressor(*x, rotor=True, friction=True)[:, columns], q, qd, qdd
        ),
    )


@pytest.mark.parametrize("n", [1, 2, 3, 8, 9, 13, 16])
def test_lanes_on_chains_of_every_width(lane_path: str, n: int) -> None:
    # Whole blocks move their rows by groups of 4 (2) columns with in-register transposes, the
    # last group shifted back to overlap the one before; chains narrower than a group keep
    # the lane-by-lane moves. Widths around and across the group size, 8 and 16 samples
    # (whole blocks of every lane count) and 19 (a partial one), against the single calls.
    arm = random_arm(np.random.default_rng(100 + n), n)
    robot = arm.robot()
    for count in (8, 16, 19):
        q, qd, qdd = states(arm, count, seed=n * count)
        assert_same(robot.rnea(q, qd, qdd), per_sample(robot.rnea, q, qd, qdd))
        assert_same(robot.gravity(q), per_sample(robot.gravity, q))
        assert_same(robot.mass_matrix(q), per_sample(robot.mass_matrix, q))
        assert_same(
            robot.regressor(q, qd, qdd, rotor=True, friction=True),
            per_sample(lambda *x: robot.regressor(*x, rotor=True, friction=True), q, qd, qdd),
        )


@pytest.mark.parametrize("q_scale", [1e3, 1e4, 1e5, 3e6])
@pytest.mark.parametrize("case", ARM_CASES)
def test_lanes_large_joint_angles(lane_path: str, case: str, q_scale: float) -> None:
    # The lanes reduce q modulo pi/2 themselves (3e6 takes the libm fallback lanes, mixed in one
    # vector with ordinary ones below).
    arm = make_arm(case)
    robot = arm.robot()
    q, qd, qdd = states(arm, 37, seed=7, q_scale=q_scale)
    q[::3] /= q_scale
    assert_same(robot.rnea(q, qd, qdd), per_sample(robot.rnea, q, qd, qdd))
    assert_same(
        robot.regressor(q, qd, qdd, friction=True),
        per_sample(lambda *x: robot.regressor(*x, friction=True), q, qd, qdd),
    )
    assert_same(robot.gravity(q), per_sample(robot.gravity, q))
    assert_same(robot.mass_matrix(q), per_sample(robot.mass_matrix, q))


def test_lanes_quadrant_boundaries(lane_path: str) -> None:
    # Angles at and next to multiples of pi/4 and pi/2, where the reduction changes quadrant
    # and the polynomials are at the end of their interval.
    arm = make_arm("lwr")
    robot = arm.robot()
    k = np.arange(-40, 41)
    base = np.concatenate(
        [k * np.pi / 4, np.nextafter(k * np.pi / 4, np.inf), k * np.pi / 2 + 1e-9]
    )
    q = np.resize(base, (base.size // 7 * 7,)).reshape(-1, 7)
    assert_same(robot.gravity(q), per_sample(robot.gravity, q))
    assert_same(robot.mass_matrix(q), per_sample(robot.mass_matrix, q))


def test_lanes_threads_split_in_whole_vectors(lane_path: str) -> None:
    arm = make_arm("random_standard")
    robot = arm.robot()
    q, qd, qdd = states(arm, 2 * 512 + 5, seed=3)
    before = dynid.get_threads()
    dynid.set_threads(2)
    try:
        tau = robot.rnea(q, qd, qdd)
        assert _core._last_batch_threads() == 2
    finally:
        dynid.set_threads(before)
    assert_same(tau, per_sample(robot.rnea, q, qd, qdd))


def test_lanes_report_overflow_by_name(lane_path: str) -> None:
    # A velocity that overflows the centripetal terms in one sample (not the first, not in the
    # first vector): ValueError naming the inputs, as on the scalar path, never inf in the result.
    arm = make_arm("lwr")
    robot = arm.robot()
    q, qd, qdd = states(arm, 21, seed=5)
    qd[13, 2] = 1e200
    with pytest.raises(ValueError, match="q, qd, qdd: the result overflowed"):
        robot.rnea(q, qd, qdd)
    with pytest.raises(ValueError, match="q, qd, qdd: the result overflowed"):
        robot.regressor(q, qd, qdd, columns=[0, 61, 65])  # link 7: w^2 overflows
    params = np.array(robot.params)
    params[3:6, 9] = 1e308  # Izz: their sum in the composite inertia overflows
    robot.params = params
    with pytest.raises(ValueError, match="q: the result overflowed"):
        robot.mass_matrix(q)


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_large_inputs_with_nan_or_inf_are_named(value: float) -> None:
    # Inputs of 64 values and more are checked by the SIMD lanes (16 values a step on AVX2, 32
    # on AVX-512, a scalar tail): a bad value anywhere, first, inside the vector steps or in the
    # tail, is a ValueError naming the input and the element; huge finite values are not.
    arm = make_arm("lwr")
    robot = arm.robot()
    q, qd, qdd = states(arm, 101, seed=9)  # 707 values: 44 steps of 16, 22 of 32, and a tail
    q[50, 3] = 1e308  # finite (an angle libm reduces): no error
    assert np.isfinite(robot.rnea(q, qd, qdd)).all()
    for index, name in enumerate(("q", "qd", "qdd")):
        for element in (0, 17, 350, 703, 706):
            bad = [q.copy(), qd.copy(), qdd.copy()]
            bad[index].flat[element] = value
            with pytest.raises(
                ValueError, match=rf"^{name}: contains NaN or inf \(element {element}\)"
            ):
                robot.rnea(*bad)


def test_vectorised_sincos_within_a_few_ulp_of_libm() -> None:
    # The sin/cos of every joint transform (single calls and lanes) against NumPy's (libm,
    # < 1 ulp): 4 ulp of the value (relative, also next to the zeros of sin and cos), for
    # angles of every size up to 1e5 and beyond the reduction's range (libm fallback), at and
    # next to multiples of pi/4, and an odd count (partial vector).
    rng = np.random.default_rng(11)
    k = np.arange(-2000, 2001)
    x = np.concatenate(
        [
            rng.uniform(-np.pi, np.pi, 5001),
            rng.uniform(-1e5, 1e5, 5001) * rng.choice([1e-8, 1e-3, 1.0], 5001),
            k * np.pi / 4,
            np.nextafter(k * np.pi / 4, np.inf),
            np.nextafter(k * np.pi / 2, -np.inf),
            [0.0, -0.0, 1e-300, 5e5, 2e6, -3e7, 1e15],
        ]
    )
    s, c = _core._sincos(x)
    for mine, ref in ((s, np.sin(x)), (c, np.cos(x))):
        ulps = np.abs(mine - ref) / np.spacing(np.abs(ref))
        assert ulps.max() <= 4.0, f"{ulps.max():.1f} ulp at x = {x[np.argmax(ulps)]!r}"


def test_forcing_a_path() -> None:
    before = _core._batch_isa()
    try:
        for isa in _core._supported_batch_isas():
            _core._set_batch_isa(isa)
            assert _core._batch_isa() == isa
        with pytest.raises(ValueError, match="isa: expected 'scalar', 'sse2', 'avx2' or 'avx512'"):
            _core._set_batch_isa("neon")
        for isa in ("avx2", "avx512"):
            if isa not in _core._supported_batch_isas():
                with pytest.raises(ValueError, match="not supported"):
                    _core._set_batch_isa(isa)
    finally:
        _core._set_batch_isa(before)
