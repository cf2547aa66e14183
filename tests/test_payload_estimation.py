"""Full payload estimation (notes p. 33, Gaz & De Luca IROS 2017) on simulated loaded arms.

The truth is the payload put on the arm by Robot.with_payload (itself checked against an
independent combined-body computation in tests/test_payload.py); the data are the loaded arm's
inverse dynamics, optionally with Gaussian torque noise of a stated level. The tool-frame
expectations, the delta-method Jacobian (finite differences) and the paper's mass-only estimates
(eqs. (31)-(32) from identified gravity coefficients) are computed independently here.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.demo import TIP_COM, TIP_INERTIA, TIP_MASS, controller_model
from dynid.identification.payload import PAYLOAD_NAMES, estimate_payload, physical_from_parameters
from dynid.sim import VirtualController

EXACT = 1e-9  # noise-free data: the fit is exact up to rounding (observed ~1e-15)
PAYLOADS = {
    "offset_body": (
        0.8,
        np.array([0.03, -0.02, 0.09]),
        np.array([[2e-3, 1e-4, -2e-4], [1e-4, 1.5e-3, 3e-4], [-2e-4, 3e-4, 1e-3]]),
    ),
    "demo_tip": (TIP_MASS, np.array(TIP_COM), np.array(TIP_INERTIA)),
    "heavy_box": (5.0, np.array([-0.05, 0.08, 0.15]), np.diag([0.02, 0.03, 0.025])),
}


def random_states(robot: dynid.Robot, count: int, seed: int) -> tuple[np.ndarray, ...]:
    """Configurations within qlim, velocities in [-2, 2] rad/s, accelerations in [-5, 5]."""
    rng = np.random.default_rng(seed)
    q = robot.random_configurations(count, seed=seed)
    return q, rng.uniform(-2, 2, q.shape), rng.uniform(-5, 5, q.shape)


@pytest.fixture(params=sorted(PAYLOADS))
def payload(request):
    return PAYLOADS[request.param]


def test_noise_free_random_states_recover_the_payload_exactly(payload):
    # KUKA LWR-IV with its drive terms (they cancel in tau_loaded - robot.rnea). 1e-9 absolute
    # on m [kg], c [m], I [kg m^2]; zero std (exact fit).
    mass, com, inertia = payload
    robot = dynid.models.kuka_lwr4()
    q, qd, qdd = random_states(robot, 300, seed=4)
    tau = robot.with_payload(mass, com, inertia).rnea(q, qd, qdd)
    est = estimate_payload(robot, q, qd, qdd, tau)
    assert est.mass == pytest.approx(mass, abs=EXACT)
    np.testing.assert_allclose(est.com, com, rtol=0, atol=EXACT)
    np.testing.assert_allclose(est.inertia, inertia, rtol=0, atol=EXACT)
    assert est.mass_std < 1e-9 and est.frame == "flange"
    assert est.fit.names == list(PAYLOAD_NAMES)
    # parameters: the standard parameters of the payload (origin of frame n), Steiner forward.
    steiner = inertia + mass * (com @ com * np.eye(3) - np.outer(com, com))
    expected = np.concatenate([[mass], mass * com, steiner[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]])
    np.testing.assert_allclose(est.parameters, expected, rtol=0, atol=EXACT)


def test_noise_free_fourier_trajectory_with_identified_unloaded_model():
    # The unloaded model known only through identified base coefficients: beta fitted by
    # least squares on the unloaded arm's data (different trajectory), tau_unloaded = Y_b beta
    # along the loaded run, a Fourier excitation trajectory (5 harmonics, 0.1 Hz). 1e-9.
    mass, com, inertia = PAYLOADS["offset_body"]
    robot = dynid.models.kuka_lwr4()
    base = dynid.base_parameters(robot, rotor=True, friction=True)
    q0, qd0, qdd0 = random_states(robot, 400, seed=11)
    Y0 = base.reduce(robot.regressor(q0, qd0, qdd0, rotor=True, friction=True))
    beta = dynid.least_squares(Y0, robot.rnea(q0, qd0, qdd0)).theta
    rng = np.random.default_rng(3)
    trajectory = dynid.FourierTrajectory(
        2 * np.pi * 0.1,
        0.3 * rng.standard_normal((7, 5)),
        0.3 * rng.standard_normal((7, 5)),
        np.zeros(7),
    )
    _, q, qd, qdd = trajectory.sample(fs=50.0)
    tau = robot.with_payload(mass, com, inertia).rnea(q, qd, qdd)
    predicted = base.reduce(robot.regressor(q, qd, qdd, rotor=True, friction=True)) @ beta
    est = estimate_payload(robot, q, qd, qdd, tau, tau_unloaded=predicted)
    assert est.mass == pytest.approx(mass, abs=EXACT)
    np.testing.assert_allclose(est.com, com, rtol=0, atol=EXACT)
    np.testing.assert_allclose(est.inertia, inertia, rtol=0, atol=EXACT)


def test_tool_frame_results_are_the_flange_results_moved():
    # Tool = Rz(0.7) Rx(-0.4) rotation and a 0.12 m offset: c_tool = R^T (c - p),
    # I_tool = R^T I R (1e-9); std transformed alike (the com's covariance by R^T . R).
    mass, com, inertia = PAYLOADS["offset_body"]
    arm = dynid.models.kuka_lwr4()
    cz, sz, cx, sx = np.cos(0.7), np.sin(0.7), np.cos(-0.4), np.sin(-0.4)
    R = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]) @ np.array(
        [[1, 0, 0], [0, cx, -sx], [0, sx, cx]]
    )
    tool = np.eye(4)
    tool[:3, :3], tool[:3, 3] = R, (0.01, -0.02, 0.12)
    robot = dynid.Robot.from_dh(
        arm.dh,
        arm.joint_types,
        arm.convention,
        arm.gravity_vector,
        arm.params,
        tool=tool,
        qlim=arm.qlim,
    )
    q, qd, qdd = random_states(robot, 300, seed=5)
    tau = robot.with_payload(mass, com, inertia).rnea(q, qd, qdd)
    rng = np.random.default_rng(0)
    tau = tau + 0.02 * rng.standard_normal(tau.shape)
    flange = estimate_payload(robot, q, qd, qdd, tau)
    est = estimate_payload(robot, q, qd, qdd, tau, frame="tool")
    assert est.frame == "tool" and est.mass == flange.mass
    np.testing.assert_allclose(est.com, R.T @ (flange.com - tool[:3, 3]), rtol=0, atol=1e-12)
    np.testing.assert_allclose(est.inertia, R.T @ flange.inertia @ R, rtol=0, atol=1e-12)
    # Noise-free: the truth in the tool frame.
    exact = estimate_payload(
        robot, q, qd, qdd, robot.with_payload(mass, com, inertia).rnea(q, qd, qdd), frame="tool"
    )
    np.testing.assert_allclose(exact.com, R.T @ (com - tool[:3, 3]), rtol=0, atol=EXACT)
    np.testing.assert_allclose(exact.inertia, R.T @ inertia @ R, rtol=0, atol=EXACT)
    # The com std from R^T Cov R, with Cov_c recomputed from the fit by the delta method.
    _, G = physical_from_parameters(flange.parameters)
    cov_c = (G @ flange.fit.covariance @ G.T)[1:4, 1:4]
    np.testing.assert_allclose(est.com_std, np.sqrt(np.diag(R.T @ cov_c @ R)), rtol=1e-10)
    np.testing.assert_allclose(flange.com_std, np.sqrt(np.diag(cov_c)), rtol=1e-10)


def test_delta_method_jacobian_matches_finite_differences():
    # G = d(m, c, I_C)/d(m, h, I_O), central differences with h = 1e-6: 1e-8 relative.
    mass, com, inertia = PAYLOADS["heavy_box"]
    steiner = inertia + mass * (com @ com * np.eye(3) - np.outer(com, com))
    theta = np.concatenate([[mass], mass * com, steiner[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]])
    phi, G = physical_from_parameters(theta)
    np.testing.assert_allclose(phi[1:4], com, rtol=0, atol=1e-15)
    np.testing.assert_allclose(
        phi[4:], inertia[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]], rtol=0, atol=1e-15
    )
    step = 1e-6
    numeric = np.column_stack(
        [
            (
                physical_from_parameters(theta + step * e)[0]
                - physical_from_parameters(theta - step * e)[0]
            )
            / (2 * step)
            for e in np.eye(10)
        ]
    )
    np.testing.assert_allclose(G, numeric, rtol=0, atol=1e-8 * np.abs(G).max())
    _, G4 = physical_from_parameters(theta[:4])
    np.testing.assert_allclose(G4, G[:4, :4], rtol=0, atol=0)


NOISE = 0.05  # N m, the demo's torque sensor noise


def test_noisy_estimates_lie_within_three_std_and_the_std_are_calibrated():
    # 0.05 N m Gaussian torque noise, 300 random states, 40 seeds. Every estimate (mass, com,
    # inertia about the com) within 4.5 std of the truth, the first seed's within 3 std; the RMS
    # of the 40 z-scores of each quantity in [0.7, 1.3] (the std are neither too small nor too
    # large: expected 1, +-0.11 one sigma for 40 draws).
    mass, com, inertia = PAYLOADS["offset_body"]
    robot = dynid.models.kuka_lwr4()
    loaded = robot.with_payload(mass, com, inertia)
    z = []
    for seed in range(40):
        q, qd, qdd = random_states(robot, 300, seed=100 + seed)
        rng = np.random.default_rng(seed)
        tau = loaded.rnea(q, qd, qdd) + NOISE * rng.standard_normal(q.shape)
        est = estimate_payload(robot, q, qd, qdd, tau)
        z.append(
            np.concatenate(
                [
                    [(est.mass - mass) / est.mass_std],
                    (est.com - com) / est.com_std,
                    ((est.inertia - inertia) / est.inertia_std)[np.triu_indices(3)],
                ]
            )
        )
    z = np.array(z)
    assert np.abs(z[0]).max() < 3.0
    assert np.abs(z).max() < 4.5
    rms = np.sqrt((z**2).mean(axis=0))
    assert np.all((rms > 0.7) & (rms < 1.3)), rms


def test_weighted_least_squares_with_joints_of_different_noise():
    # Noise 0.01 N m on joints 1-4, 0.2 N m on joints 5-7; WLS within 3 std, and its mass std
    # below the OLS one (the noisy joints are down-weighted).
    mass, com, inertia = PAYLOADS["heavy_box"]
    robot = dynid.models.kuka_lwr4()
    q, qd, qdd = random_states(robot, 400, seed=21)
    rng = np.random.default_rng(21)
    level = np.array([0.01] * 4 + [0.2] * 3)
    tau = robot.with_payload(mass, com, inertia).rnea(q, qd, qdd) + level * rng.standard_normal(
        q.shape
    )
    wls = estimate_payload(robot, q, qd, qdd, tau, method="wls")
    ols = estimate_payload(robot, q, qd, qdd, tau)
    assert abs(wls.mass - mass) < 3 * wls.mass_std
    assert np.all(np.abs(wls.com - com) < 3 * wls.com_std)
    assert np.all(np.abs(wls.inertia - inertia) < 3 * wls.inertia_std)
    assert wls.mass_std < ols.mass_std


def test_no_payload_gives_zero_and_no_centre_of_mass():
    # Unloaded data: all 10 parameters ~0 (1e-12 noise-free); with noise the mass lies within
    # 3 std of 0 and com / inertia are None (a zero mass has no centre of mass).
    robot = dynid.models.kuka_lwr4()
    q, qd, qdd = random_states(robot, 300, seed=8)
    tau = robot.rnea(q, qd, qdd)
    est = estimate_payload(robot, q, qd, qdd, tau)
    np.testing.assert_allclose(est.parameters, 0.0, rtol=0, atol=1e-12)
    assert est.com is None and est.inertia is None and est.com_std is None
    noisy = estimate_payload(
        robot, q, qd, qdd, tau + NOISE * np.random.default_rng(1).standard_normal(tau.shape)
    )
    assert abs(noisy.mass) < 3 * noisy.mass_std and noisy.com is None


def test_an_uninformative_joint_can_be_excluded():
    # Joint 1's torque sensor broken (a 7 N m offset): with exclude_joints=(0,) the estimate is
    # exact again (1e-9); without, it is visibly wrong (> 1e-3 kg).
    mass, com, inertia = PAYLOADS["offset_body"]
    robot = dynid.models.kuka_lwr4()
    q, qd, qdd = random_states(robot, 300, seed=9)
    tau = robot.with_payload(mass, com, inertia).rnea(q, qd, qdd)
    tau[:, 0] += 7.0
    assert abs(estimate_payload(robot, q, qd, qdd, tau).mass - mass) > 1e-3
    est = estimate_payload(robot, q, qd, qdd, tau, exclude_joints=(0,))
    assert est.mass == pytest.approx(mass, abs=EXACT)
    np.testing.assert_allclose(est.inertia, inertia, rtol=0, atol=EXACT)
    assert est.fit.excluded == (0,)


def test_a_planar_arm_cannot_see_the_out_of_plane_parameters():
    # Planar 2R (vertical plane): only m, mx, my and Izz of the payload act; the error names the
    # others.
    robot = dynid.models.planar_2r()
    q, qd, qdd = random_states(robot, 200, seed=2)
    tau = robot.with_payload(0.5, (0.1, 0.02, 0.0), np.diag([1e-3, 2e-3, 2e-3])).rnea(q, qd, qdd)
    with pytest.raises(
        dynid.RankDeficientError, match=r"^the data do not determine the payload: .*rank 4 < 10"
    ) as info:
        estimate_payload(robot, q, qd, qdd, tau)
    least = str(info.value).split("least excited: ")[1].split(" (")[0].split(", ")
    assert set(least) <= {"mz_L", "Ixx_L", "Ixy_L", "Ixz_L", "Iyy_L", "Iyz_L"}
    assert "m_L" not in least and "Izz_L" not in least


def test_too_few_samples_is_a_clear_error():
    # One sample of 7 joints: 7 equations for 10 unknowns.
    robot = dynid.models.kuka_lwr4()
    q = np.full(7, 0.3)
    with pytest.raises(
        dynid.RankDeficientError, match=r"^q: 1 sample\(s\) give 7 torque equations"
    ):
        estimate_payload(robot, q, q, q, robot.rnea(q, q, q))


def test_static_data_need_inertia_false():
    # qd = qdd = 0: the inertia does not act; the error says so and inertia=False recovers m and
    # c exactly (1e-9); inertia=False with moving data is refused.
    mass, com, inertia = PAYLOADS["offset_body"]
    robot = dynid.models.kuka_lwr4()
    q = robot.random_configurations(100, seed=3)
    zero = np.zeros_like(q)
    tau = robot.with_payload(mass, com, inertia).rnea(q, zero, zero)
    with pytest.raises(dynid.RankDeficientError, match=r"Static data .* pass inertia=False"):
        estimate_payload(robot, q, zero, zero, tau)
    est = estimate_payload(robot, q, zero, zero, tau, inertia=False)
    assert est.mass == pytest.approx(mass, abs=EXACT)
    np.testing.assert_allclose(est.com, com, rtol=0, atol=EXACT)
    assert est.inertia is None and est.parameters.shape == (4,)
    with pytest.raises(ValueError, match=r"^inertia: False fits the mass"):
        estimate_payload(robot, q, zero + 0.1, zero, tau, inertia=False)


@pytest.mark.parametrize("noise", [0.0, 1.0], ids=["noise_free", "demo_noise"])
def test_the_mass_equals_the_papers_eqs_31_32_on_the_papers_setting(noise):
    # Paper Sect. VI: the controller's numeric g(q) at 1000 configurations, for the arm and for
    # the arm with the 250 g tip. Eqs. (31)-(32): mass from the change of the identified gravity
    # coefficients holding d1 and d2 (payload_mass_estimates). Here: the rule of change on the
    # same static data, tau_unloaded = the identified unloaded model's g(q), inertia=False.
    # Noise-free all three agree with 0.25 kg to 1e-9; with the demo noise (model 1e-5 relative,
    # position 1e-5 rad) all within 1 % of 0.25 kg and within 5e-4 relative of each other
    # (observed: 0.2500093 and 0.2499990 from eqs. (31), (32), 0.2500036 here). Not "within 3
    # std": the std covers the loaded data's noise, not the error of the identified unloaded
    # model, which here is of the same size (+- 0.0000013 kg).
    structure, truth = dynid.models.kuka_lwr4(), controller_model()
    q = truth.random_configurations(1000, seed=6)
    options = {"model_noise": 1e-5 * noise, "position_noise": 1e-5 * noise}
    readings, fits = [], []
    for k, robot in enumerate((truth, truth.with_payload(TIP_MASS, TIP_COM, TIP_INERTIA))):
        data = VirtualController(robot, seed=k, **options).read_static(q)
        readings.append(data)
        fits.append(dynid.identify_from_controller(structure, data.q, data.g, data.M))
    paper = dynid.payload_mass_estimates(fits[0].gravity_base, fits[0].pi_g, fits[1].pi_g)
    assert sorted(e["factor"] for e in paper) == [0.39, 0.4]
    loaded = readings[1]
    zero = np.zeros_like(loaded.q)
    est = estimate_payload(
        structure,
        loaded.q,
        zero,
        zero,
        loaded.g,
        tau_unloaded=fits[0].gravity(loaded.q),
        inertia=False,
        exclude_joints=(0,),
    )
    if noise == 0.0:
        assert est.mass == pytest.approx(TIP_MASS, abs=EXACT)
        np.testing.assert_allclose(est.com, TIP_COM, rtol=0, atol=EXACT)
        for e in paper:
            assert e["mass"] == pytest.approx(est.mass, abs=EXACT)
    else:
        assert est.mass == pytest.approx(TIP_MASS, rel=0.01)
        for e in paper:
            assert e["mass"] == pytest.approx(TIP_MASS, rel=0.01)
            assert e["mass"] == pytest.approx(est.mass, rel=5e-4)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"robot": "LWR"}, r"^robot: expected a dynid.Robot"),
        ({"q": np.zeros((10, 6))}, r"^q: expected shape \(T, 7\)"),
        ({"qd": np.zeros((9, 7))}, r"^qd: expected the shape of q"),
        ({"tau": np.full((10, 7), np.nan)}, r"^tau: non-finite"),
        ({"tau_unloaded": np.zeros((10, 3))}, r"^tau_unloaded: expected shape"),
        ({"inertia": "yes"}, r"^inertia: expected True or False"),
        ({"frame": "world"}, r"^frame: expected one of"),
        ({"method": "ridge"}, r"^method: expected one of"),
        ({"exclude_joints": (7,)}, r"^exclude_joints: expected .*\[0, 7\)"),
        ({"exclude_joints": 3}, r"^exclude_joints: expected"),
        ({"qdd": [[1j] * 7] * 10}, r"^qdd: expected real numbers"),
    ],
)
def test_bad_arguments_are_value_errors_naming_them(change, match):
    robot = dynid.models.kuka_lwr4()
    q, qd, qdd = random_states(robot, 10, seed=0)
    args = {"robot": robot, "q": q, "qd": qd, "qdd": qdd, "tau": robot.rnea(q, qd, qdd), **change}
    with pytest.raises(ValueError, match=match):
        estimate_payload(
            args.pop("robot"),
            args.pop("q"),
            args.pop("qd"),
            args.pop("qdd"),
            args.pop("tau"),
            **args,
        )


def test_results_compare_by_value():
    # The same data give equal estimates (arrays compared by value, None fields included).
    robot = dynid.models.kuka_lwr4()
    q, qd, qdd = random_states(robot, 50, seed=0)
    tau = robot.with_payload(*PAYLOADS["offset_body"]).rnea(q, qd, qdd)
    assert estimate_payload(robot, q, qd, qdd, tau) == estimate_payload(robot, q, qd, qdd, tau)
    empty = estimate_payload(robot, q, qd, qdd, robot.rnea(q, qd, qdd))
    assert empty == estimate_payload(robot, q, qd, qdd, robot.rnea(q, qd, qdd))
    assert empty != estimate_payload(robot, q, qd, qdd, tau)


# --- from the change of identified coefficients (the paper's static readings) ------------------


def identified_pair(payload, noise: float, structure=None, truth=None, **options):
    """identify_from_controller on 1000 controller readings without and with the payload."""
    structure = structure or dynid.models.kuka_lwr4()
    truth = truth or controller_model()
    fits = []
    for k, robot in enumerate((truth, truth.with_payload(*payload))):
        controller = VirtualController(
            robot, seed=k, model_noise=1e-5 * noise, position_noise=1e-5 * noise
        )
        data = controller.read_static(controller.random_configurations(1000))
        fits.append(dynid.identify_from_controller(structure, data.q, data.g, data.M, **options))
    return fits


@pytest.mark.parametrize("name", ["offset_body", "demo_tip"])
def test_coefficient_changes_give_the_full_payload_and_contain_eqs_31_32(name):
    # Noise-free controller readings: the gravity and inertia coefficient changes determine all
    # 10 payload parameters of the LWR (rank 10), exactly (1e-9); the mass equals the paper's
    # eqs. (31)-(32) estimates (1e-9), which are rows of the same system.
    mass, com, inertia = PAYLOADS[name]
    unloaded, loaded = identified_pair(PAYLOADS[name], 0.0)
    est = dynid.payload_from_identified(unloaded, loaded)
    assert est.fit is None and est.frame == "flange"
    assert est.mass == pytest.approx(mass, abs=EXACT)
    np.testing.assert_allclose(est.com, com, rtol=0, atol=EXACT)
    np.testing.assert_allclose(est.inertia, inertia, rtol=0, atol=EXACT)
    paper = dynid.payload_mass_estimates(unloaded.gravity_base, unloaded.pi_g, loaded.pi_g)
    assert len(paper) == 2
    for e in paper:
        assert e["mass"] == pytest.approx(est.mass, abs=EXACT)


def test_coefficient_changes_with_the_demo_noise_lie_within_three_std():
    # Demo noise (model 1e-5 relative, position 1e-5 rad): every quantity within 3 std (std from
    # both fits' covariances), and the mass within 0.01 % like eqs. (31)-(32).
    mass, com, inertia = PAYLOADS["offset_body"]
    unloaded, loaded = identified_pair(PAYLOADS["offset_body"], 1.0)
    est = dynid.payload_from_identified(unloaded, loaded)
    assert abs(est.mass - mass) < 3 * est.mass_std
    assert np.all(np.abs(est.com - com) < 3 * est.com_std)
    assert np.all(np.abs(est.inertia - inertia) < 3 * est.inertia_std)
    assert est.mass == pytest.approx(mass, rel=1e-4)
    for e in dynid.payload_mass_estimates(unloaded.gravity_base, unloaded.pi_g, loaded.pi_g):
        assert e["mass"] == pytest.approx(mass, rel=1e-4)


def test_coefficient_changes_of_a_planar_arm_name_what_they_miss():
    # The planar 2R's controller readings see m, mx, my and Izz of the payload only.
    robot = dynid.models.planar_2r()
    payload = (0.5, np.array([0.1, 0.02, 0.0]), np.diag([1e-3, 2e-3, 2e-3]))
    fits = identified_pair(payload, 0.0, structure=robot, truth=robot, exclude_gravity_joints=())
    with pytest.raises(
        dynid.RankDeficientError,
        match=r"^the coefficient changes do not determine the payload: rank 4 < 10"
        r"; not determined: mz_L, Ixx_L, Ixy_L, Ixz_L, Iyy_L, Iyz_L$",
    ):
        dynid.payload_from_identified(*fits)


def test_payload_from_identified_bad_arguments():
    unloaded, loaded = identified_pair(PAYLOADS["demo_tip"], 0.0)
    with pytest.raises(ValueError, match=r"^loaded: expected a dynid.IdentifiedModel"):
        dynid.payload_from_identified(unloaded, loaded.pi_g)
    with pytest.raises(ValueError, match=r"^frame: expected one of"):
        dynid.payload_from_identified(unloaded, loaded, frame="base")
    robot = dynid.models.planar_2r()
    other = identified_pair(
        PAYLOADS["demo_tip"], 0.0, structure=robot, truth=robot, exclude_gravity_joints=()
    )[1]
    with pytest.raises(ValueError, match=r"^loaded: identified on another structure"):
        dynid.payload_from_identified(unloaded, other)


def test_as_dict_is_json_ready():
    # json.dumps accepts it; values round-trip to the estimate's (exact, floats as given).
    import json

    robot = dynid.models.kuka_lwr4()
    q, qd, qdd = random_states(robot, 50, seed=0)
    est = estimate_payload(
        robot, q, qd, qdd, robot.with_payload(*PAYLOADS["offset_body"]).rnea(q, qd, qdd)
    )
    back = json.loads(json.dumps(est.as_dict()))
    assert back["mass"] == est.mass and back["frame"] == "flange"
    np.testing.assert_array_equal(back["com"], est.com)
    np.testing.assert_array_equal(back["inertia_std"], est.inertia_std)
    assert list(back["parameters"]) == list(PAYLOAD_NAMES)
    assert back["parameters"]["Izz_L"] == est.parameters[9]
    empty = estimate_payload(robot, q, qd, qdd, robot.rnea(q, qd, qdd)).as_dict()
    assert empty["com"] is None and empty["inertia"] is None
    json.dumps(empty)
