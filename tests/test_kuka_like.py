"""The KUKA-like joint torque controller (dynid.sim.KukaLike, C++ KukaLikeController) and the
elastic option of dynid.sim.VirtualController (issue 12 item 2).

Each law is checked against physics it must obey, not against its own formula:

- set-point regulation: q -> q_d, theta -> q_d + K^-1 g(q_d), tau_J -> g(q_d) (the equilibrium
  of eqs. (1)-(3) under the law), and with a user torque the closed-form shifted equilibrium;
- with K_T = D_T = 0 and the gravity at the set-point, the run equals MotorPD's (bit for bit);
- passivity (Albu-Schaeffer, Ott, Hirzinger 2007): along a friction-free regulation run, the
  storage V = link + shaped-motor kinetic (B_theta = B / (1 + K_T)) + spring + gravity +
  controller potential obeys dV/dt = -thetad^T Kd thetad; the sampled run's balance error falls
  as dt (zero-order hold) and V never rises by more than round-off-sized ZOH steps;
- the torque loop shapes the motor inertia: plant B under gain K_T runs like plant B / (1 + K_T)
  without it (error falling as dt);
- VirtualController: as K grows the elastic run approaches the rigid one (positions as 1/K);
  through the paper's torque validation (eq. (33)) the elastic joints give torque errors of the
  same order as the rigid ones; static readings do not depend on the option.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize

import dynid
from dynid.cli.demo import controller_model, torque_validation
from dynid.identification.from_controller import identify_from_controller
from dynid.identification.validation import error_metrics
from dynid.sim import (
    KukaLike,
    MotorPD,
    VirtualController,
    paper_validation_trajectory,
    simulate_elastic,
)

Q_D = np.array([0.3, 0.8, -0.2, -1.0, 0.4, 0.6, 0.1])
#: Joint stiffness assumed for the LWR-IV [N m/rad]: stiffer shoulder and elbow, softer wrist.
LWR_STIFFNESS = np.array([1.5e4, 1.5e4, 1.5e4, 1.5e4, 5e3, 5e3, 5e3])


def lwr_elastic(
    robot: dynid.Robot | None = None,
    coulomb: bool = False,
    stiffness: np.ndarray | float = LWR_STIFFNESS,
    viscous: bool = True,
) -> dynid.ElasticRobot:
    """The LWR-IV on springs, its rotor inertia (and friction) on the motor side."""
    robot = dynid.models.kuka_lwr4() if robot is None else robot
    return dynid.ElasticRobot(
        robot,
        stiffness,
        robot.Ia,
        motor_viscous=robot.Fv if viscous else None,
        motor_coulomb=robot.Fs if coulomb else None,
    )


def static_link_position(elastic: dynid.ElasticRobot, theta: np.ndarray) -> np.ndarray:
    """qbar with K (theta - qbar) = g(qbar) per row of theta, by NumPy iteration, the residual
    checked to 1e-10 N m (so the result does not depend on the method)."""
    x = theta.copy()
    for _ in range(200):
        x = theta - elastic.link.gravity(x) / elastic.K
    residual = elastic.K * (theta - x) - elastic.link.gravity(x)
    assert np.abs(residual).max() < 1e-10
    return x


def test_set_point_regulation_reaches_the_elastic_equilibrium() -> None:
    """q -> q_d, theta -> q_d + K^-1 g(q_d), tau_J -> g(q_d) (1e-8 rad, 1e-6 N m after 10 s at
    3 kHz; measured 2e-14 rad, 6e-12 N m), for both gravity terms, K_T = 3, D_T = 1e-3 s."""
    elastic = lwr_elastic()
    g_d = elastic.link.gravity(Q_D)
    for gravity in ("static", "desired"):
        law = KukaLike(
            elastic, 400.0, 40.0, Q_D, torque_gain=3.0, torque_damping=1e-3, gravity=gravity
        )
        run = simulate_elastic(
            elastic, np.zeros(7), None, duration=10.0, controller=law, dt=1 / 3000, substeps=2
        )
        np.testing.assert_allclose(run.q[-1], Q_D, rtol=0, atol=1e-8)
        np.testing.assert_allclose(run.theta[-1], Q_D + g_d / elastic.K, rtol=0, atol=1e-8)
        np.testing.assert_allclose(run.tau_J[-1], g_d, rtol=0, atol=1e-6)
        np.testing.assert_allclose(run.qd[-1], 0.0, rtol=0, atol=1e-8)


def test_user_torque_shifts_the_equilibrium_as_the_closed_form_says() -> None:
    """With tau_user constant, at rest u = tau_J = g(q) and q = qbar(theta), so
    Kp (theta_d - theta) + tau_user = 0: theta = theta_d + Kp^-1 tau_user, q = qbar(theta),
    tau_J = g(q) (1e-8 rad, 1e-6 N m)."""
    elastic = lwr_elastic()
    kp = np.linspace(300.0, 500.0, 7)
    tau_user = np.array([1.0, -2.0, 0.5, 1.5, -0.3, 0.2, 0.1])
    law = KukaLike(elastic, kp, 40.0, Q_D, torque_gain=3.0, torque_damping=1e-3, tau_user=tau_user)
    run = simulate_elastic(
        elastic, np.zeros(7), None, duration=10.0, controller=law, dt=1 / 3000, substeps=2
    )
    theta = Q_D + elastic.link.gravity(Q_D) / elastic.K + tau_user / kp
    q = static_link_position(elastic, theta[None])[0]
    np.testing.assert_allclose(run.theta[-1], theta, rtol=0, atol=1e-8)
    np.testing.assert_allclose(run.q[-1], q, rtol=0, atol=1e-8)
    np.testing.assert_allclose(run.tau_J[-1], elastic.link.gravity(q), rtol=0, atol=1e-6)


def test_the_controller_uses_its_own_model() -> None:
    """A controller whose model carries a 0.5 kg payload the plant does not have (gravity
    "desired", K_T = 3, D_T = 1e-3 s) settles where the plant's link equation and the law
    balance at rest, K (theta - q) = g_p(q) and Kp (q_d + K^-1 g_c(q_d) - theta) + g_c(q_d) =
    K (theta - q), solved for q here with scipy's fsolve (residual < 1e-9 N m): q, theta within
    1e-8 rad (measured 1e-14). The model's error moves the rest far more: |q - q_d| > 1e-3 rad
    (measured 0.012)."""
    robot = dynid.models.kuka_lwr4()
    plant = lwr_elastic(robot)
    heavier = robot.with_payload(0.5, (0.0, 0.0, 0.1), np.diag([1e-3, 1e-3, 5e-4]))
    model = dynid.ElasticRobot(heavier, LWR_STIFFNESS, robot.Ia)
    kp = np.linspace(300.0, 500.0, 7)
    law = KukaLike(model, kp, 40.0, Q_D, torque_gain=3.0, torque_damping=1e-3, gravity="desired")
    run = simulate_elastic(
        plant, np.zeros(7), None, duration=10.0, controller=law, dt=1 / 3000, substeps=2
    )
    g_c = model.link.gravity(Q_D)

    def rest(q):
        theta = q + plant.link.gravity(q) / plant.K
        return kp * (Q_D + g_c / plant.K - theta) + g_c - plant.link.gravity(q)

    q = scipy.optimize.fsolve(rest, Q_D, xtol=1e-12)
    assert np.abs(rest(q)).max() < 1e-9
    np.testing.assert_allclose(run.q[-1], q, rtol=0, atol=1e-8)
    np.testing.assert_allclose(run.theta[-1], q + plant.link.gravity(q) / plant.K, atol=1e-8)
    assert np.abs(run.q[-1] - Q_D).max() > 1e-3


def test_without_torque_loop_it_is_the_motor_pd() -> None:
    """K_T = D_T = 0 and g_c(q_d): tau = Kp (theta_d - theta) - Kd thetad + g(q_d), MotorPD's law:
    the runs agree to 1e-12 relative (measured: identical), with motor Coulomb friction."""
    elastic = lwr_elastic(coulomb=True)
    kp = np.linspace(300.0, 500.0, 7)
    pd = simulate_elastic(
        elastic,
        np.zeros(7),
        None,
        duration=3.0,
        controller=MotorPD(kp, 40.0, Q_D),
        dt=1e-3,
        substeps=5,
    )
    kuka = simulate_elastic(
        elastic,
        np.zeros(7),
        None,
        duration=3.0,
        controller=KukaLike(elastic, kp, 40.0, Q_D, gravity="desired"),
        dt=1e-3,
        substeps=5,
    )
    for name in ("q", "qd", "theta", "thetad", "tau", "tau_J"):
        a, b = getattr(pd, name), getattr(kuka, name)
        np.testing.assert_allclose(b, a, rtol=0, atol=1e-12 * np.abs(a).max(), err_msg=name)


def storage(elastic, run, kp, torque_gain):
    """Albu-Schaeffer 2007's storage function of the closed loop (no friction, D_T = 0):
    1/2 qd^T M qd + 1/2 thetad^T B_theta thetad + 1/2 (theta - q)^T K (theta - q) + U_g(q)
    + 1/2 (theta - theta_d)^T Kp (theta - theta_d) - W(theta),
    W(theta) = U_g(qbar) + 1/2 (theta - qbar)^T K (theta - qbar), whose gradient is g(qbar)."""
    link = elastic.link
    theta_d = Q_D + link.gravity(Q_D) / elastic.K
    qbar = static_link_position(elastic, run.theta)
    W = link.potential_energy(qbar) + 0.5 * np.sum(elastic.K * (run.theta - qbar) ** 2, axis=1)
    B_theta = elastic.B / (1.0 + torque_gain)
    return (
        link.kinetic_energy(run.q, run.qd)
        + 0.5 * np.sum(B_theta * run.thetad**2, axis=1)
        + 0.5 * np.sum(elastic.K * (run.theta - run.q) ** 2, axis=1)
        + link.potential_energy(run.q)
        + 0.5 * np.sum(kp * (run.theta - theta_d) ** 2, axis=1)
        - W
    )


def test_closed_loop_storage_function_never_increases() -> None:
    """Passivity (no friction, D_T = 0, K_T = 3): V(t) - V(0) = -int thetad^T Kd thetad dt. The
    sampled run's balance error is below 1e-3 of V(0) at dt = 1e-4 s and halves with dt (the
    zero-order hold, first order: ratio in [1.8, 2.2]). V rises over no step by more than 1e-8 of
    V(0) at dt = 5e-5 s, and such rises (the held torque's own, largest at the start, where the
    damping has no velocity to act on yet) fall at least 3-fold when dt halves; V ends below 1 %
    of V(0)."""
    elastic = lwr_elastic(stiffness=5e3, viscous=False)
    kp, kd, torque_gain = 400.0, 40.0, 3.0
    law = KukaLike(elastic, kp, kd, Q_D, torque_gain=torque_gain)
    balance, rise = [], []
    for dt in (1e-4, 5e-5):
        run = simulate_elastic(
            elastic, np.zeros(7), None, duration=1.0, controller=law, dt=dt, substeps=1
        )
        V = storage(elastic, run, kp, torque_gain)
        power = kd * np.sum(run.thetad**2, axis=1)
        dissipated = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * dt)])
        balance.append(np.abs(V - V[0] + dissipated).max() / V[0])
        rise.append(np.diff(V).max() / V[0])
    assert balance[0] < 1e-3, balance
    assert 1.8 < balance[0] / balance[1] < 2.2, balance
    assert rise[1] < 1e-8 and rise[0] / rise[1] > 3.0, rise
    assert V[-1] < 1e-2 * V[0]


def test_torque_loop_scales_the_motor_inertia() -> None:
    """Plant B, Fv_m under K_T = 3 (D_T = 0) obeys the same equations as plant B / 4, Fv_m / 4
    without the loop (B_theta thetadd + tau_J + B_theta B^-1 tau_F = u): the runs agree up to the
    zero-order hold, the gap below 3e-4 rad on a 1 rad motion (measured 1.5e-4) and halving with
    dt (ratio in [1.7, 2.3]; measured 2.0)."""
    robot = dynid.models.kuka_lwr4()
    heavy = dynid.ElasticRobot(robot, LWR_STIFFNESS, robot.Ia, motor_viscous=robot.Fv)
    light = dynid.ElasticRobot(robot, LWR_STIFFNESS, robot.Ia / 4, motor_viscous=robot.Fv / 4)
    gaps = []
    for dt in (1e-4, 5e-5):
        a = simulate_elastic(
            heavy,
            np.zeros(7),
            None,
            duration=0.5,
            dt=dt,
            substeps=1,
            controller=KukaLike(heavy, 400.0, 40.0, Q_D, torque_gain=3.0),
        )
        b = simulate_elastic(
            light,
            np.zeros(7),
            None,
            duration=0.5,
            dt=dt,
            substeps=1,
            controller=KukaLike(heavy, 400.0, 40.0, Q_D),
        )
        gaps.append(max(np.abs(a.q - b.q).max(), np.abs(a.theta - b.theta).max()))
    assert gaps[0] < 3e-4, gaps
    assert 1.7 < gaps[0] / gaps[1] < 2.3, gaps


def paper_motion(t):
    return paper_validation_trajectory(t, 7)


def test_stiff_joints_approach_the_rigid_virtual_controller() -> None:
    """K = 1e4, 1e5, 1e6 N m/rad, B = Ia, motor friction = the rigid joints' friction, K_T = D_T
    = 0: the elastic track() (its controller at 3 kHz) approaches the rigid track() at 3 kHz on
    the first second of eq. (33). Recorded q: the gap falls by 10 per decade of K (ratio in
    [8, 12.5]; measured 10.4, 10.2), 2e-6 rad at 1e6. tau_J: the gap falls with K (measured 0.14,
    0.039, 0.021 N m) and is below 0.03 N m at 1e6 (0.08 % of the largest torque, 38.6 N m), but
    more slowly than 1/K: what remains is the spring's ringing after each held-torque step, whose
    size does not depend on K (docs/elastic.md)."""
    robot = dynid.models.kuka_lwr4()
    rigid = VirtualController(robot).track(paper_motion, 1.0, 3000.0)
    q_gaps, tau_gaps = [], []
    for K in (1e4, 1e5, 1e6):
        elastic = dynid.ElasticRobot(
            robot, K, robot.Ia, motor_viscous=robot.Fv, motor_coulomb=robot.Fs
        )
        controller = VirtualController(robot, elastic=elastic, torque_gain=0.0, torque_damping=0.0)
        run = controller.track(paper_motion, 1.0, 1000.0)
        np.testing.assert_allclose(run.t, rigid.t[::3], rtol=0, atol=1e-12)
        q_gaps.append(np.abs(run.q - rigid.q[::3]).max())
        tau_gaps.append(np.abs(run.tau - rigid.tau[::3]).max())
    assert all(8.0 < q_gaps[i] / q_gaps[i + 1] < 12.5 for i in range(2)), q_gaps
    assert q_gaps[-1] < 2e-6, q_gaps
    assert tau_gaps[0] > tau_gaps[1] > tau_gaps[2], tau_gaps
    assert tau_gaps[2] < 0.03, tau_gaps


def test_paper_torque_validation_errors_are_of_the_rigid_order() -> None:
    """The demo's pipeline (identification from static readings, eq. (33) tracked for 14 s,
    1 Hz filtering, torque errors) on the rigid and on the elastic LWR (K 5e3-1.5e4 N m/rad,
    default KUKA-like controller), same noise, no link-side friction: the largest torque error
    of each is within a factor 3 of the other's and below 0.05 N m (measured 0.016 and 0.007),
    the link tracking errors below 1e-2 rad."""
    truth = controller_model()
    noise = {"model_noise": 1e-5, "torque_noise": 0.05, "position_noise": 1e-5}
    static = VirtualController(truth, seed=0, **noise)
    readings = static.read_static(static.random_configurations(100))
    ident = identify_from_controller(dynid.models.kuka_lwr4(), readings.q, readings.g, readings.M)
    errors = {}
    for name, elastic in (("rigid", None), ("elastic", lwr_elastic(truth, coulomb=True))):
        controller = VirtualController(truth, seed=1, elastic=elastic, **noise)
        recording = controller.track(paper_motion, 14.0, 1000.0)
        assert np.abs(recording.motion.q - recording.q_desired).max() < 1e-2
        _, _, _, tau, tau_hat = torque_validation(recording, ident)
        errors[name] = error_metrics(tau, tau_hat)["max_abs"].max()
    assert max(errors.values()) < 0.05, errors
    assert 1 / 3 < errors["elastic"] / errors["rigid"] < 3, errors


def test_elastic_recording_is_the_spring_torque_and_static_readings_are_unchanged() -> None:
    """tau of the elastic track() is K (theta - q) at the recorded instants (noise-free, 1e-12);
    read_static is the same with or without the option (same seed: identical)."""
    robot = dynid.models.kuka_lwr4()
    elastic = lwr_elastic(robot)
    run = VirtualController(robot, elastic=elastic).track(paper_motion, 0.2, 1000.0)
    motion = run.motion
    np.testing.assert_allclose(
        run.tau, elastic.K * (motion.theta - motion.q), rtol=0, atol=1e-12 * np.abs(run.tau).max()
    )
    assert run.q.shape == (201, 7) and np.array_equal(run.q, motion.q)
    # encoder_counts quantises the recorded q (2 pi / counts) and nothing else
    counts = 2.0**20
    coarse = VirtualController(robot, elastic=elastic, encoder_counts=counts)
    quantised = coarse.track(paper_motion, 0.2, 1000.0)
    step = 2.0 * np.pi / counts
    np.testing.assert_allclose(quantised.q / step, np.round(quantised.q / step), rtol=0, atol=1e-6)
    assert np.abs(quantised.q - quantised.motion.q).max() <= 0.5 * step * (1 + 1e-9)
    np.testing.assert_array_equal(quantised.tau, run.tau)
    q = np.random.default_rng(3).uniform(-1, 1, (5, 7))
    a = VirtualController(robot, model_noise=1e-3, seed=4).read_static(q)
    b = VirtualController(robot, model_noise=1e-3, seed=4, elastic=elastic).read_static(q)
    assert np.array_equal(a.g, b.g) and np.array_equal(a.M, b.M) and np.array_equal(a.q, b.q)


def test_bad_arguments_name_the_argument() -> None:
    robot = dynid.models.kuka_lwr4()
    elastic = lwr_elastic(robot)

    def run(**changes):
        options = {"model": elastic, "kp": 400.0, "kd": 40.0, "reference": Q_D}
        options.update(changes)
        simulate_elastic(elastic, np.zeros(7), duration=0.01, controller=KukaLike(**options))

    with pytest.raises(ValueError, match=r"^gravity:"):
        run(gravity="link")
    with pytest.raises(ValueError, match=r"^model:"):
        run(model=robot)
    with pytest.raises(ValueError, match=r"^torque_gain:"):
        run(torque_gain=-1.0)
    with pytest.raises(ValueError, match=r"^torque_damping:"):
        run(torque_damping=[1.0, 2.0])
    with pytest.raises(ValueError, match=r"^tau_user:"):
        run(tau_user=np.zeros((3, 7)))
    with pytest.raises(ValueError, match=r"^reference"):
        run(reference=np.zeros(6))
    soft = lwr_elastic(robot, stiffness=1.0)  # 1 N m/rad cannot hold the arm's gravity
    with pytest.raises(RuntimeError, match=r"static link position .* did not converge"):
        simulate_elastic(elastic, np.zeros(7), duration=0.01, controller=KukaLike(soft, 1, 1, Q_D))
    with pytest.raises(ValueError, match=r"^elastic:"):
        VirtualController(robot, elastic=robot)
    with pytest.raises(ValueError, match=r"^link_friction:"):
        VirtualController(robot, elastic=elastic, link_friction=0.25)
    with pytest.raises(ValueError, match=r"^torque_gain:"):
        VirtualController(robot, elastic=elastic, torque_gain=-3.0)
