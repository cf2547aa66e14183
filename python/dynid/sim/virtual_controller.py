"""A virtual robot controller that reports what the KUKA LWR's interface reports.

The LWR's Fast Research Interface returns, for the current link position q, the numeric link
inertia matrix M(q) and gravity vector g(q) of the controller's own model, and the elastic joint
torques tau_J measured by the joint torque sensors (paper, Sect. II and eqs. (1)-(3), (7)). For
any :class:`~dynid.Robot` this class produces the same kinds of data, so that the paper's pipeline
can be run, tested and demonstrated without the hardware.

Static readings are the link equation (7), M qdd + c + g = tau_J, of the robot with its drive
terms removed (rotor inertias and friction act on the motor side of the elastic joints).

A commanded motion (:meth:`VirtualController.track`, the torque validation experiment of paper
eq. (33)) is simulated in closed loop (:func:`dynid.sim.simulate`): a 1 kHz joint position
controller (PD + gravity compensation of the controller's model, like FRI's
JointPositionController) drives the whole robot, rotor inertias and friction included, in the
rigid-joint limit of eqs. (1)-(3) (theta = q). The torque sensor sits between the gear and the
link, so it measures the link equation plus the part of the friction that acts on the link side
of it (output bearings), ``link_friction`` times the robot's Fv qd + Fs sgn(qd):

    tau_J = M(q) qdd + c(q, qd) + g(q) + rho F(qd)        (eq. (7) plus link-side friction)

plus the sensor's noise. Unlike a perfectly tracked motion, this shows what the paper's torque
validation shows on the real robot: a tracking error, measured positions that are not the
desired ones, and torque errors of the identified model, which has no friction, of a few tenths
of a N m at the joints with the largest friction.

With ``elastic=`` a :class:`~dynid.ElasticRobot`, :meth:`VirtualController.track` simulates the
elastic joints instead (paper eqs. (1)-(3), :func:`dynid.sim.simulate_elastic`) under the
KUKA-like joint torque controller (:class:`dynid.sim.KukaLike`: motor-side impedance law with
the controller's gravity, inner torque loop of gain ``torque_gain``) run at
:data:`TORQUE_LOOP_FACTOR` times the recording rate, and tau_J is the spring torque
K (theta - q) plus the sensor's noise: what GetMeasuredJointTorques returns.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from ..model.elastic import ElasticRobot
from ..model.robot import Robot
from .closed_loop import Simulation, plant_friction, simulate
from .controllers import PDGravity, sample_reference
from .controllers import gains as check_gains
from .elastic_joints import ElasticSimulation, KukaLike, simulate_elastic

Trajectory = Callable[[NDArray[np.float64]], tuple[NDArray, NDArray, NDArray]]


@dataclass(frozen=True)
class StaticReadings:
    """What the controller returns at a list of configurations."""

    q: NDArray[np.float64]  #: (N, n) measured link positions
    g: NDArray[np.float64]  #: (N, n) numeric gravity vectors
    M: NDArray[np.float64]  #: (N, n, n) numeric link inertia matrices


@dataclass(frozen=True)
class TorqueRecording:
    """Measured link positions and joint torques along a commanded motion."""

    t: NDArray[np.float64]  #: (T,) seconds
    q: NDArray[np.float64]  #: (T, n) measured link positions
    tau: NDArray[np.float64]  #: (T, n) measured elastic joint torques tau_J
    q_desired: NDArray[np.float64]  #: (T, n) the commanded positions
    #: the closed-loop run (true q, qd, the commanded torques; an ElasticSimulation with theta,
    #: thetad, tau_J at the recording rate when the joints are elastic)
    motion: Simulation | ElasticSimulation


#: Closed-loop bandwidth [rad/s] of the default position controller: each joint's PD gains put
#: its poles at -omega (critically damped) for its inertia M_ii at the start of the motion.
TRACKING_BANDWIDTH = 30.0
#: Coulomb smoothing band [rad/s] of the simulated plant (dynid.sim.simulate's coulomb_band).
COULOMB_BAND = 1e-3
#: Default gain K_T of the KUKA-like controller's torque loop (elastic joints): the motor inertia
#: seen by the impedance law is B / (1 + K_T).
KUKA_TORQUE_GAIN = 3.0
#: Default D_T [s] of the torque loop: the torque-derivative feedback -D_T tau_J' damps the joints'
#: own vibration, which the sampled torque loop excites (without it K_T = 3 diverges on the LWR's
#: wrist at 3 kHz; docs/elastic.md).
KUKA_TORQUE_DAMPING = 1e-3
#: The elastic joints' controller runs this many times faster than the recording (the KR C2's
#: joint controllers run at 3 kHz under the FRI's 1 kHz): it keeps the sampled torque loop stable.
TORQUE_LOOP_FACTOR = 3
#: Largest RK4 step, as a fraction of the period of the fastest spring oscillation.
SPRING_STEP = 0.05


class VirtualController:
    """Controller-like data for any robot, with optional Gaussian noise and a seed.

    Parameters
    ----------
    robot
        The arm whose controller is simulated. Static readings use its links only (the link
        equation (7)); :meth:`track` simulates the whole robot, rotor inertias and friction
        included.
    model_noise
        Relative standard deviation of the errors on the numeric M(q) and g(q): these are the
        controller's own model evaluated numerically, so their errors scale with the values and
        elements that are identically zero stay zero (as the paper found for M_76).
    torque_noise
        Standard deviation [N m] of the joint torque sensor noise.
    position_noise
        Standard deviation [rad or m] of the link position measurement noise.
    link_friction
        Fraction (a scalar or one per joint, in [0, 1]) of the robot's joint friction Fv, Fs that
        acts on the link side of the torque sensor and therefore appears in tau_J (0: none, the
        link equation (7) alone; 1: all of it).
    encoder_counts
        Resolution of the link position sensors in counts per revolution, seen by the position
        controller and in the recorded q (None: exact).
    seed
        Seed of the random generator (configurations and noise).
    elastic
        None (rigid joints), or the elastic-joint plant (:class:`~dynid.ElasticRobot`, same joint
        count) that :meth:`track` simulates under the KUKA-like controller; its stiffness is the
        controller's too. Needs ``link_friction=0`` (the elastic plant's friction is on the motor
        side, outside tau_J). ``encoder_counts`` then quantises the recorded q only (the
        controller uses the motor positions).
    torque_gain, torque_damping
        K_T and D_T of the KUKA-like torque loop (a number or one per joint, >= 0), elastic
        joints only.
    """

    def __init__(
        self,
        robot: Robot,
        *,
        model_noise: float = 0.0,
        torque_noise: float = 0.0,
        position_noise: float = 0.0,
        link_friction: ArrayLike = 0.0,
        encoder_counts: float | None = None,
        seed: int | None = 0,
        elastic: ElasticRobot | None = None,
        torque_gain: ArrayLike = KUKA_TORQUE_GAIN,
        torque_damping: ArrayLike = KUKA_TORQUE_DAMPING,
    ) -> None:
        checks.robot(robot)
        for name, value in (
            ("model_noise", model_noise),
            ("torque_noise", torque_noise),
            ("position_noise", position_noise),
        ):
            if not (np.isfinite(value) and value >= 0.0):
                raise ValueError(f"{name}: expected a finite value >= 0, got {value!r}")
        fraction = real_array(link_friction, "link_friction")
        if fraction.ndim == 0:
            fraction = np.full(robot.n, float(fraction))
        if fraction.shape != (robot.n,) or np.any((fraction < 0.0) | (fraction > 1.0)):
            raise ValueError(
                f"link_friction: expected a fraction in [0, 1], scalar or shape ({robot.n},), "
                f"got {link_friction!r}"
            )
        # At least one count per revolution, as the simulator requires (cpp/src/simulator.cpp):
        # a coarser encoder reports a constant position.
        if encoder_counts is not None and not (
            _positive_number(encoder_counts) and float(encoder_counts) >= 1.0
        ):
            raise ValueError(
                "encoder_counts: expected at least 1 count per revolution (per metre) or None, "
                f"got {encoder_counts!r}"
            )
        if elastic is not None:
            if not isinstance(elastic, ElasticRobot) or elastic.n != robot.n:
                raise ValueError(
                    f"elastic: expected None or a dynid.ElasticRobot with {robot.n} joints, got "
                    f"{elastic!r}"
                )
            if np.any(fraction != 0.0):
                raise ValueError(
                    "link_friction: expected 0 with elastic joints (their friction acts on the "
                    f"motor side, outside tau_J), got {link_friction!r}"
                )
        self.elastic = elastic
        self.torque_gain = check_gains(torque_gain, "torque_gain", robot.n)
        self.torque_damping = check_gains(torque_damping, "torque_damping", robot.n)
        self.plant = robot.copy()
        self.robot = robot.rigid_body()
        self.model_noise = float(model_noise)
        self.torque_noise = float(torque_noise)
        self.position_noise = float(position_noise)
        self.link_friction = fraction
        self.encoder_counts = encoder_counts
        self.seed = seed
        self.rng = np.random.default_rng(seed)

    def random_configurations(self, count: int) -> NDArray[np.float64]:
        """``count`` configurations drawn uniformly within the joint limits (paper, Sect. VI)."""
        if int(count) < 1:
            raise ValueError(f"count: expected a positive number of configurations, got {count!r}")
        low, high = self.robot.qlim[:, 0], self.robot.qlim[:, 1]
        return low + (high - low) * self.rng.random((int(count), self.robot.n))

    def read_static(self, q: ArrayLike) -> StaticReadings:
        """The numeric g(q) and M(q) at each configuration (GetCurrentGravityVector and
        GetCurrentMassMatrix), with the measured position."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        g = self._model_error(self.robot.gravity(q))
        M = self._model_error(self.robot.mass_matrix(q))
        M = 0.5 * (M + np.swapaxes(M, -1, -2))  # the controller's M is symmetric
        return StaticReadings(q=self._measure_position(q), g=g, M=M)

    def track(
        self,
        trajectory: Trajectory,
        duration: float,
        rate: float = 1000.0,
        *,
        gains: tuple[ArrayLike, ArrayLike] | None = None,
        substeps: int | None = None,
    ) -> TorqueRecording:
        """Track a commanded motion in closed loop and record q and tau_J at ``rate`` Hz.

        ``trajectory(t)`` returns the desired (q, qd, qdd) for the times t (T,), each (T, n); the
        robot starts on it at rest or moving as it says. The position controller (PD + gravity
        compensation of the controller's model, at ``rate``) has the gains ``(kp, kd)`` or, by
        default, critically damped gains of bandwidth :data:`TRACKING_BANDWIDTH` for the inertia
        at the start. The plant is integrated by RK4 with ``substeps`` steps per period; by
        default as many as the friction band needs for a stable explicit step (2 at 1 kHz for the
        LWR-IV, see :func:`stable_substeps`).
        """
        if not (np.isfinite(duration) and duration > 0.0):
            raise ValueError(f"duration: expected a positive time, got {duration!r}")
        if not (np.isfinite(rate) and rate > 0.0):
            raise ValueError(f"rate: expected a sampling rate > 0, got {rate!r}")
        periods = max(round(duration * rate), 1)
        t = np.arange(periods + 1) / rate
        q_d, qd_d, qdd_d = sample_reference(trajectory, t, self.robot.n, "trajectory")
        if self.elastic is not None:
            return self._track_elastic(trajectory, periods, rate, gains, substeps)
        if gains is None:
            inertia = np.diag(self.plant.mass_matrix(q_d[0]))
            kp, kd = TRACKING_BANDWIDTH**2 * inertia, 2.0 * TRACKING_BANDWIDTH * inertia
        else:
            if not (isinstance(gains, tuple) and len(gains) == 2):
                raise ValueError(f"gains: expected a tuple (kp, kd), got {gains!r}")
            kp = check_gains(gains[0], "kp", self.robot.n)
            kd = check_gains(gains[1], "kd", self.robot.n)
        if substeps is None:
            substeps = stable_substeps(self.plant, q_d[0], 1.0 / rate, COULOMB_BAND, kd)
        run = simulate(
            self.plant,
            q_d[0],
            qd_d[0],
            periods / rate,
            PDGravity(self.robot, kp, kd, (q_d, qd_d, qdd_d)),
            dt=1.0 / rate,
            substeps=substeps,
            coulomb_band=COULOMB_BAND,
            encoder_counts=self.encoder_counts,
        )
        # The sensor between gear and link: link equation (7) plus the link-side friction.
        tau = self.robot.rnea(run.q, run.qd, run.qdd)
        tau += self.link_friction * plant_friction(self.plant, run.qd, COULOMB_BAND)
        if self.torque_noise > 0.0:
            tau = tau + self.torque_noise * self.rng.standard_normal(tau.shape)
        return TorqueRecording(
            t=t, q=self._measure_position(run.q_measured), tau=tau, q_desired=q_d, motion=run
        )

    def _track_elastic(
        self,
        trajectory: Trajectory,
        periods: int,
        rate: float,
        gains: tuple[ArrayLike, ArrayLike] | None,
        substeps: int | None,
    ) -> TorqueRecording:
        """track() on the elastic plant: the KUKA-like controller at TORQUE_LOOP_FACTOR * rate,
        recorded at ``rate``; tau_J = K (theta - q) plus the sensor noise."""
        elastic = self.elastic
        assert elastic is not None
        n, factor = elastic.n, TORQUE_LOOP_FACTOR
        dt = 1.0 / (rate * factor)
        t_fine = np.asarray(np.arange(periods * factor + 1) * dt, dtype=np.float64)
        q_d, qd_d, qdd_d = sample_reference(trajectory, t_fine, n, "trajectory")
        # The inertia the impedance law moves: the links' and the shaped motor's, B / (1 + K_T).
        inertia = np.diag(elastic.link.mass_matrix(q_d[0])) + elastic.B / (1.0 + self.torque_gain)
        kp, kd = self._gains(gains, inertia)
        if substeps is None:
            substeps = elastic_substeps(
                elastic, q_d[0], dt, COULOMB_BAND, self.torque_gain, kd, self.torque_damping
            )
        run = simulate_elastic(
            elastic,
            q_d[0],
            None,  # the springs start at the static deflection of q_d(0)
            qd_d[0],
            qd_d[0],
            periods * factor * dt,
            KukaLike(
                elastic,
                kp,
                kd,
                (q_d, qd_d, qdd_d),
                torque_gain=self.torque_gain,
                torque_damping=self.torque_damping,
            ),
            dt=dt,
            substeps=substeps,
            coulomb_band=COULOMB_BAND,
        )
        keep = slice(None, None, factor)
        motion = ElasticSimulation(
            *(
                getattr(run, name)[keep]
                for name in ("t", "q", "qd", "theta", "thetad", "tau", "tau_J")
            )
        )
        tau = motion.tau_J
        if self.torque_noise > 0.0:
            tau = tau + self.torque_noise * self.rng.standard_normal(tau.shape)
        q = motion.q
        if self.encoder_counts is not None:
            # As dynid.sim.simulate: 2 pi / counts rad (revolute), 1 / counts m (prismatic).
            revolute = np.array([kind == "R" for kind in self.robot.joint_types])
            step = np.where(revolute, 2.0 * np.pi, 1.0) / float(self.encoder_counts)
            q = step * np.round(q / step)
        return TorqueRecording(
            t=motion.t,
            q=self._measure_position(q),
            tau=tau,
            q_desired=q_d[keep],
            motion=motion,
        )

    def _gains(
        self, gains: tuple[ArrayLike, ArrayLike] | None, inertia: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(kp, kd): the given ones, checked, or critically damped ones of bandwidth
        TRACKING_BANDWIDTH for ``inertia``."""
        if gains is None:
            return TRACKING_BANDWIDTH**2 * inertia, 2.0 * TRACKING_BANDWIDTH * inertia
        if not (isinstance(gains, tuple) and len(gains) == 2):
            raise ValueError(f"gains: expected a tuple (kp, kd), got {gains!r}")
        return check_gains(gains[0], "kp", self.robot.n), check_gains(gains[1], "kd", self.robot.n)

    def _model_error(self, values: NDArray[np.float64]) -> NDArray[np.float64]:
        if self.model_noise == 0.0:
            return values
        return values * (1.0 + self.model_noise * self.rng.standard_normal(values.shape))

    def _measure_position(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        if self.position_noise == 0.0:
            return q.copy()
        return q + self.position_noise * self.rng.standard_normal(q.shape)


def _positive_number(value: object) -> bool:
    if isinstance(value, (bool, np.bool_)):
        return False
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False
    return bool(np.isfinite(number) and number > 0.0)


def stable_substeps(
    robot: Robot, q: ArrayLike, dt: float, coulomb_band: float, kd: ArrayLike = 0.0
) -> int:
    """Integration steps per control period dt that keep explicit RK4 stable near qd = 0.

    There the friction and the controller's damping act as a viscous term D = diag(Fv + Fs /
    band + Kd) (with coupled drives T^T diag(Fv + Fs / band) T + diag(Kd)), whose fastest mode
    decays at the largest eigenvalue of M^-1 D; RK4 is stable for rate * h < 2.78, and h is
    chosen for rate * h <= 2 (at the configuration q).
    """
    T = robot.transmission
    motor = T.T @ np.diag(robot.Fv + robot.Fs / coulomb_band) @ T
    damping = motor + np.diag(np.broadcast_to(np.asarray(kd, dtype=float), (robot.n,)))
    L = np.linalg.cholesky(robot.mass_matrix(q))
    scaled = np.linalg.solve(L, np.linalg.solve(L, damping).T)  # L^-1 D L^-T
    rate = float(np.linalg.eigvalsh(0.5 * (scaled + scaled.T))[-1])
    return max(1, int(np.ceil(dt * rate / 2.0)))


def elastic_substeps(
    elastic: ElasticRobot,
    q: ArrayLike,
    dt: float,
    coulomb_band: float,
    torque_gain: ArrayLike = 0.0,
    kd: ArrayLike = 0.0,
    torque_damping: ArrayLike = 0.0,
) -> int:
    """RK4 steps per control period dt of an elastic run under :class:`KukaLike`: the step
    resolves the fastest spring oscillation (a :data:`SPRING_STEP` of its period, motors of the
    shaped inertia B / (1 + K_T)) and the motor damping near rest (Kd through the torque loop,
    the friction band, D_T K; rate * h <= 2 as in :func:`stable_substeps`)."""
    gain = 1.0 + np.asarray(torque_gain, dtype=float)
    # Undamped links and motors on the springs, shaped motor inertia: the largest frequency.
    n = elastic.n
    K = np.diag(elastic.K)
    mass = np.zeros((2 * n, 2 * n))
    mass[:n, :n] = elastic.link.mass_matrix(q)
    mass[n:, n:] = np.diag(elastic.B / gain)
    stiffness = np.block([[K, -K], [-K, K]])
    L = np.linalg.cholesky(mass)
    scaled = np.linalg.solve(L, np.linalg.solve(L, stiffness).T)  # L^-1 S L^-T
    omega = float(np.sqrt(max(np.linalg.eigvalsh(0.5 * (scaled + scaled.T))[-1], 0.0)))
    spring = dt * omega / (2.0 * np.pi * SPRING_STEP)
    # Motor equation near rest: B thetadd = -((1 + K_T) Kd + Fv_m + Fs_m / band + D_T K) thetad.
    friction = elastic.Fv_m + elastic.Fs_m / coulomb_band
    damping = np.asarray(kd, dtype=float) * gain + friction
    damping = damping + np.asarray(torque_damping, dtype=float) * elastic.K
    motor = dt * float(np.max(damping / elastic.B)) / 2.0
    return max(1, int(np.ceil(max(spring, motor))))


def paper_validation_trajectory(
    t: NDArray[np.float64], n: int = 7, amplitude: float = np.pi / 2, period: float = 14.0
) -> tuple[NDArray, NDArray, NDArray]:
    """The torque validation motion of paper eq. (33): every joint follows
    q(t) = pi/2 cos(pi t / 7), from q = pi/2 at rest and back, T = 14 s."""
    w = 2.0 * np.pi / period
    t = np.asarray(t, dtype=float)[:, None]
    q = amplitude * np.cos(w * t)
    qd = -amplitude * w * np.sin(w * t)
    qdd = -amplitude * w**2 * np.cos(w * t)
    ones = np.ones((1, n))
    return q * ones, qd * ones, qdd * ones


#: The final validation experiment of the paper (Sect. VI, Fig. 5): "sinusoidal reference
#: trajectories of different frequency and amplitude have been imposed during 1 minute to each
#: joint", M(q) and g(q) read from FRI every 120 ms (500 samples). The paper shows the motion only
#: as a figure: these amplitudes [rad] and periods [s] are ours, within the LWR-IV's ranges.
FIG5_AMPLITUDES = (0.9, 0.8, 1.0, 1.1, 1.2, 1.0, 1.5)
FIG5_PERIODS = (30.0, 20.0, 15.0, 12.0, 10.0, 7.5, 6.0)
#: Its sampling: every 120 ms for one minute.
FIG5_SAMPLE_TIME = 0.12
FIG5_DURATION = 60.0


def paper_final_validation_trajectory(t: ArrayLike) -> tuple[NDArray, NDArray, NDArray]:
    """The 7 joints' sinusoids of the paper's final validation experiment (Fig. 5): joint j
    follows A_j sin(2 pi t / T_j) with ``FIG5_AMPLITUDES`` and ``FIG5_PERIODS``; (q, qd, qdd),
    (T, 7) each."""
    a = np.asarray(FIG5_AMPLITUDES)
    w = 2.0 * np.pi / np.asarray(FIG5_PERIODS)
    t = np.asarray(t, dtype=float)[:, None]
    return a * np.sin(w * t), a * w * np.cos(w * t), -a * w**2 * np.sin(w * t)
