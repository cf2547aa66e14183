"""Property-based fuzzing of the public Python API (issue 22): whatever the arguments, a call
either returns a result with no NaN or inf in it, or raises a ValueError whose message starts
with the name of an argument of the call ("q: ...", "q, qd, qdd: ..."). Never another
exception, never a crash, never a silent NaN.

Non-finite values in a result are accepted only with a warning that says why.

The arguments are drawn around the valid ones: right shapes with values across the whole
float64 range (1e-300 to 1e300, both signs, zeros), NaN and inf among them, wrong shapes and
dimensions, scalars, empty arrays, strings, None, booleans, nested lists, complex and object
arrays. Bounded in time: a fixed number of examples per call, derandomised.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable
from typing import Any

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

import dynid

ROBOT = dynid.models.kuka_lwr4()
N = ROBOT.n
SETTINGS = settings(
    max_examples=150,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

# Magnitudes across float64's range, with the special values.
floats = st.one_of(
    st.floats(-10.0, 10.0),
    st.builds(
        lambda sign, exponent: sign * 10.0**exponent,
        st.sampled_from([-1.0, 1.0]),
        st.integers(-300, 300),
    ),
    st.sampled_from([0.0, -0.0, np.nan, np.inf, -np.inf, 5e-324, 1.7e308]),
)


def arrays(shape: tuple[int, ...]) -> st.SearchStrategy[np.ndarray]:
    size = int(np.prod(shape)) if shape else 1
    return st.lists(floats, min_size=size, max_size=size).map(
        lambda values: np.array(values, dtype=float).reshape(shape)
    )


def argument(shape: tuple[int, ...]) -> st.SearchStrategy[Any]:
    """Mostly the right shape, sometimes anything else a user might pass."""
    wrong_shapes = st.sampled_from(
        [(), (0,), (shape[-1] + 1,) if shape else (2,), (3, 2, 2), (1, *shape), (2, 0)]
    )
    return st.one_of(
        arrays(shape),
        arrays(shape),
        arrays(shape).map(lambda a: np.stack([a, a])),  # a batch of two samples
        wrong_shapes.flatmap(arrays),
        st.sampled_from(
            [None, "q", True, 3, [[1.0, 2.0], [3.0]], np.zeros(shape, dtype=complex)]
            if shape
            else [None, "q", True]
        ),
        st.just(np.array([object()] * max(1, shape[-1] if shape else 1), dtype=object)),
    )


def check(call: Callable[..., Any], names: list[str], *args: Any, **kwargs: Any) -> None:
    """The contract: a finite result (or one whose non-finite values, such as an inf standard
    deviation where the data leave no degree of freedom, come with a warning saying so), or a
    ValueError naming one of ``names`` first."""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = call(*args, **kwargs)
    except ValueError as error:
        message = str(error)
        leading = re.match(r"^([A-Za-z_][\w.\[\]]*(?:, [A-Za-z_][\w.\[\]]*)*):", message)
        assert leading, f"ValueError without a leading argument name: {message!r}"
        named = set(leading.group(1).split(", "))
        assert named & set(names) or any(n.split(".")[0] in names for n in named), (
            f"ValueError names {sorted(named)}, not an argument of {names}: {message!r}"
        )
        return
    for value in _numbers(result):
        assert np.all(np.isfinite(value)) or caught, f"a silent non-finite result: {value!r}"


def _numbers(result: Any) -> list[np.ndarray]:
    if isinstance(result, (tuple, list)):
        return [v for item in result for v in _numbers(item)]
    if isinstance(result, (float, int, np.floating, np.ndarray)):
        return [np.asarray(result, dtype=float)]
    return [np.asarray(getattr(result, field), dtype=float) for field in ("theta", "std")
            if hasattr(result, field)]  # fmt: skip


# ------------------------------------------------------------------------- per-sample dynamics

ONE_VECTOR = ["mass_matrix", "gravity", "fkine", "jacobian", "potential_energy",
              "gravity_regressor", "inertia_regressor", "friction"]  # fmt: skip
TWO_VECTORS = ["coriolis_matrix", "kinetic_energy"]
THREE_VECTORS = ["rnea", "forward_dynamics", "regressor"]


@pytest.mark.parametrize("method", ONE_VECTOR)
@SETTINGS
@given(data=st.data())
def test_calls_of_one_vector(method: str, data: st.DataObject) -> None:
    name = "qd" if method == "friction" else "q"
    check(getattr(ROBOT, method), [name, "out"], data.draw(argument((N,))))


@pytest.mark.parametrize("method", TWO_VECTORS)
@SETTINGS
@given(data=st.data())
def test_calls_of_two_vectors(method: str, data: st.DataObject) -> None:
    q, qd = data.draw(argument((N,))), data.draw(argument((N,)))
    check(getattr(ROBOT, method), ["q", "qd", "out"], q, qd)


@pytest.mark.parametrize("method", THREE_VECTORS)
@SETTINGS
@given(data=st.data())
def test_calls_of_three_vectors(method: str, data: st.DataObject) -> None:
    third = "tau" if method == "forward_dynamics" else "qdd"
    args = [data.draw(argument((N,))) for _ in range(3)]
    check(getattr(ROBOT, method), ["q", "qd", third, "out"], *args)


# ------------------------------------------------------------------------- models and fits


@SETTINGS
@given(data=st.data())
def test_set_link(data: st.DataObject) -> None:
    robot = dynid.models.planar_2r()
    index = data.draw(st.one_of(st.integers(-3, 3), st.sampled_from([None, "1", 1.0, True])))
    check(
        robot.set_link,
        ["i", "mass", "com", "inertia_com"],
        index,
        mass=data.draw(st.one_of(floats, st.sampled_from([None, "1", [1.0]]))),
        com=data.draw(argument((3,))),
        inertia_com=data.draw(argument((3, 3))),
    )
    assert np.all(np.isfinite(robot.params))  # a refused link leaves the robot as it was


@SETTINGS
@given(data=st.data())
def test_from_dh(data: st.DataObject) -> None:
    rows = data.draw(st.integers(1, 3))
    check(
        dynid.Robot.from_dh,
        ["dh", "joint_types", "convention", "gravity"],
        data.draw(argument((rows, 4))),
        joint_types=data.draw(st.sampled_from([None, "R" * rows, "P" * rows, "X", "RR" * rows, 3])),
        convention=data.draw(st.sampled_from(["standard", "modified", "other", None])),
        gravity=data.draw(argument((3,))),
    )


@SETTINGS
@given(data=st.data())
def test_least_squares(data: st.DataObject) -> None:
    T, p = data.draw(st.integers(1, 12)), data.draw(st.integers(1, 4))
    Y = data.draw(st.one_of(argument((T, p)), argument((T, 2, p))))
    tau = data.draw(st.one_of(argument((T,)), argument((T, 2))))
    method = data.draw(st.sampled_from(["ols", "wls", "other"]))
    check(
        dynid.least_squares,
        ["Y", "tau", "method", "on_rank_deficient"],
        Y,
        tau,
        method=method,
        on_rank_deficient="warn",
    )
