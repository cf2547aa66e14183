"""Base parameters against independent checks.

- Reproduction on FRESH samples (conftest's seeded states, not the library's): for the robot's
  own pi and for random pi, Y[:, independent] @ (beta @ pi) == Y @ pi.
- The expressions, parsed with Python's ast and evaluated with eval, equal beta @ pi.
- The count equals the rank of a regressor stacked here on fresh samples (SVD with a checked
  gap), and the LWR-IV counts of the issue (the paper's p_g = 12).
- The planar 2R of the lecture (notes pp. 22-24) in modified DH: the lecture's a1..a4, term by
  term and by value against its closed form; structural counts 6 (vertical) and 4 (horizontal).
- The paper's gravity groupings d1 (m3 + ... + m7) and d2 (m5 + m6 + m7) (eqs. (31)-(32)).

Tolerances: reproduction and evaluation 1e-9 relative (max |error| <= 1e-9 * max |expected|,
expected = Y @ pi resp. sum_j |beta_kj pi_j|); an exact beta reproduces to ~1e-13, so the
tolerance only leaves room for rounding beta to about 12 significant digits. Closed-form 2R
values: 1e-12 relative.
"""

from __future__ import annotations

import ast
import dataclasses

import numpy as np
import pytest

import dynid
from conftest import SEED, make_arm, random_pose, random_state
from dynid.model.base_parameters import CACHE_SIZE

RTOL = 1e-9
FRESH_SEED = SEED + 1000  # the library draws its samples from seed 0 with its own sampler
OPTIONS = [  # (kind, rotor, friction)
    ("torque", False, False),
    ("torque", True, False),
    ("torque", False, True),
    ("torque", True, True),
    ("gravity", False, False),
    ("inertia", False, False),
    ("inertia", True, False),
]
CASES = (
    "lwr",
    "puma",
    "random_standard",
    "random_modified",
    "random_prismatic_first",
    "planar_2r_standard",
    "planar_2r_modified",
)

# The lecture's 2R (notes p. 24): lengths l_i, CoM at d_i on the link axis, Ic_i,zz about the CoM.
L1, L2, D1, D2, M1, M2, IC1, IC2 = 0.7, 0.5, 0.3, 0.2, 2.0, 1.5, 0.1, 0.05


def tx(length: float) -> np.ndarray:
    pose = np.eye(4)
    pose[0, 3] = length
    return pose


def planar_2r_modified(gravity=(0.0, -9.81, 0.0)) -> dynid.Robot:
    """Frames at the joints as in the lecture: modified DH, the tool at the tip of link 2."""
    robot = dynid.Robot.from_dh(
        [[0, 0, 0, 0], [L1, 0, 0, 0]], "RR", convention="modified", gravity=gravity, tool=tx(L2)
    )
    robot.set_link(0, M1, (D1, 0, 0), np.diag([0.01 * IC1, IC1, IC1]))
    robot.set_link(1, M2, (D2, 0, 0), np.diag([0.01 * IC2, IC2, IC2]))
    return robot


def planar_2r_standard(gravity=(0.0, -9.81, 0.0)) -> dynid.Robot:
    return dynid.models.planar_2r(
        l1=L1, l2=L2, lc1=D1, lc2=D2, m1=M1, m2=M2, I1=IC1, I2=IC2, gravity=gravity
    )


def build(case: str) -> dynid.Robot:
    if case == "lwr":
        return dynid.models.kuka_lwr4()
    if case == "puma":
        return dynid.models.puma560()
    if case == "planar_2r_standard":
        return planar_2r_standard()
    if case == "planar_2r_modified":
        return planar_2r_modified()
    return make_arm(case).robot()


ROBOTS: dict[str, dynid.Robot] = {}


def robot_of(case: str) -> dynid.Robot:
    """One robot per case for the module (base parameters are cached on it; never mutated)."""
    if case not in ROBOTS:
        ROBOTS[case] = build(case)
    return ROBOTS[case]


def regressor_of(robot: dynid.Robot, kind: str, rotor: bool, friction: bool, samples: int, seed):
    """(samples, rows, P) regressor of ``kind`` on conftest's states (fresh for the library)."""
    q, qd, qdd = random_state(np.random.default_rng(seed), robot.joint_types, samples)
    if kind == "gravity":
        return robot.gravity_regressor(q)
    if kind == "inertia":
        return robot.inertia_regressor(q, rotor=rotor)
    return robot.regressor(q, qd, qdd, rotor=rotor, friction=friction)


def linear_terms(expression: str) -> dict[str, float]:
    """{name: coefficient} of a sum of ``[c*]name`` terms, parsed with ast (nothing else
    allowed)."""
    terms: dict[str, float] = {}

    def walk(node: ast.expr, sign: float) -> None:
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub)):
            walk(node.left, sign)
            walk(node.right, sign if isinstance(node.op, ast.Add) else -sign)
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            walk(node.operand, -sign)
        elif isinstance(node, ast.Name):
            assert node.id not in terms, f"{node.id} twice in {expression!r}"
            terms[node.id] = sign
        elif (
            isinstance(node, ast.BinOp)
            and isinstance(node.op, ast.Mult)
            and isinstance(node.right, ast.Name)
        ):
            # "c*name"; a leading "-c*name" parses as (-c)*name
            left, factor = node.left, sign
            if isinstance(left, ast.UnaryOp) and isinstance(left.op, ast.USub):
                left, factor = left.operand, -sign
            if not (isinstance(left, ast.Constant) and isinstance(left.value, (int, float))):
                pytest.fail(f"not a numeric factor in {expression!r}")
            assert node.right.id not in terms, f"{node.right.id} twice in {expression!r}"
            terms[node.right.id] = factor * float(left.value)
        else:
            pytest.fail(f"not a linear sum of parameters: {expression!r}")

    walk(ast.parse(expression, mode="eval").body, 1.0)
    return terms


def evaluate(expression: str, names: list[str], pi: np.ndarray) -> float:
    return float(eval(expression, {"__builtins__": {}}, dict(zip(names, pi.tolist()))))


def numerical_rank(W: np.ndarray) -> int:
    """Rank from the SVD of the column-normalised matrix, asserting a clear gap (1e-12 .. 1e-6)."""
    norms = np.linalg.norm(W, axis=0)
    scale = norms.max()
    W = W[:, norms > 1e-12 * scale] / norms[norms > 1e-12 * scale]
    s = np.linalg.svd(W, compute_uv=False)
    s = s / s[0]
    in_gap = np.flatnonzero((s > 1e-12) & (s < 1e-6))
    assert in_gap.size == 0, f"no clear numerical rank: singular values {s[in_gap]}"
    return int(np.count_nonzero(s >= 1e-6))


# ---- reproduction, expressions, structure -------------------------------------------------------


@pytest.mark.parametrize(("kind", "rotor", "friction"), OPTIONS)
@pytest.mark.parametrize("case", CASES)
def test_reduced_regressor_reproduces_on_fresh_samples(case, kind, rotor, friction) -> None:
    robot = robot_of(case)
    base = dynid.base_parameters(robot, kind=kind, rotor=rotor, friction=friction)
    Y = regressor_of(robot, kind, rotor, friction, 6, FRESH_SEED)
    P = Y.shape[-1]
    assert base.beta.shape == (base.count, P)
    reduced = base.reduce(Y)
    np.testing.assert_array_equal(reduced, Y[..., base.independent])

    rng = np.random.default_rng(FRESH_SEED + 1)
    pis = [robot.parameter_vector(rotor=rotor, friction=friction), *rng.normal(size=(3, P))]
    for which, pi in enumerate(pis):
        expected = Y @ pi
        got = reduced @ (base.beta @ pi)
        scale = np.max(np.abs(expected))
        error = np.max(np.abs(got - expected))
        assert scale > 0
        assert error <= RTOL * scale, (
            f"{case} {kind} rotor={rotor} friction={friction} pi #{which}: "
            f"max error {error:.3e} > {RTOL:.0e} * {scale:.3e}"
        )
    np.testing.assert_allclose(base.values(robot), base.beta @ pis[0], rtol=0, atol=0)


@pytest.mark.parametrize(("kind", "rotor", "friction"), OPTIONS)
@pytest.mark.parametrize("case", CASES)
def test_structure_and_expressions(case, kind, rotor, friction) -> None:
    robot = robot_of(case)
    base = dynid.base_parameters(robot, kind=kind, rotor=rotor, friction=friction)
    names = robot.parameter_names(rotor=rotor, friction=friction)
    assert base.parameter_names == names
    assert len(base.names) == len(base.expressions) == base.count == len(base.independent)
    assert np.all(np.diff(base.independent) > 0), "independent is not increasing"
    np.testing.assert_array_equal(base.beta[:, base.independent], np.eye(base.count))
    # each base parameter is named after its representative column (plus an "R" when regrouped)
    for name, k in zip(base.names, base.independent):
        assert name.startswith(names[k])

    # zero terms dropped: the factors are ratios and products of DH lengths (>= 1e-4 for these
    # robots), never least-squares noise (<= ~1e-10)
    magnitude = np.where(base.beta != 0.0, np.abs(base.beta), np.inf)
    row, column = np.unravel_index(np.argmin(magnitude), magnitude.shape)
    assert magnitude[row, column] >= 1e-8, (
        f"noise-sized factor of {names[column]} in {base.expressions[row]!r}"
    )

    rng = np.random.default_rng(FRESH_SEED + 2)
    pis = [robot.parameter_vector(rotor=rotor, friction=friction), rng.normal(size=len(names))]
    for k, expression in enumerate(base.expressions):
        terms = linear_terms(expression)
        # the expression lists exactly the non-zero entries of beta's row, with those factors
        assert set(terms) == {names[j] for j in np.flatnonzero(base.beta[k])}, expression
        for name, coefficient in terms.items():
            assert coefficient == pytest.approx(base.beta[k, names.index(name)], rel=1e-12)
        for pi in pis:
            expected = float(base.beta[k] @ pi)
            scale = float(np.abs(base.beta[k]) @ np.abs(pi))
            got = evaluate(expression, names, pi)
            assert abs(got - expected) <= RTOL * scale, f"{expression!r}: {got} != {expected}"


@pytest.mark.parametrize(("kind", "rotor", "friction"), OPTIONS)
@pytest.mark.parametrize("case", ["lwr", "random_modified", "random_prismatic_first"])
def test_count_is_rank_of_fresh_stacked_regressor(case, kind, rotor, friction) -> None:
    robot = robot_of(case)
    base = dynid.base_parameters(robot, kind=kind, rotor=rotor, friction=friction)
    Y = regressor_of(robot, kind, rotor, friction, 40, FRESH_SEED + 3)
    W = Y.reshape(-1, Y.shape[-1])
    assert np.linalg.matrix_rank(W) == base.count
    assert np.linalg.matrix_rank(base.reduce(W)) == base.count  # the kept columns are independent
    assert numerical_rank(W) == base.count


def test_deterministic_and_cached() -> None:
    first, second = dynid.models.kuka_lwr4(), dynid.models.kuka_lwr4()
    for kind, rotor, friction in [
        ("torque", True, True),
        ("gravity", False, False),
        ("inertia", False, False),
    ]:
        a = dynid.base_parameters(first, kind=kind, rotor=rotor, friction=friction)
        b = dynid.base_parameters(second, kind=kind, rotor=rotor, friction=friction)
        np.testing.assert_array_equal(a.beta, b.beta)
        np.testing.assert_array_equal(a.independent, b.independent)
        assert a.expressions == b.expressions and a.names == b.names
        assert dynid.base_parameters(first, kind=kind, rotor=rotor, friction=friction) is a
    assert dynid.base_parameters(first) is not dynid.base_parameters(first, rotor=True)
    with pytest.raises(dataclasses.FrozenInstanceError):
        dynid.base_parameters(first).count = 0


def test_cache_keeps_the_most_recently_used_and_stays_correct() -> None:
    """A sweep over gravity directions, base poses and transmissions (a mobile base, a
    calibration) keeps at most CACHE_SIZE results on the robot, the least recently used dropped
    first; every result equals that of a fresh copy (no cache) of the robot as it is then."""
    rng = np.random.default_rng(SEED)
    robot = dynid.models.planar_2r()
    kept = dynid.base_parameters(robot)  # used at every step below: never dropped
    vertical = robot.gravity_vector.copy()
    options = {"rotor": True, "friction": True}
    cache = robot.__dict__["_base_parameter_cache"]
    for step, angle in enumerate(np.linspace(0.0, np.pi / 2, 3 * CACHE_SIZE)):
        robot.gravity_vector = 9.81 * np.array([np.sin(angle), 0.0, -np.cos(angle)])
        robot.base = random_pose(rng)
        robot.transmission = [[1.0, 0.0], [step / 10, 1.0]]
        for rotor_friction in (False, True):
            got = dynid.base_parameters(robot, **(options if rotor_friction else {}))
            fresh = dynid.base_parameters(robot.copy(), **(options if rotor_friction else {}))
            np.testing.assert_array_equal(got.beta, fresh.beta)
            np.testing.assert_array_equal(got.independent, fresh.independent)
        assert len(cache) <= CACHE_SIZE
        saved = robot.copy()
        robot.gravity_vector, robot.base, robot.transmission = vertical, np.eye(4), None
        assert dynid.base_parameters(robot) is kept
        robot.gravity_vector, robot.base = saved.gravity_vector, saved.base
        robot.transmission = saved.transmission
    assert len(cache) == CACHE_SIZE


# ---- counts -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kind", "rotor", "friction", "count"),
    [
        ("torque", False, False, 43),
        ("torque", True, False, 48),
        ("torque", True, True, 62),
        ("gravity", False, False, 12),  # the paper's p_g
        ("inertia", False, False, 39),
    ],
)
def test_lwr_counts(kind, rotor, friction, count) -> None:
    base = dynid.base_parameters(robot_of("lwr"), kind=kind, rotor=rotor, friction=friction)
    assert base.count == count


@pytest.mark.parametrize(("kind", "rotor", "friction"), OPTIONS)
def test_puma_counts_match_independent_rank(kind, rotor, friction) -> None:
    robot = robot_of("puma")
    Y = regressor_of(robot, kind, rotor, friction, 60, FRESH_SEED + 4)
    expected = numerical_rank(Y.reshape(-1, Y.shape[-1]))
    base = dynid.base_parameters(robot, kind=kind, rotor=rotor, friction=friction)
    assert base.count == expected


# ---- the lecture's planar 2R --------------------------------------------------------------------


@pytest.mark.parametrize("builder", [planar_2r_standard, planar_2r_modified])
def test_planar_2r_structural_counts(builder) -> None:
    vertical = dynid.base_parameters(builder(gravity=(0.0, -9.81, 0.0)))
    horizontal = dynid.base_parameters(builder(gravity=(0.0, 0.0, -9.81)))
    assert (vertical.count, horizontal.count) == (6, 4)
    # CoMs on the link axes (my1 = my2 = 0): exactly 4 non-zero base values in a vertical plane
    values = vertical.values(builder())
    nonzero = np.abs(values) > 1e-12 * np.max(np.abs(values))
    assert np.count_nonzero(nonzero) == 4, dict(zip(vertical.expressions, values))
    for expression in np.array(vertical.expressions)[~nonzero]:
        assert set(linear_terms(expression)) <= {"my1", "my2"}, expression


def test_planar_2r_modified_gives_the_lecture_coefficients() -> None:
    robot = planar_2r_modified()
    base = dynid.base_parameters(robot)
    terms = [linear_terms(e) for e in base.expressions]
    expected = [
        {"mx1": 1.0, "m2": L1},  # a1 = m1 d1 + m2 l1
        {"my1": 1.0},
        {"Izz1": 1.0, "m2": L1**2},  # a2 = Ic1zz + m1 d1^2 + m2 l1^2
        {"mx2": 1.0},  # a3 = m2 d2
        {"my2": 1.0},
        {"Izz2": 1.0},  # a4 = Ic2zz + m2 d2^2
    ]
    assert [sorted(t) for t in terms] == [sorted(t) for t in expected], base.expressions
    for got, want in zip(terms, expected):
        for name, coefficient in want.items():
            assert got[name] == pytest.approx(coefficient, rel=1e-12, abs=0)
    # the printed factors are the lecture's l1 = 0.7 and l1^2 = 0.49, not 0.48999999999999994
    assert "0.7*m2" in base.expressions[0] and "0.49*m2" in base.expressions[2]

    lecture = {
        "a1": M1 * D1 + M2 * L1,
        "a2": IC1 + M1 * D1**2 + M2 * L1**2,
        "a3": M2 * D2,
        "a4": IC2 + M2 * D2**2,
    }
    values = base.values(robot)
    got = {"a1": values[0], "a2": values[2], "a3": values[3], "a4": values[5]}
    for key, value in lecture.items():
        assert got[key] == pytest.approx(value, rel=1e-12), key
    assert values[1] == 0.0 and values[4] == 0.0  # my1, my2
    names = robot.parameter_names()
    pi = robot.parameter_vector()
    assert evaluate(base.expressions[0], names, pi) == pytest.approx(lecture["a1"], rel=1e-12)
    assert evaluate(base.expressions[2], names, pi) == pytest.approx(lecture["a2"], rel=1e-12)


def test_planar_2r_modified_horizontal_plane() -> None:
    """No gravity work: link 1 enters only through its z inertia, m2 grouped into it."""
    base = dynid.base_parameters(planar_2r_modified(gravity=(0.0, 0.0, -9.81)))
    terms = [linear_terms(e) for e in base.expressions]
    assert [sorted(t) for t in terms] == [["Izz1", "m2"], ["mx2"], ["my2"], ["Izz2"]]
    assert terms[0]["m2"] == pytest.approx(L1**2, rel=1e-12)


# ---- the paper's gravity groupings ------------------------------------------------------------


def test_lwr_gravity_groupings_of_the_paper() -> None:
    """Seed 001 eqs. (31)-(32): d1 (m3 + ... + m7) and d2 (m5 + m6 + m7) enter g(q) grouped."""
    base = dynid.base_parameters(robot_of("lwr"), kind="gravity")
    masses = [
        {
            name: c
            for name, c in linear_terms(e).items()
            if name.startswith("m") and name[1:].isdigit()
        }
        for e in base.expressions
    ]
    d1 = [m for m in masses if set(m) == {"m3", "m4", "m5", "m6", "m7"}]
    d2 = [m for m in masses if set(m) == {"m5", "m6", "m7"}]
    assert len(d1) == 1 and len(d2) == 1, base.expressions
    for coefficient in d1[0].values():
        assert abs(coefficient) == pytest.approx(0.4, rel=1e-12)
    for coefficient in d2[0].values():
        assert abs(coefficient) == pytest.approx(0.39, rel=1e-12)
    assert len(set(np.sign(list(d1[0].values())))) == 1  # the same sign: d1 * (sum of masses)
    assert len(set(np.sign(list(d2[0].values())))) == 1


# ---- bad arguments ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"kind": "foo"}, "kind"),
        ({"kind": "gravity", "rotor": True}, "rotor"),
        ({"kind": "gravity", "friction": True}, "friction"),
        ({"kind": "inertia", "friction": True}, "friction"),
    ],
)
def test_bad_arguments_raise_value_error(kwargs, argument) -> None:
    robot = dynid.models.planar_2r()
    with pytest.raises(ValueError, match=argument):
        dynid.base_parameters(robot, **kwargs)
