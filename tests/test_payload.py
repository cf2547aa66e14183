"""A payload on the last link: the rule of change (Robot.with_payload) and the tip experiment.

Notes, "Rule of change in dynamic parameters" (p. 33): a rigid payload on link n changes only that
link's parameters: masses add, first moments add (the centre of mass is the mass-weighted mean),
inertia tensors about the same point in the same axes add. Paper eqs. (31)-(32): the 250 g tip
changes the gravity coefficients holding d1 (m3+...+m7) and d2 (m5+m6+m7) by d1 m_L and d2 m_L.

The references are independent of with_payload: the combined body computed here through its
centre of mass (parallel-axis theorem twice), the payload's own gravity torque and inertia matrix
from the NumPy reference model (tests/reference_model.py) and from dynid's geometric Jacobian
at a tool frame placed at the payload's centre of mass, and potential-energy finite differences.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import dynid
import reference_model as ref
from dynid.cli.demo import TIP_COM, TIP_INERTIA, TIP_MASS, controller_model
from dynid.sim import VirtualController

DEMO_NOISE = {"model_noise": 1e-5, "torque_noise": 0.05, "position_noise": 1e-5}  # run_demo's
PAYLOADS = {
    "demo_tip": (TIP_MASS, np.array(TIP_COM), np.array(TIP_INERTIA)),
    "offset_body": (
        0.8,
        np.array([0.03, -0.02, 0.09]),
        np.array([[2e-3, 1e-4, -2e-4], [1e-4, 1.5e-3, 3e-4], [-2e-4, 3e-4, 1e-3]]),
    ),
    "point_mass": (1.3, np.array([-0.05, 0.01, 0.12]), None),
}


def shift(mass: float, offset: np.ndarray) -> np.ndarray:
    """m (|r|^2 E - r r^T): the parallel-axis term for a body displaced by r."""
    return mass * (offset @ offset * np.eye(3) - np.outer(offset, offset))


def combined_link(params: np.ndarray, mass: float, com: np.ndarray, inertia) -> np.ndarray:
    """Standard parameters of link + payload through the combined centre of mass (p. 33):
    M = m + m_L, c = (m c + m_L c_L) / M, I_c = I_c,link + shift + I_L + shift, then Steiner
    back to the frame origin."""
    inertia = np.zeros((3, 3)) if inertia is None else np.asarray(inertia)
    m, c, I_c = ref.params_to_physical(params)
    total = m + mass
    centre = (m * c + mass * com) / total
    I_centre = I_c + shift(m, c - centre) + inertia + shift(mass, com - centre)
    return ref.physical_to_params(total, centre, I_centre)


def tool_at(robot: dynid.Robot, com: np.ndarray) -> dynid.Robot:
    """The same arm with its tool frame at the payload's centre of mass (frame n axes)."""
    tool = np.eye(4)
    tool[:3, 3] = com
    return dynid.Robot.from_dh(
        robot.dh,
        robot.joint_types,
        robot.convention,
        robot.gravity_vector,
        robot.params,
        robot.base,
        tool,
    )


@pytest.fixture(params=sorted(PAYLOADS))
def payload(request):
    return PAYLOADS[request.param]


# --- the rule of change --------------------------------------------------------------------------


def test_with_payload_changes_only_the_last_link_by_the_rule_of_change(payload):
    # Parameters, 1e-12 absolute (values are O(1)); the original robot is left untouched.
    mass, com, inertia = payload
    robot = dynid.models.kuka_lwr4()
    before = robot.params.copy()
    loaded = robot.with_payload(mass, com, inertia)
    np.testing.assert_array_equal(robot.params, before)
    np.testing.assert_array_equal(loaded.params[:-1], before[:-1])
    np.testing.assert_allclose(
        loaded.params[-1], combined_link(before[-1], mass, com, inertia), rtol=0, atol=1e-12
    )
    for field in ("Ia", "Fv", "Fs", "dh", "base", "tool", "qlim", "gravity_vector"):
        np.testing.assert_array_equal(getattr(loaded, field), getattr(robot, field), field)
    assert loaded.is_physically_consistent()


def test_with_payload_gravity_and_mass_matrix_add_the_payloads_own(payload):
    # g_L = -m_L J_v^T g0 and M_L = m_L J_v^T J_v + J_w^T R I_L R^T J_w at the payload's CoM,
    # from (a) the NumPy reference model and (b) dynid's Jacobian of a tool frame at that CoM.
    # Tolerance 1e-10 relative to max|g|, max|M|.
    mass, com, inertia = payload
    I_L = np.zeros((3, 3)) if inertia is None else inertia
    robot = dynid.models.kuka_lwr4()
    loaded = robot.with_payload(mass, com, inertia)
    arm = ref.Arm(
        dh=np.array(robot.dh),
        joint_types=robot.joint_types,
        convention=robot.convention,
        mass=np.ones(7),
        com=np.zeros((7, 3)),
        inertia_com=np.zeros((7, 3, 3)),
    )
    g0 = np.array(robot.gravity_vector)
    tool = tool_at(robot, com)
    for q in robot.random_configurations(6, seed=1):
        kin = ref.kinematics(arm, q)
        frame = kin.frames[-1]
        J = ref.point_jacobian(arm, kin, frame[:3, :3] @ com + frame[:3, 3], arm.n)
        np.testing.assert_allclose(tool.jacobian(q), J, rtol=0, atol=1e-12)  # (b) == (a)
        R = frame[:3, :3]
        g_L = -mass * J[:3].T @ g0
        M_L = mass * J[:3].T @ J[:3] + J[3:].T @ R @ I_L @ R.T @ J[3:]
        g_new, M_new = loaded.gravity(q), loaded.mass_matrix(q)
        np.testing.assert_allclose(
            g_new, robot.gravity(q) + g_L, rtol=0, atol=1e-10 * np.abs(g_new).max()
        )
        np.testing.assert_allclose(
            M_new, robot.mass_matrix(q) + M_L, rtol=0, atol=1e-10 * np.abs(M_new).max()
        )


def test_with_payload_potential_energy_gradient_is_the_added_gravity(payload):
    # U_new - U = -m_L g0^T p_L (closed form, 1e-12) and its central-difference gradient
    # (h = 1e-6) equals g_new - g (1e-7 relative).
    mass, com, inertia = payload
    robot = dynid.models.kuka_lwr4()
    loaded = robot.with_payload(mass, com, inertia)
    tool = tool_at(robot, com)
    g0, h = np.array(robot.gravity_vector), 1e-6
    for q in robot.random_configurations(4, seed=2):
        added = loaded.potential_energy(q) - robot.potential_energy(q)
        assert added == pytest.approx(-mass * g0 @ tool.fkine(q)[:3, 3], abs=1e-12)
        gradient = np.array(
            [
                (
                    loaded.potential_energy(q + h * e)
                    - robot.potential_energy(q + h * e)
                    - loaded.potential_energy(q - h * e)
                    + robot.potential_energy(q - h * e)
                )
                / (2 * h)
                for e in np.eye(robot.n)
            ]
        )
        dg = loaded.gravity(q) - robot.gravity(q)
        np.testing.assert_allclose(gradient, dg, rtol=0, atol=1e-7 * np.abs(dg).max())


@pytest.mark.parametrize(
    ("args", "name"),
    [
        pytest.param((0.0, (0, 0, 0.1), None), "mass", id="mass-zero"),
        pytest.param((-0.2, (0, 0, 0.1), None), "mass", id="mass-negative"),
        pytest.param((np.nan, (0, 0, 0.1), None), "mass", id="mass-nan"),
        pytest.param((np.inf, (0, 0, 0.1), None), "mass", id="mass-inf"),
        pytest.param(("heavy", (0, 0, 0.1), None), "mass", id="mass-text"),
        pytest.param((0.2, (0, 0), None), "com", id="com-shape"),
        pytest.param((0.2, (0, 0, np.nan), None), "com", id="com-nan"),
        pytest.param((0.2, "tip", None), "com", id="com-text"),
        pytest.param((0.2, (0, 0, 0.1), np.eye(2)), "inertia", id="inertia-shape"),
        pytest.param((0.2, (0, 0, 0.1), np.full((3, 3), np.nan)), "inertia", id="inertia-nan"),
    ],
)
def test_with_payload_bad_input_raises_value_error_naming_the_argument(args, name):
    # The argument of with_payload is called `inertia`; the message must start with its name.
    with pytest.raises(ValueError, match=rf"^{name}\b(?!_)"):
        dynid.models.kuka_lwr4().with_payload(*args)


@pytest.mark.parametrize(
    "inertia",
    [
        -1e-3 * np.eye(3),  # negative definite
        np.diag([1e-3, 1e-3, 5e-3]),  # Izz > Ixx + Iyy: violates the triangle inequality
        1e-3 * np.array([[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),  # not symmetric
    ],
    ids=["negative", "triangle", "asymmetric"],
)
def test_with_payload_rejects_a_physically_impossible_inertia(inertia):
    # docs/conventions.md, "Bad input": a physically impossible body given in physical form raises
    # ValueError (as set_link does); silently adding it would corrupt the model.
    with pytest.raises(ValueError, match=r"^inertia\b"):
        dynid.models.kuka_lwr4().with_payload(0.25, (0.0, 0.0, 0.1), inertia)


# --- which coefficients carry the payload mass (from the expressions) ----------------------------


def evaluate(expressions: list[str], robot: dynid.Robot) -> np.ndarray:
    """Each base-parameter expression evaluated as Python arithmetic with the robot's values."""
    values = dict(zip(robot.parameter_names(), robot.parameter_vector()))
    assert all(re.fullmatch(r"[\w\s.*+-]+", e) for e in expressions)
    return np.array([eval(e, {"__builtins__": {}}, values) for e in expressions])


def with_flange_offset() -> dynid.Robot:
    """controller_model() with the real arm's 0.078 m flange offset as d7 in the DH table: then
    a gravity coefficient holds m7 together with mz7 (mz6 + 0.078*m7 + mz7) and measures the
    payload's centre of mass as well as its mass, so it must not be used."""
    robot = controller_model()
    dh = np.array(robot.dh)
    dh[6, 2] = 0.078
    return dynid.Robot.from_dh(
        dh, robot.joint_types, robot.convention, robot.gravity_vector, robot.params, qlim=robot.qlim
    )


@pytest.mark.parametrize(
    "make", [controller_model, with_flange_offset], ids=["paper_frames", "flange_in_dh"]
)
def test_exactly_the_d1_and_d2_coefficients_carry_the_payload_mass(make):
    # Independent derivation: evaluate the gravity expressions (text) on the robot with two very
    # different payloads of the same mass; a coefficient that changes by the same k * m_L for
    # both, whatever the centre of mass and inertia, measures the mass alone. Those must be the
    # paper's two (k = d1 = 0.4, eq. (31) and k = d2 = 0.39, eq. (32)) and the library must find
    # exactly them, with exact changes (1e-12) on noise-free true values.
    robot = make()
    base = dynid.base_parameters(robot, "gravity")
    mass = 0.7
    probes = (((0.04, -0.03, 0.2), None), ((-0.1, 0.05, -0.02), np.diag([1e-3, 2e-3, 2.5e-3])))
    changes = [
        (
            evaluate(base.expressions, robot.with_payload(mass, com, inertia))
            - evaluate(base.expressions, robot)
        )
        / mass
        for com, inertia in probes
    ]
    same = np.abs(changes[0] - changes[1]) < 1e-12
    moved = np.abs(changes[0]) > 1e-9
    mass_only = np.flatnonzero(same & moved)
    factors = sorted(changes[0][mass_only].round(12))
    assert factors == [0.39, 0.4]

    before = base.values(robot)
    after = base.values(robot.with_payload(0.25, TIP_COM, TIP_INERTIA))
    estimates = dynid.payload_mass_estimates(base, before, after)
    assert sorted(e["coefficient"] for e in estimates) == sorted(base.names[k] for k in mass_only)
    assert sorted(e["factor"] for e in estimates) == [0.39, 0.4]
    for e in estimates:
        assert e["expression"] == base.expressions[base.names.index(e["coefficient"])]
        assert f"{e['factor']!r}*m7" in e["expression"]
        assert e["mass"] == pytest.approx(0.25, abs=1e-12)


@pytest.mark.parametrize("seed", [0, 5])
def test_tip_experiment_recovers_250_g_within_one_percent(seed):
    # Paper Sect. VI: two controllers (arm, arm + 250 g tip), demo noise levels, 1000 training
    # configurations each as the paper; both estimates (eqs. (31) and (32)) within 1 %.
    structure = dynid.models.kuka_lwr4()
    truth = controller_model()
    fits = []
    for k, robot in enumerate((truth, truth.with_payload(TIP_MASS, TIP_COM, TIP_INERTIA))):
        controller = VirtualController(robot, seed=seed + k, **DEMO_NOISE)
        data = controller.read_static(controller.random_configurations(1000))
        fits.append(dynid.identify_from_controller(structure, data.q, data.g, data.M))
    estimates = dynid.payload_mass_estimates(fits[0].gravity_base, fits[0].pi_g, fits[1].pi_g)
    assert sorted(e["factor"] for e in estimates) == [0.39, 0.4]
    for e in estimates:
        assert e["mass"] == pytest.approx(TIP_MASS, rel=0.01), e


def test_payload_mass_estimates_rejects_wrong_shapes():
    base = dynid.base_parameters(dynid.models.kuka_lwr4(), "gravity")
    with pytest.raises(ValueError, match="before"):
        dynid.payload_mass_estimates(base, np.zeros(base.count - 1), np.zeros(base.count))
