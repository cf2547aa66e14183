"""Physically consistent identification on the real KUKA LWR4+ logs (docs/real_data.md,
"Physically consistent identification").

As tests/test_real_data.py: train on measurements_1, validate on measurements_2, from sample 500
on; rigid body + rotor + friction + one torque offset per joint, WLS. The physical fit has the
prior examples/kuka_lwr4_urdf_prior.json (the LWR4 URDF's inertial parameters in the DH frames of
dynid.models.kuka_lwr4(); checked here against the arm's own DH table and the URDF parameters of
tests/data/kuka_lwr4_dh.json) with the default prior_weight.

Two column sets are measured: the strict one above, and the same plus the position torque
ks_j sin q_j + kc_j cos q_j (``position_torque=True``; joints 1, 3-7, joint 2 being gravity), for
BOTH fits. The ratio bounds state where the issue's 1.25 holds: in the strict set on A2-A6 only;
with the position torque on A1-A6 (A7: 1.95).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.identification.log_identification import DEFAULT_PRIOR_WEIGHT, identify_log, validate_log
from real_logs import DATA, lwr4_logs

PRIOR = Path(__file__).parent.parent / "examples" / "kuka_lwr4_urdf_prior.json"
OPTIONS = {"rotor": True, "friction": True, "offset": True, "method": "wls"}

#: Validation relative RMS per joint of the unconstrained fit (tests/test_real_data.py) and of
#: the physical one (prior_weight 1e-5), measured; guards at rtol 0.05 (see EXPECTED there).
UNCONSTRAINED = np.array([0.1483, 0.00862, 0.0741, 0.0207, 0.2189, 0.2976, 0.2165])
PHYSICAL = np.array([0.2249, 0.00893, 0.0868, 0.0214, 0.2505, 0.3513, 0.8605])

#: Ratio physical / unconstrained that holds on each joint. The issue asks for 1.25 on every
#: joint; A1 (1.52) and A7 (3.97) cannot meet it (docs/real_data.md: the unconstrained fit reaches
#: its A1 and A7 errors only through parameters no rigid body has, e.g. Ia7 = -1.04 kg m^2 and
#: Iyy3 + Izz4 = -3.9 kg m^2).
RATIO_BOUND = np.array([1.6, 1.25, 1.25, 1.25, 1.25, 1.25, 4.2])

#: The same with the position torque in both fits (docs/real_data.md, "Position torque"),
#: measured; guards at rtol 0.05. A1-A6 within the issue's 1.25, A7 at 1.95: the unconstrained
#: fit's remaining A7 advantage is products of inertia of the 0.3 kg hand no rigid body has
#: (Ixy7 = 0.31 kg m^2 with Izz7 = 0.045 kg m^2), not a function of q7 (the physical residual
#: is uncorrelated with q7, sin q7, cos q7, qd7, sign qd7: test below).
UNCONSTRAINED_POSITION = np.array([0.1495, 0.00862, 0.0774, 0.0206, 0.2183, 0.2418, 0.0872])
PHYSICAL_POSITION = np.array([0.1823, 0.00902, 0.0773, 0.0208, 0.2640, 0.2932, 0.1696])
RATIO_BOUND_POSITION = np.array([1.25, 1.25, 1.25, 1.25, 1.25, 1.25, 2.05])


@pytest.fixture(scope="module")
def logs():
    return lwr4_logs()


@pytest.fixture(scope="module")
def lwr():
    return dynid.models.kuka_lwr4()


@pytest.fixture(scope="module")
def fits(logs, lwr):
    train, check = logs
    ls = identify_log(train, lwr, **OPTIONS)
    physical = identify_log(train, lwr, **OPTIONS, physical=True, prior=PRIOR)
    return ls, physical, validate_log(ls, check), validate_log(physical, check)


@pytest.fixture(scope="module")
def position_fits(logs, lwr):
    train, check = logs
    ls = identify_log(train, lwr, **OPTIONS, position_torque=True)
    physical = identify_log(train, lwr, **OPTIONS, position_torque=True, physical=True, prior=PRIOR)
    return ls, physical, validate_log(ls, check), validate_log(physical, check)


def test_the_prior_file_is_the_urdf_in_the_frames_of_kuka_lwr4(lwr):
    """The prior's rigid-body torques equal those of the arm's own standard DH table (d1 =
    0.3105, d7 = 0.078) with the URDF parameters of tests/data/kuka_lwr4_dh.json at random
    states, to 1e-12 N m: the same links, the parameters re-expressed exactly."""
    source = json.loads((DATA / "kuka_lwr4_dh.json").read_text())
    rows = source["dh"]["standard"]["rows"]
    urdf = dynid.Robot.from_dh(
        [[r["a"], r["alpha"], r["d"], r["theta_offset"]] for r in rows],
        params=source["params"]["kuka_lwr4.urdf (HEAD)"]["standard"],
    )
    prior = dynid.load_model(PRIOR)
    np.testing.assert_array_equal(prior.dh, lwr.dh)
    rng = np.random.default_rng(0)
    q = lwr.random_configurations(50, seed=0)
    qd, qdd = rng.uniform(-2, 2, (2, 50, 7))
    np.testing.assert_allclose(
        prior.rigid_body().rnea(q, qd, qdd), urdf.rnea(q, qd, qdd), rtol=0, atol=1e-12
    )
    assert prior.is_physically_consistent()
    urdf_joints = source["joints"]
    np.testing.assert_array_equal(prior.Fv, [j["urdf_damping_HEAD"] for j in urdf_joints])
    np.testing.assert_array_equal(prior.Fs, [j["urdf_friction_HEAD"] for j in urdf_joints])


def test_physical_fit_validates_close_to_the_unconstrained_one(fits):
    _ls, physical, ls_metrics, metrics = fits
    np.testing.assert_allclose(ls_metrics["relative_rms"], UNCONSTRAINED, rtol=0.05)
    np.testing.assert_allclose(metrics["relative_rms"], PHYSICAL, rtol=0.05)  # guard
    assert np.all(metrics["relative_rms"] <= RATIO_BOUND * ls_metrics["relative_rms"])
    assert physical.physical["status"] == "optimal"
    assert physical.physical["prior_weight"] == DEFAULT_PRIOR_WEIGHT
    # The masses stay near the URDF's (2.7, 2.7, 2.7, 2.7, 1.7, 1.6, 0.3 kg; 14.4 in total).
    masses = physical.robot.params[:, 0]
    assert abs(masses.sum() - 14.4) < 0.5
    np.testing.assert_allclose(masses, [2.7, 2.7, 2.7, 2.7, 1.7, 1.6, 0.3], atol=0.65)


def test_with_the_position_torque_the_physical_fit_is_within_1_25_except_on_a7(position_fits, fits):
    """Both fits with the position torque: the table of docs/real_data.md (guard rtol 0.05),
    the ratio within 1.25 on A1-A6 (A7: 1.95, bound 2.05); and the physical fit with it is within
    1.25 x of the strict unconstrained fit (no position torque) on every joint (measured at most
    1.23, A1), better than it on A6 and A7 (A7: 17.0 % against 21.7 %)."""
    ls, physical, ls_metrics, metrics = position_fits
    assert ls.position_joints == physical.position_joints == (0, 2, 3, 4, 5, 6)
    np.testing.assert_allclose(ls_metrics["relative_rms"], UNCONSTRAINED_POSITION, rtol=0.05)
    np.testing.assert_allclose(metrics["relative_rms"], PHYSICAL_POSITION, rtol=0.05)  # guard
    ratio = metrics["relative_rms"] / ls_metrics["relative_rms"]
    assert np.all(ratio <= RATIO_BOUND_POSITION) and ratio[6] > 1.25  # the A7 gap, stated
    strict = fits[2]["relative_rms"]
    assert np.all(metrics["relative_rms"] <= 1.25 * strict)
    assert np.all(metrics["relative_rms"][5:] < strict[5:])
    assert physical.physical["status"] == "optimal"
    assert physical.robot.is_physically_consistent()
    masses = physical.robot.params[:, 0]
    assert abs(masses.sum() - 14.4) < 0.5


def test_position_torque_takes_what_the_negative_inertia_stood_for(fits, position_fits, logs):
    """On these logs q_j = c_j + A_j sin(0.5 t + phi) (one harmonic, two phases), so
    qdd_j = -0.25 (q_j - c_j) to within the differentiation noise (4 % of qdd7) and a negative
    Ia7 is a torque +0.25 |Ia7| (q7 - c7). The strict physical fit's A7 residual correlates
    with q7 (|corr| > 0.8); with the position torque, no correlation above 0.15 with q, sin q,
    cos q, qd or sign qd is left on A1 and A7 (training log), and its ks7 (0.33 N m) is the
    strict unconstrained fit's -0.25 Ia7 (0.26 N m/rad, within 30 %)."""
    strict_ls, strict, _, _ = fits
    _, physical, _, _ = position_fits
    log = strict.log
    qdd7 = log.qdd[:, 6]
    fit = np.polyfit(log.q[:, 6], qdd7, 1)
    assert abs(fit[0] + 0.25) < 0.005
    assert np.std(qdd7 - np.polyval(fit, log.q[:, 6])) < 0.05 * np.std(qdd7)
    residual = log.tau - strict.regressor(log.q, log.qd, log.qdd) @ strict.theta
    assert np.corrcoef(residual[:, 6], log.q[:, 6])[0, 1] > 0.8
    residual = log.tau - physical.regressor(log.q, log.qd, log.qdd) @ physical.theta
    for j in (0, 6):
        q, qd = log.q[:, j], log.qd[:, j]
        for feature in (q, np.sin(q), np.cos(q), qd, np.sign(qd)):
            assert abs(np.corrcoef(residual[:, j], feature)[0, 1]) < 0.15
    ia7 = strict_ls.theta[strict_ls.names.index("Ia7")]
    ks7 = physical.theta[physical.names.index("ks7")]
    assert ia7 < -0.9 and abs(ks7 - 0.25 * -ia7) < 0.3 * ks7


def test_the_urdf_itself_is_the_same_prior(fits, logs, lwr):
    """prior = the LWR4 URDF file (read by Robot.from_urdf, mapped to kuka_lwr4()'s frames by the
    fit): the same identified model as with the prior file (predictions to 1e-6 of the
    torques; the solver's tolerance)."""
    _, physical, _, _ = fits
    train, check = logs
    urdf = identify_log(
        train, lwr, **OPTIONS, physical=True, prior=DATA / "urdf" / "kuka_lwr4.urdf"
    )
    np.testing.assert_allclose(
        urdf.predict(check), physical.predict(check), rtol=0, atol=1e-6 * np.abs(check.tau).max()
    )


def test_physical_model_is_usable_where_the_unconstrained_one_is_not(fits, lwr):
    """The unconstrained base values mapped to standard parameters (minimum norm) give an M(q)
    that is indefinite at every one of 2000 random q (the issue's observation); the physical
    robot is consistent and M(q) > 0 at all of them."""
    ls, physical, _, _ = fits
    q = lwr.random_configurations(2000, seed=4)
    standard = np.linalg.lstsq(ls.beta, ls.theta[: ls.count], rcond=None)[0]
    unconstrained = lwr.copy()
    unconstrained.params = standard[:70].reshape(7, 10)
    unconstrained.Ia, unconstrained.Fv, unconstrained.Fs = standard[70:].reshape(3, 7)
    assert np.all(np.linalg.eigvalsh(unconstrained.mass_matrix(q))[:, 0] < 0)
    robot = physical.robot
    assert robot.is_physically_consistent()
    assert np.linalg.eigvalsh(robot.mass_matrix(q))[:, 0].min() > 0


def joint_side_torque(result, q: np.ndarray) -> np.ndarray:
    """The torque of the result's extra columns at q: offsets (+ ks sin q + kc cos q)."""
    zeros = np.zeros((1, q.size))
    columns = result.regressor(q[None], zeros, zeros)[0, :, result.count :]
    return columns @ result.theta[result.count :]


def simulate(result, log, start: int, steps: int) -> np.ndarray:
    """Classic RK4 on the log's own time steps from the measured state at ``start``, driven by
    the measured torques (linear between samples) minus the result's offsets and position
    torque at the current q, with the identified robot; the q of each step."""
    robot, t, tau = result.robot, log.t, log.tau
    q, qd = log.q[start].copy(), log.qd[start].copy()
    out = [q]
    for k in range(start, start + steps):
        h = t[k + 1] - t[k]
        u0, u1 = tau[k], tau[k + 1]
        um = 0.5 * (u0 + u1)

        def f(q, qd, u):
            return qd, robot.forward_dynamics(q, qd, u - joint_side_torque(result, q))

        a = f(q, qd, u0)
        b = f(q + h / 2 * a[0], qd + h / 2 * a[1], um)
        c = f(q + h / 2 * b[0], qd + h / 2 * b[1], um)
        d = f(q + h * c[0], qd + h * c[1], u1)
        q = q + h / 6 * (a[0] + 2 * b[0] + 2 * c[0] + d[0])
        qd = qd + h / 6 * (a[1] + 2 * b[1] + 2 * c[1] + d[1])
        out.append(q)
    return np.array(out)


def test_simulating_the_physical_model_with_the_measured_torques(fits, logs):
    """Forward dynamics (RK4, the log's 5 ms steps) along the validation log with the measured
    torques, restarted from the measured state every second (22 windows of 200 steps): every
    step is finite (M(q) > 0 throughout). The open-loop drift after 1 s is reported in
    docs/real_data.md; bounds here: median over the windows below 30 degrees on A1-A4 (gravity
    and the big links), below 3000 degrees on the wrist (its unmodelled joint-7 torque spins the
    light hand: see the docs)."""
    _, physical, _, _ = fits
    median = median_drift(physical, logs[1])
    assert np.all(median[:4] < 30) and np.all(median < 3000)


def test_simulating_the_physical_model_with_its_position_torque(position_fits, logs):
    """As above, the position torque subtracted at the simulated q: every step finite; the
    median drift after 1 s, measured 7.5, 19, 9.3, 33, 13, 17, 8.1 degrees, is below 50 degrees
    on every joint: the hand no longer spins (A7: 2700 degrees without the position torque)."""
    _, physical, _, _ = position_fits
    median = median_drift(physical, logs[1])
    assert np.all(median < 50) and median[6] < 20


def median_drift(result, check) -> np.ndarray:
    """Median over the 1 s windows of |q_simulated - q_measured| after 1 s, degrees."""
    drift = []
    for start in range(0, check.T - 201, 200):
        q = simulate(result, check, start, 200)
        assert np.all(np.isfinite(q))
        drift.append(np.degrees(np.abs(q[-1] - check.q[start + 200])))
    return np.median(drift, axis=0)
