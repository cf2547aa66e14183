"""The vectorcall fast path of the single-sample calls (cpp/bindings/calls.cpp, generated for
every entry of cpp/bindings/call_table.hpp) against the full pybind11 methods it bypasses (kept
as Model._<name>_full): bit-identical results for the inputs it takes, and for every other input
(keywords, out=, lists, other dtypes, layouts, shapes, NaN, batches) the full method's result or
error, unchanged."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from conftest import make_arm, random_state
from dynid import _core

CALLS = {
    "rnea": ("q", "qd", "qdd"),
    "mass_matrix": ("q",),
    "gravity": ("q",),
    "coriolis": ("q", "qd"),
    "coriolis_matrix": ("q", "qd"),
    "friction": ("qd",),
    "forward_dynamics": ("q", "qd", "tau"),
    "kinetic_energy": ("q", "qd"),
    "potential_energy": ("q",),
    "fkine": ("q",),
    "jacobian": ("q",),
    "regressor": ("q", "qd", "qdd"),
    "gravity_regressor": ("q",),
    "inertia_regressor": ("q",),
    "jacobian_dot": ("q", "qd"),
    "rnea_derivatives": ("q", "qd", "qdd"),
    "rnea_time_derivatives": ("q", "qd", "qdd", "qddd", "qdddd"),
}
ENERGIES = ("kinetic_energy", "potential_energy")
# Tuples of views into one array; no out=.
PARTS = ("rnea_derivatives", "rnea_time_derivatives")
NO_OUT = (*ENERGIES, *PARTS, "jacobian_dot")


def setup():
    arm = make_arm("random_standard")
    q, qd, qdd = random_state(np.random.default_rng(4), arm)
    robot = arm.robot()
    rng = np.random.default_rng(5)
    return robot, {
        "q": q,
        "qd": qd,
        "qdd": qdd,
        "qddd": rng.uniform(-3.0, 3.0, robot.n),
        "qdddd": rng.uniform(-3.0, 3.0, robot.n),
        "tau": robot.rnea(q, qd, qdd),
    }


def test_every_call_of_the_table_has_a_fast_path_and_is_tested() -> None:
    # The table (call_table.hpp) generates Model.<name> and Model._<name>_full for each entry.
    full = {name[1:-5] for name in vars(_core.Model) if name.endswith("_full")}
    assert full == set(CALLS)
    for name in CALLS:
        assert type(vars(_core.Model)[name]).__name__ == "method_descriptor", name


@pytest.mark.parametrize("call", sorted(CALLS))
def test_fast_path_equals_full_method(call: str) -> None:
    robot, s = setup()
    args = [s[k] for k in CALLS[call]]
    fast = getattr(robot, call)(*args)
    full = getattr(_core.Model, f"_{call}_full")(robot, *args)
    if call in ENERGIES:
        assert type(fast) is float and fast == full
        return
    if call in PARTS:
        assert type(fast) is tuple and len(fast) == len(full)
        for part, expected in zip(fast, full):
            np.testing.assert_array_equal(part, expected)
            assert part.base is fast[0].base and part.base.shape == (len(full), *part.shape)
        return
    assert type(fast) is np.ndarray and fast.dtype == np.float64 and fast.flags.c_contiguous
    np.testing.assert_array_equal(fast, full)
    assert fast.flags.writeable and fast.base is None  # a fresh array the caller owns


@pytest.mark.parametrize("call", sorted(CALLS))
def test_other_inputs_take_the_full_path(call: str) -> None:
    robot, s = setup()
    names = CALLS[call]
    args = [s[k] for k in names]
    expected = getattr(robot, call)(*args)
    variants = [
        [list(a) for a in args],  # lists
        [a.astype(np.float32) for a in args],
        [np.asfortranarray(np.stack([a, a], axis=1))[:, 0] for a in args],  # strided views
        [a.astype(">f8") for a in args],  # big-endian
    ]
    full = getattr(_core.Model, f"_{call}_full")
    for variant in variants:
        np.testing.assert_array_equal(getattr(robot, call)(*variant), full(robot, *variant))
    by_keyword = getattr(robot, call)(**dict(zip(names, args)))
    np.testing.assert_array_equal(by_keyword, expected)
    if call not in NO_OUT:
        out = np.empty_like(expected)
        assert getattr(robot, call)(*args, out=out) is out
    batch = getattr(robot, call)(*[np.stack([a, a]) for a in args])
    if call in PARTS:  # each part (2, ...): its second sample
        batch, expected = np.stack([part[1] for part in batch]), np.stack(expected)
    else:
        batch = batch[1]
    np.testing.assert_allclose(batch, expected, rtol=1e-12, atol=1e-12)  # lane kernels


@pytest.mark.parametrize("call", sorted(CALLS))
def test_errors_are_the_full_methods(call: str) -> None:
    robot, s = setup()
    names = CALLS[call]
    bad = [s[k].copy() for k in names]
    bad[-1][2] = np.nan
    with pytest.raises(ValueError, match=rf"^{names[-1]}: contains NaN or inf"):
        getattr(robot, call)(*bad)
    short = [s[k][:-1] for k in names]
    with pytest.raises(ValueError, match=rf"^{names[0]}: expected shape"):
        getattr(robot, call)(*short)
    with pytest.raises(TypeError):
        getattr(robot, call)()
    with pytest.raises(TypeError):
        getattr(_core.Model, call)(object(), *[s[k] for k in names])
    if call == "forward_dynamics":  # M not positive definite: the full method's named error
        params = np.array(robot.params)
        params[:, 0] = -1.0
        robot.params = params
        robot.Ia = np.zeros(robot.n)
        with pytest.raises(ValueError, match=r"^params: "):
            robot.forward_dynamics(s["q"], s["qd"], s["tau"])
    if call == "mass_matrix":  # overflow of the result: named ValueError, not inf
        params = np.array(robot.params)
        params[:, 9] = 1e308
        robot.params = params
        with pytest.raises(ValueError, match="the result overflowed"):
            robot.mass_matrix(s["q"])


def test_fast_path_keeps_no_references() -> None:
    robot, s = setup()
    before = [sys.getrefcount(s[k]) for k in CALLS["rnea"]]
    for _ in range(1000):
        robot.rnea(s["q"], s["qd"], s["qdd"])
        robot.gravity(s["q"])
    assert [sys.getrefcount(s[k]) for k in CALLS["rnea"]] == before
    assert "Joint torques" in (type(robot).rnea.__doc__ or "")


@pytest.mark.parametrize("call", sorted(CALLS))
def test_fast_methods_keep_the_signature_and_docstring(call: str) -> None:
    import inspect

    robot, _ = setup()
    fast, full = getattr(robot, call), getattr(robot, f"_{call}_full")
    assert inspect.signature(fast) == inspect.signature(full)
    # The same text after the typed signature line; that line is written from the table with
    # the arguments' real types (pybind11's own line, on the full method, says `object`), and
    # the stub (tools/generate_stubs.py) is read from it.
    typed, _, text = (fast.__doc__ or "").partition("\n")
    assert text.strip() == (full.__doc__ or "").partition("\n")[2].strip()
    assert typed.startswith(f"{call}(self: dynid._core.Model, ")
    assert ": object" not in typed and "typing.Any" not in typed
    for name in inspect.signature(fast).parameters:
        assert name == "self" or f"{name}: " in typed
