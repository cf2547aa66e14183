"""Batch calls, accepted input forms, and input validation (docs/conventions.md "Shapes",
"Bad input").

- A (T, n) batch gives exactly the per-sample results stacked (1e-14 relative).
- Lists, integer arrays, float32, Fortran-ordered and strided arrays give the float64 result.
- Every bad input raises ValueError naming the argument; set_link checks the physics with an
  independent test-side criterion (m > 0, I_c symmetric positive definite, triangle inequalities).
- Hypothesis throws random shapes, dtypes and values (incl. NaN/inf) at the public calls:
  each call returns finite arrays of the documented shape or raises ValueError, nothing else.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis.extra.numpy import array_shapes, arrays

import dynid
import reference_model as ref
from conftest import make_arm, random_inertia_com, random_state

# name -> (argument names, output shape for one sample given n)
CALLS: dict[str, tuple[tuple[str, ...], Callable[[int], tuple[int, ...]]]] = {
    "rnea": (("q", "qd", "qdd"), lambda n: (n,)),
    "mass_matrix": (("q",), lambda n: (n, n)),
    "gravity": (("q",), lambda n: (n,)),
    "coriolis": (("q", "qd"), lambda n: (n,)),
    "coriolis_matrix": (("q", "qd"), lambda n: (n, n)),
    "friction": (("qd",), lambda n: (n,)),
    "forward_dynamics": (("q", "qd", "tau"), lambda n: (n,)),
    "kinetic_energy": (("q", "qd"), lambda n: ()),
    "potential_energy": (("q",), lambda n: ()),
    "fkine": (("q",), lambda n: (4, 4)),
    "jacobian": (("q",), lambda n: (6, n)),
    "regressor": (("q", "qd", "qdd"), lambda n: (n, 10 * n)),
    "gravity_regressor": (("q",), lambda n: (n, 10 * n)),
    "inertia_regressor": (("q",), lambda n: (n * (n + 1) // 2, 10 * n)),
}
# derandomized (same examples every run, no flakiness) and no example database on disk
HYPOTHESIS = settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)


@functools.cache
def arm() -> ref.Arm:
    return make_arm("random_modified")  # 5 joints "RRPRP", friction, rotor inertia, base, tool


def robot() -> dynid.Robot:
    return arm().robot()


def batch_inputs(rng: np.random.Generator, count: int) -> dict[str, np.ndarray]:
    q, qd, qdd = random_state(rng, arm(), count)
    qd[0, 1] = 0.0  # exercise sign(0) = 0
    tau = rng.uniform(-5, 5, q.shape)
    return {"q": q, "qd": qd, "qdd": qdd, "tau": tau}


def name_pattern(name: str) -> str:
    return rf"\b{re.escape(name)}\b"


# ---------------------------------------------------------------- batch == per sample


@pytest.mark.parametrize("call", sorted(CALLS))
def test_batch_equals_per_sample(call: str, rng: np.random.Generator) -> None:
    names, shape = CALLS[call]
    r = robot()
    inputs = batch_inputs(rng, 6)
    batch = np.asarray(getattr(r, call)(*(inputs[k] for k in names)))
    assert batch.shape == (6, *shape(arm().n))
    single = np.array(
        [np.asarray(getattr(r, call)(*(inputs[k][t] for k in names))) for t in range(6)]
    )
    assert single.shape == batch.shape
    np.testing.assert_allclose(
        batch, single, rtol=1e-14, atol=1e-14 * max(1.0, float(np.abs(single).max()))
    )


@pytest.mark.parametrize("call", sorted(CALLS))
def test_lists_ints_float32_and_layouts_accepted(call: str) -> None:
    names, _ = CALLS[call]
    r = robot()
    n = arm().n
    base_int = np.array([[1, -1, 0, 2, -2], [0, 1, 1, -1, 0], [2, 0, -1, 1, 1]])[:, :n]
    inputs = {k: np.roll(base_int, i, axis=1) for i, k in enumerate(("q", "qd", "qdd", "tau"))}
    expected = np.asarray(getattr(r, call)(*(inputs[k].astype(np.float64) for k in names)))
    variants = {
        "int64": lambda a: a.astype(np.int64),
        "int32": lambda a: a.astype(np.int32),
        "float32": lambda a: a.astype(np.float32),  # small integers are exact in float32
        "list": lambda a: a.tolist(),
        "fortran": lambda a: np.asfortranarray(a.astype(np.float64)),
        "strided": lambda a: np.repeat(a.astype(np.float64), 2, axis=1)[:, ::2],
    }
    for label, convert in variants.items():
        got = np.asarray(getattr(r, call)(*(convert(inputs[k]) for k in names)))
        np.testing.assert_allclose(got, expected, rtol=1e-14, atol=1e-14, err_msg=label)
        got_single = np.asarray(getattr(r, call)(*(convert(inputs[k])[0] for k in names)))
        np.testing.assert_allclose(got_single, expected[0], rtol=1e-14, atol=1e-14, err_msg=label)


def test_params_accepts_flat_and_matrix() -> None:
    a = arm()
    r = robot()
    params = a.params  # Steiner done here; the robot got its links through set_link
    np.testing.assert_allclose(r.params, params, rtol=1e-14, atol=1e-15)
    r.params = params.ravel() * 1.5
    np.testing.assert_array_equal(np.asarray(r.params), params * 1.5)
    assert np.asarray(r.params).shape == (a.n, 10)
    r2 = dynid.Robot.from_dh(
        a.dh, joint_types=a.joint_types, convention=a.convention, params=params.ravel()
    )
    np.testing.assert_array_equal(np.asarray(r2.params), params)
    r3 = dynid.Robot.from_dh(a.dh, joint_types=a.joint_types, convention=a.convention)
    np.testing.assert_array_equal(np.asarray(r3.params), np.zeros((a.n, 10)))


def test_set_link_applies_steiner(rng: np.random.Generator) -> None:
    """params row = [m, m c, I_c + m (|c|^2 E - c c^T)] computed here (1e-14)."""
    a = arm()
    r = robot()
    mass, com, inertia = 2.5, np.array([0.1, -0.2, 0.3]), random_inertia_com(rng, 2.5)
    r.set_link(2, mass, com, inertia)
    expected = ref.physical_to_params(mass, com, inertia)
    np.testing.assert_allclose(np.asarray(r.params)[2], expected, rtol=1e-14, atol=1e-15)
    assert a.n == r.n


def test_set_link_tolerates_roundoff_asymmetry(rng: np.random.Generator) -> None:
    """R diag R^T is symmetric only up to roundoff (~1e-18 here); set_link must accept it."""
    rot = ref.rot_z(0.3)[:3, :3] @ ref.rot_x(1.1)[:3, :3]
    inertia = rot @ np.diag([0.02, 0.03, 0.04]) @ rot.T
    r = robot()
    r.set_link(0, 1.0, np.zeros(3), inertia)
    np.testing.assert_allclose(
        np.asarray(r.params)[0, 4:],
        ref.physical_to_params(1.0, np.zeros(3), inertia)[4:],
        atol=1e-15,
    )


def test_is_physically_consistent() -> None:
    a = arm()
    r = robot()
    assert r.is_physically_consistent()
    bad = a.params.copy()
    bad[1, 0] = -1.0  # negative mass: accepted as identified values, but not consistent
    r.params = bad
    assert not r.is_physically_consistent()
    bad = a.params.copy()
    bad[2] = ref.physical_to_params(1.0, np.zeros(3), np.diag([0.1, 0.1, 0.5]))  # 0.1 + 0.1 < 0.5
    r.params = bad
    assert not r.is_physically_consistent()


# ---------------------------------------------------------------- bad input -> ValueError naming it


def bad_dynamics_inputs() -> list[tuple[str, str, str, Callable[[dict], None]]]:
    """(call, argument, what, mutate)."""
    cases = []

    def setter(key: str, value_fn: Callable[[np.ndarray], np.ndarray]) -> Callable[[dict], None]:
        def mutate(inputs: dict) -> None:
            inputs[key] = value_fn(inputs[key])

        return mutate

    def with_value(v: float) -> Callable[[np.ndarray], np.ndarray]:
        def f(a: np.ndarray) -> np.ndarray:
            a = a.copy()
            a.flat[1] = v
            return a

        return f

    for call, (names, _) in CALLS.items():
        for k in names:
            cases += [
                (call, k, "too long", setter(k, lambda a: np.append(a, 0.0))),
                (call, k, "too short", setter(k, lambda a: a[:-1])),
                (call, k, "3-d", setter(k, lambda a: a[None, None, :])),
                (call, k, "0-d", setter(k, lambda a: np.float64(a[0]))),
                (call, k, "nan", setter(k, with_value(math.nan))),
                (call, k, "inf", setter(k, with_value(math.inf))),
                (call, k, "-inf", setter(k, with_value(-math.inf))),
            ]
    return cases


@pytest.mark.parametrize(
    ("call", "arg", "what", "mutate"),
    bad_dynamics_inputs(),
    ids=[f"{c}-{a}-{w}" for c, a, w, _ in bad_dynamics_inputs()],
)
def test_bad_sample_raises_value_error(call: str, arg: str, what: str, mutate) -> None:
    names, _ = CALLS[call]
    inputs = {k: v[0] for k, v in batch_inputs(np.random.default_rng(1), 2).items()}
    mutate(inputs)
    with pytest.raises(ValueError, match=name_pattern(arg)):
        getattr(robot(), call)(*(inputs[k] for k in names))


@pytest.mark.parametrize("call", sorted(c for c, (names, _) in CALLS.items() if len(names) > 1))
def test_mismatched_sample_counts_raise(call: str) -> None:
    names, _ = CALLS[call]
    inputs = batch_inputs(np.random.default_rng(2), 4)
    for k in names[1:]:
        args = {**inputs, k: inputs[k][:3]}
        with pytest.raises(ValueError, match=name_pattern(k)):
            getattr(robot(), call)(*(args[m] for m in names))
    # a batch in a non-first argument with the wrong width is named too
    for k in names:
        args = {**inputs, k: inputs[k][:, :-1]}
        with pytest.raises(ValueError, match=name_pattern(k)):
            getattr(robot(), call)(*(args[m] for m in names))


def from_dh_kwargs() -> dict:
    a = arm()
    return {
        "dh": a.dh.copy(),
        "joint_types": a.joint_types,
        "convention": a.convention,
        "gravity": tuple(a.gravity),
        "params": a.params,
        "base": a.base.copy(),
        "tool": a.tool.copy(),
    }


def nan_at(a: np.ndarray, index: tuple[int, ...]) -> np.ndarray:
    a = np.array(a, dtype=float)
    a[index] = math.nan
    return a


BAD_FROM_DH = {
    "dh 3 columns": ("dh", lambda kw: kw["dh"][:, :3]),
    "dh 5 columns": ("dh", lambda kw: np.column_stack([kw["dh"], np.zeros(len(kw["dh"]))])),
    "dh 1-d": ("dh", lambda kw: kw["dh"][0]),
    "dh 3-d": ("dh", lambda kw: kw["dh"][None]),
    "dh nan": ("dh", lambda kw: nan_at(kw["dh"], (1, 2))),
    "dh inf": ("dh", lambda kw: np.where(np.eye(5, 4, dtype=bool), math.inf, kw["dh"])),
    "joint_types too short": ("joint_types", lambda kw: kw["joint_types"][:-1]),
    "joint_types too long": ("joint_types", lambda kw: kw["joint_types"] + "R"),
    "joint_types letter": ("joint_types", lambda kw: "RXPRP"),
    "joint_types empty": ("joint_types", lambda kw: ""),
    "convention unknown": ("convention", lambda kw: "craig-ish"),
    "convention empty": ("convention", lambda kw: ""),
    "gravity 2": ("gravity", lambda kw: (0.0, -9.81)),
    "gravity 4": ("gravity", lambda kw: (0.0, 0.0, -9.81, 0.0)),
    "gravity nan": ("gravity", lambda kw: (0.0, math.nan, -9.81)),
    "base 3x3": ("base", lambda kw: np.eye(3)),
    "base 4x3": ("base", lambda kw: np.eye(4)[:, :3]),
    "base nan": ("base", lambda kw: nan_at(kw["base"], (0, 3))),
    "tool 3x4": ("tool", lambda kw: np.eye(4)[:3]),
    "tool inf": ("tool", lambda kw: np.where(np.eye(4, dtype=bool), math.inf, kw["tool"])),
    "params n x 9": ("params", lambda kw: kw["params"][:, :9]),
    "params (n-1) x 10": ("params", lambda kw: kw["params"][:-1]),
    "params flat short": ("params", lambda kw: kw["params"].ravel()[:-1]),
    "params 3-d": ("params", lambda kw: kw["params"][None]),
    "params nan": ("params", lambda kw: nan_at(kw["params"], (2, 5))),
}


@pytest.mark.parametrize("case", sorted(BAD_FROM_DH))
def test_bad_from_dh_raises_value_error(case: str) -> None:
    arg, make_bad = BAD_FROM_DH[case]
    kwargs = from_dh_kwargs()
    kwargs[arg] = make_bad(kwargs)
    with pytest.raises(ValueError, match=name_pattern(arg)):
        dynid.Robot.from_dh(**kwargs)


@pytest.mark.parametrize(
    ("attr", "value"),
    [
        ("params", lambda n: np.zeros((n, 9))),
        ("params", lambda n: np.zeros(10 * n + 1)),
        ("params", lambda n: nan_at(np.zeros((n, 10)), (0, 0))),
        ("Ia", lambda n: np.zeros(n + 1)),
        ("Ia", lambda n: nan_at(np.zeros(n), (0,))),
        ("Fv", lambda n: np.zeros(n - 1)),
        ("Fv", lambda n: np.full(n, math.inf)),
        ("Fs", lambda n: np.zeros((n, 2))),
        ("Fs", lambda n: nan_at(np.zeros(n), (1,))),
    ],
)
def test_bad_setter_raises_value_error(attr: str, value: Callable[[int], np.ndarray]) -> None:
    r = robot()
    before = np.array(getattr(r, attr), dtype=float)
    with pytest.raises(ValueError, match=name_pattern(attr)):
        setattr(r, attr, value(r.n))
    np.testing.assert_array_equal(np.asarray(getattr(r, attr), dtype=float), before)


GOOD_LINK = (2.0, np.array([0.1, 0.0, -0.1]), np.diag([0.02, 0.03, 0.04]))
BAD_LINKS = {
    "negative mass": ("mass", (-1.0, GOOD_LINK[1], GOOD_LINK[2])),
    "zero mass": ("mass", (0.0, GOOD_LINK[1], GOOD_LINK[2])),
    "nan mass": ("mass", (math.nan, GOOD_LINK[1], GOOD_LINK[2])),
    "inf mass": ("mass", (math.inf, GOOD_LINK[1], GOOD_LINK[2])),
    "com length 2": ("com", (2.0, np.array([0.1, 0.0]), GOOD_LINK[2])),
    "com 2-d": ("com", (2.0, np.zeros((3, 1)), GOOD_LINK[2])),
    "com nan": ("com", (2.0, np.array([0.1, math.nan, 0.0]), GOOD_LINK[2])),
    "inertia 3": ("inertia_com", (2.0, GOOD_LINK[1], np.array([0.02, 0.03, 0.04]))),
    "inertia 2x2": ("inertia_com", (2.0, GOOD_LINK[1], np.eye(2) * 0.1)),
    "inertia nan": ("inertia_com", (2.0, GOOD_LINK[1], nan_at(GOOD_LINK[2], (1, 1)))),
    "inertia not symmetric": (
        "inertia_com",
        (2.0, GOOD_LINK[1], GOOD_LINK[2] + np.triu(np.full((3, 3), 0.005), 1)),
    ),
    "inertia negative eigenvalue": (
        "inertia_com",
        (2.0, GOOD_LINK[1], np.diag([0.02, 0.03, -0.01])),
    ),
    "inertia singular": ("inertia_com", (2.0, GOOD_LINK[1], np.diag([0.0, 0.03, 0.03]))),
    "triangle inequality": ("inertia_com", (2.0, GOOD_LINK[1], np.diag([0.01, 0.02, 0.05]))),
    "triangle inequality rotated": (
        "inertia_com",
        (
            2.0,
            GOOD_LINK[1],
            ref.rot_x(0.7)[:3, :3] @ np.diag([0.05, 0.01, 0.02]) @ ref.rot_x(0.7)[:3, :3].T,
        ),
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_LINKS))
def test_impossible_set_link_raises_value_error(case: str) -> None:
    arg, link = BAD_LINKS[case]
    r = robot()
    before = np.array(r.params, dtype=float)
    with pytest.raises(ValueError, match=name_pattern(arg)):
        r.set_link(1, *link)
    np.testing.assert_array_equal(np.asarray(r.params), before)  # nothing half-applied
    r.set_link(1, *GOOD_LINK)  # the good link is accepted
    np.testing.assert_allclose(
        np.asarray(r.params)[1], ref.physical_to_params(*GOOD_LINK), rtol=1e-14, atol=1e-16
    )


# ------------------------------------------------------------- hypothesis: nothing but ValueError

FLOAT_DTYPES = (np.float64, np.float32)
INT_DTYPES = (np.int64, np.int32, np.int8, np.uint8)


@st.composite
def numeric_arrays(
    draw: st.DrawFn,
    n: int,
    shape_pool: tuple[tuple[int, ...], ...],
    preferred: tuple[int, ...] | None = None,
) -> object:
    """An array (or nested list) of a random numeric dtype and shape, finite in [-1e3, 1e3]
    except that one entry of a float array is NaN/inf in about a quarter of the draws.
    The shape is `preferred` (if given) or one of `shape_pool` most of the time, else arbitrary."""
    pick = draw(st.integers(0, 9))
    if preferred is not None and pick < 7:
        shape = preferred
    elif pick < 8:
        shape = draw(st.sampled_from(shape_pool))
    else:
        shape = draw(array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=n + 2))
    dtype = draw(st.sampled_from(FLOAT_DTYPES + INT_DTYPES))
    if dtype in FLOAT_DTYPES:
        width = 64 if dtype is np.float64 else 32
        elements = st.floats(-1e3, 1e3, width=width)
    else:
        info = np.iinfo(dtype)
        elements = st.integers(max(int(info.min), -1000), min(int(info.max), 1000))
    value = draw(arrays(dtype, shape, elements=elements))
    if dtype in FLOAT_DTYPES and value.size > 0 and draw(st.integers(0, 4)) == 0:
        value.flat[draw(st.integers(0, value.size - 1))] = draw(
            st.sampled_from([math.nan, math.inf, -math.inf])
        )
    return value.tolist() if draw(st.booleans()) and value.ndim > 0 else value


def check_outcome(
    fn: Callable[[], object], valid: bool | None, shape: tuple[int, ...] | None
) -> None:
    """valid=True: finite result of `shape`; False: ValueError; None: either (finite result or
    ValueError)."""
    try:
        out = fn()
    except ValueError:
        event(f"expected {valid}: ValueError")
        assert valid is not True, "valid input rejected"
        return
    event(f"expected {valid}: result")
    assert valid is not False, "invalid input accepted"
    out = np.asarray(out, dtype=float)
    assert np.all(np.isfinite(out)), "non-finite result"
    if shape is not None:
        assert out.shape == shape


N_HYP = 5  # joints of arm()
SHAPE_POOL = ((N_HYP,), (1, N_HYP), (3, N_HYP), (0, N_HYP))


@pytest.mark.parametrize("call", sorted(CALLS))
@HYPOTHESIS
@given(data=st.data())
def test_hypothesis_dynamics_calls(call: str, data: st.DataObject) -> None:
    names, out_shape = CALLS[call]
    r = robot()
    n = r.n
    assert n == N_HYP
    common = data.draw(st.sampled_from(SHAPE_POOL), label="common shape")
    args = tuple(data.draw(numeric_arrays(n, SHAPE_POOL, common), label=k) for k in names)
    arrays_ = [np.asarray(a, dtype=float) for a in args]
    finite = all(np.all(np.isfinite(a)) for a in arrays_)
    shapes = {a.shape for a in arrays_}
    plausible = all(a.shape == (n,) or (a.ndim == 2 and a.shape[1] == n) for a in arrays_)

    def call_it() -> object:
        return getattr(r, call)(*args)

    if not finite or not plausible:
        check_outcome(call_it, False, None)
    elif shapes == {(n,)}:
        check_outcome(call_it, True, out_shape(n))
    elif len(shapes) == 1:  # one (T, n) batch
        t = arrays_[0].shape[0]
        check_outcome(
            call_it, True if t > 0 else None, (t, *out_shape(n))
        )  # T = 0: empty or ValueError
    else:  # single and batch mixed (not documented): ValueError, or a result if the T agree
        same_t = len({a.shape[0] for a in arrays_ if a.ndim == 2}) == 1
        check_outcome(call_it, None if same_t else False, None)


@pytest.mark.parametrize("call", sorted(CALLS))
@HYPOTHESIS
@given(data=st.data())
def test_hypothesis_huge_finite_values(call: str, data: st.DataObject) -> None:
    # Finite but enormous inputs (up to 1e300) overflow the arithmetic: the call must then raise
    # a ValueError naming its inputs, never return inf or NaN (docs/conventions.md, "Bad input").
    names, out_shape = CALLS[call]
    r = robot()
    n = r.n
    t = data.draw(st.sampled_from([None, 2]), label="batch")
    shape = (n,) if t is None else (t, n)
    huge = st.floats(-1e300, 1e300, allow_nan=False, allow_infinity=False)
    args = [data.draw(arrays(np.float64, shape, elements=huge), label=k) for k in names]
    try:
        out = np.asarray(getattr(r, call)(*args), dtype=float)
    except ValueError as error:  # either outcome is fine; a ValueError must name an argument
        assert any(name in str(error) for name in names), str(error)  # noqa: PT017
        return
    assert np.all(np.isfinite(out)), "non-finite result"
    assert out.shape == (out_shape(n) if t is None else (t, *out_shape(n)))


def link_is_physical(mass: float, com: np.ndarray, inertia: np.ndarray) -> bool | None:
    """Independent criterion; None when within 1e-9 of the boundary (either answer accepted)."""
    if not (np.ndim(mass) == 0 and com.shape == (3,) and inertia.shape == (3, 3)):
        return False
    if not (np.isfinite(mass) and np.all(np.isfinite(com)) and np.all(np.isfinite(inertia))):
        return False
    asym = float(np.abs(inertia - inertia.T).max())
    eig = np.linalg.eigvalsh(0.5 * (inertia + inertia.T))
    margins = [float(mass), float(eig.min()), *(eig.sum() - 2 * eig)]  # I1 + I2 - I3 >= 0 for each
    if asym > 1e-9 or min(margins) < -1e-9:
        return False
    if asym > 0.0 or min(margins) <= 1e-9:
        return None
    return True


DEFECTS = (
    None,
    None,
    None,
    None,
    "mass<=0",
    "mass nonfinite",
    "com",
    "moment<0",
    "asym",
    "nan/inf",
)


@HYPOTHESIS
@given(
    defect=st.sampled_from(DEFECTS),
    mass=st.floats(1e-3, 5),
    bad_mass=st.floats(-1, 0) | st.sampled_from([math.nan, math.inf, -math.inf]),
    com=st.tuples(*[st.floats(-1, 1)] * 3),
    bad_com=numeric_arrays(3, ((3,),), (3,)),
    second_moments=st.tuples(*[st.floats(1e-4, 0.1)] * 3),
    which=st.integers(0, 2),
    angle=st.floats(-np.pi, np.pi),
    poison=st.sampled_from([math.nan, math.inf, -math.inf]),
)
def test_hypothesis_set_link(
    defect, mass, bad_mass, com, bad_com, second_moments, which, angle, poison
) -> None:
    """Random links, physical or with one defect; the verdict comes from link_is_physical."""
    r = robot()
    if defect in ("mass<=0", "mass nonfinite"):
        mass = bad_mass
    com_in = bad_com if defect == "com" else np.array(com)
    moments = list(second_moments)
    if defect == "moment<0":
        moments[which] = -moments[which]
    a, b, c = moments  # principal moments (b + c, a + c, a + b): physical iff a, b, c >= 0
    rot = ref.rot_z(angle)[:3, :3] @ ref.rot_x(0.3)[:3, :3]
    inertia = rot @ np.diag([b + c, a + c, a + b]) @ rot.T
    inertia = 0.5 * (inertia + inertia.T)
    if defect == "asym":
        inertia[which, (which + 1) % 3] += 0.01
    if defect == "nan/inf":
        inertia[which, 2 - which] = poison
    com_arr = np.asarray(com_in, dtype=float)
    valid = link_is_physical(mass, com_arr, inertia)
    before = np.array(r.params, dtype=float)
    event(f"expected {valid}")
    try:
        r.set_link(0, mass, com_in, inertia)
    except ValueError:
        assert valid is not True, "physical link rejected"
        np.testing.assert_array_equal(np.asarray(r.params), before)
        return
    assert valid is not False, "impossible link accepted"
    np.testing.assert_allclose(
        np.asarray(r.params)[0],
        ref.physical_to_params(mass, com_arr, inertia),
        rtol=1e-12,
        atol=1e-15,
    )
    assert r.is_physically_consistent()


@HYPOTHESIS
@given(
    dh=numeric_arrays(4, ((1, 4), (0, 4), (5, 3)), (5, 4)),
    joint_types=st.one_of(
        st.text(alphabet="RP", min_size=5, max_size=5),
        st.text(alphabet="RP", min_size=5, max_size=5),
        st.text(alphabet="RPrpX ", max_size=7),
    ),
    convention=st.sampled_from(["standard", "modified", "Standard", "MODIFIED", "craig", "", "dh"]),
)
def test_hypothesis_from_dh(dh: object, joint_types: str, convention: str) -> None:
    dh_arr = np.asarray(dh, dtype=float)
    n = dh_arr.shape[0] if dh_arr.ndim == 2 else -1
    shape_ok = dh_arr.ndim == 2 and dh_arr.shape[1] == 4 and len(joint_types) == n
    finite = bool(np.all(np.isfinite(dh_arr)))
    valid: bool | None
    if not (shape_ok and finite) or "X" in joint_types or " " in joint_types:
        valid = False
    elif n == 0:
        valid = None  # a chain without joints: not documented either way
    elif convention not in ("standard", "modified"):
        valid = None if convention.lower() in ("standard", "modified") else False
    elif set(joint_types) <= {"R", "P"}:
        valid = True
    else:
        valid = None  # lower-case letters: either accepted or rejected
    event(f"expected {valid}")
    try:
        r = dynid.Robot.from_dh(dh, joint_types=joint_types, convention=convention)
    except ValueError:
        assert valid is not True, "valid DH input rejected"
        return
    assert valid is not False, "invalid DH input accepted"
    assert r.n == n
    if n == 0:
        return
    pose = np.asarray(r.fkine(np.zeros(n)))
    assert pose.shape == (4, 4) and np.all(np.isfinite(pose))


@HYPOTHESIS
@given(value=numeric_arrays(10 * 5, ((5, 10), (50,), (10, 5), (5, 9))))
def test_hypothesis_params_setter(value: object) -> None:
    r = robot()
    before = np.array(r.params, dtype=float)
    arr = np.asarray(value, dtype=float)
    valid = arr.shape in ((5, 10), (50,)) and bool(np.all(np.isfinite(arr)))
    event(f"expected {valid}")
    try:
        r.params = value
    except ValueError:
        assert not valid, "valid params rejected"
        np.testing.assert_array_equal(np.asarray(r.params), before)
        return
    assert valid, "invalid params accepted"
    np.testing.assert_array_equal(np.asarray(r.params), arr.reshape(5, 10))
