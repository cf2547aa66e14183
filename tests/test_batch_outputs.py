"""Batch outputs without waste: the caller's preallocated ``out=`` array, the regressor's
``columns=`` selection in C++, and finiteness checked per sample (an overflow anywhere in a
batch is a ValueError naming the inputs, never inf/NaN in the result).

Exact equality where the same kernel computes both sides (out= and columns= only change where
the numbers are written)."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from conftest import make_arm, random_state
from dynid import _core

CALLS = {  # name: (inputs, per-sample shape for n)
    "rnea": (("q", "qd", "qdd"), lambda n: (n,)),
    "mass_matrix": (("q",), lambda n: (n, n)),
    "gravity": (("q",), lambda n: (n,)),
    "coriolis": (("q", "qd"), lambda n: (n,)),
    "coriolis_matrix": (("q", "qd"), lambda n: (n, n)),
    "friction": (("qd",), lambda n: (n,)),
    "forward_dynamics": (("q", "qd", "tau"), lambda n: (n,)),
    "fkine": (("q",), lambda n: (4, 4)),
    "jacobian": (("q",), lambda n: (6, n)),
    "regressor": (("q", "qd", "qdd"), lambda n: (n, 10 * n)),
    "gravity_regressor": (("q",), lambda n: (n, 10 * n)),
    "inertia_regressor": (("q",), lambda n: (n * (n + 1) // 2, 10 * n)),
}


def setup(count: int | None):
    arm = make_arm("random_modified")
    robot = arm.robot()
    q, qd, qdd = random_state(np.random.default_rng(1), arm, count)
    tau = np.asarray(robot.rnea(q, qd, qdd))
    return robot, {"q": q, "qd": qd, "qdd": qdd, "tau": tau}


@pytest.mark.parametrize("count", [None, 1, 13])
@pytest.mark.parametrize("call", sorted(CALLS))
def test_out_receives_the_result(call: str, count: int | None) -> None:
    names, shape = CALLS[call]
    robot, inputs = setup(count)
    args = [inputs[k] for k in names]
    expected = getattr(robot, call)(*args)
    out = np.full(((count,) if count else ()) + shape(robot.n), np.nan)
    result = getattr(robot, call)(*args, out=out)
    assert result is out
    np.testing.assert_array_equal(out, expected)


BAD_OUT = {
    "float32": (lambda shape: np.zeros(shape, np.float32), "expected dtype float64"),
    "big-endian": (lambda shape: np.zeros(shape, ">f8"), "expected dtype float64"),
    "shape": (lambda shape: np.zeros((*shape[:-1], shape[-1] + 1)), "expected shape"),
    "fortran": (lambda shape: np.asfortranarray(np.zeros((*shape, 2)))[..., 0], "C-contiguous"),
    "read-only": (lambda shape: np.lib.stride_tricks.as_strided(np.zeros(shape)), None),
    "list": (lambda shape: [0.0] * shape[0], "expected a NumPy float64 array"),
}


@pytest.mark.parametrize("case", sorted(BAD_OUT))
@pytest.mark.parametrize("call", ["rnea", "mass_matrix", "gravity", "regressor", "fkine"])
def test_bad_out_is_a_value_error_naming_out(call: str, case: str) -> None:
    names, shape = CALLS[call]
    robot, inputs = setup(5)
    make, message = BAD_OUT[case]
    out = make((5, *shape(robot.n)))
    if case == "read-only":
        out.setflags(write=False)
        message = "writable"
    with pytest.raises(ValueError, match=rf"^out: .*{message}"):
        getattr(robot, call)(*(inputs[k] for k in names), out=out)


@pytest.mark.parametrize(("rotor", "friction"), [(False, False), (True, False), (True, True)])
@pytest.mark.parametrize("count", [None, 9])
def test_regressor_columns_select_in_cpp(rotor: bool, friction: bool, count: int | None) -> None:
    robot, s = setup(count)
    full = robot.regressor(s["q"], s["qd"], s["qdd"], rotor=rotor, friction=friction)
    P = full.shape[-1]
    rng = np.random.default_rng(2)
    for columns in (
        np.arange(P),
        rng.permutation(P)[: P // 2],
        np.array([3, 3, 0]),
        dynid.base_parameters(robot, "torque", rotor, friction).independent,
    ):
        Y = robot.regressor(
            s["q"], s["qd"], s["qdd"], rotor=rotor, friction=friction, columns=columns
        )
        np.testing.assert_array_equal(Y, full[..., columns])
        out = np.empty(Y.shape)
        robot.regressor(
            s["q"],
            s["qd"],
            s["qdd"],
            rotor=rotor,
            friction=friction,
            columns=list(columns),
            out=out,
        )
        np.testing.assert_array_equal(out, Y)


@pytest.mark.parametrize(
    ("columns", "message"),
    [
        ([], "non-empty 1-D"),
        ([[0, 1]], "non-empty 1-D"),
        ([0.0, 1.0], "integer"),
        ([0, 50], r"indices in \[0, 50\), got 50"),
        ([-1], "got -1"),
        ("a", "non-empty 1-D"),
    ],
)
def test_bad_columns_name_columns(columns, message: str) -> None:
    robot, s = setup(3)
    with pytest.raises(ValueError, match=rf"^columns: .*{message}"):
        robot.regressor(s["q"], s["qd"], s["qdd"], columns=columns)


@pytest.mark.parametrize("isa", _core._supported_batch_isas())
@pytest.mark.parametrize("call", ["rnea", "regressor", "coriolis", "mass_matrix"])
def test_overflow_in_any_sample_is_reported(call: str, isa: str) -> None:
    # Sample 10 of 12 overflows (qd ~ 1e200 squares to inf; q has no overflow path, so the
    # mass matrix gets huge link parameters instead); on every batch path and with out=.
    names, shape = CALLS[call]
    robot, s = setup(12)
    s["qd"][10, 1] = 1e200
    if call == "mass_matrix":
        params = np.array(robot.params)
        params[:, 4] = 1e308
        robot.params = params
    before = _core._batch_isa()
    _core._set_batch_isa(isa)
    try:
        out = np.zeros((12, *shape(robot.n)))
        with pytest.raises(ValueError, match="the result overflowed"):
            getattr(robot, call)(*(s[k] for k in names), out=out)
    finally:
        _core._set_batch_isa(before)


# ------------------------------------------------------------- recycled memory of large results


def _address(a: np.ndarray) -> int:
    return int(a.__array_interface__["data"][0])


def test_large_results_recycle_freed_memory_and_never_a_live_result() -> None:
    """A large batch result (>= 4 MiB) reuses the block of a result that was freed, never the
    block of one that is alive; the values equal those written into a caller's ``out=`` (exact:
    the same kernel) and per-sample calls (the scalar kernel, to 1e-12 of the largest entry)."""
    robot = dynid.models.kuka_lwr4()
    rng = np.random.default_rng(7)
    T = 2000  # 2000 x 7 x 70 doubles = 7.8 MB
    first_inputs = [rng.standard_normal((T, 7)) for _ in range(3)]
    second_inputs = [rng.standard_normal((T, 7)) for _ in range(3)]
    first = robot.regressor(*first_inputs)
    kept = first.copy()
    second = robot.regressor(*second_inputs)  # first is alive: its memory must not be reused
    assert not np.shares_memory(first, second)
    np.testing.assert_array_equal(first, kept)
    blocks = _core._result_pool()[0]
    del second
    waiting = _core._result_pool()[0]
    assert waiting == min(blocks + 1, 4)  # second's block waits for reuse (at most 4 wait)
    third = robot.regressor(*second_inputs)
    assert _core._result_pool()[0] == waiting - 1  # third took a pooled block, already mapped
    assert not np.shares_memory(third, first)
    np.testing.assert_array_equal(third, robot.regressor(*second_inputs, out=np.empty_like(kept)))
    for t in (0, 999, T - 1):
        single = robot.regressor(*(x[t] for x in second_inputs))
        np.testing.assert_allclose(third[t], single, rtol=0, atol=1e-12 * np.abs(single).max())


def test_recycled_memory_is_bounded_and_small_results_are_numpys() -> None:
    """At most 4 blocks and 256 MiB wait for reuse; a result larger than that is returned to the
    system when it dies; results under 4 MiB are ordinary NumPy arrays owning their data."""
    robot = dynid.models.kuka_lwr4()
    q = np.random.default_rng(8).standard_normal((12_000, 7))
    results = [robot.mass_matrix(q + k) for k in range(6)]  # 4.7 MB each
    del results
    blocks, size = _core._result_pool()
    assert 1 <= blocks <= 4 and size <= 256 << 20
    pooled = _core._result_pool()
    big = robot.mass_matrix(np.zeros((700_000, 7)))  # 274 MB: more than the pool keeps
    assert not big.flags.owndata
    del big
    assert _core._result_pool() == pooled  # returned to the system, not kept
    small = robot.mass_matrix(q[:100])
    assert small.flags.owndata
