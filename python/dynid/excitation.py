"""Exciting trajectories for identification: finite Fourier series with optimised coefficients.

Notes, "Identification experiments": the motion must be "sufficiently exciting", i.e. explore the
workspace and involve every component of the dynamic model, and be periodic with multiple
frequency components. Following Swevers et al. (IEEE Trans. RA 13(5), 1997), joint i moves as

    q_i(t) = q0_i + sum_{l=1..H} a_il/(wf l) sin(wf l t) - b_il/(wf l) cos(wf l t)
    qd_i   =        sum_l a_il cos(wf l t) + b_il sin(wf l t)
    qdd_i  =        sum_l wf l (-a_il sin(wf l t) + b_il cos(wf l t))

so a_il, b_il are velocity amplitudes [rad/s or m/s]. The coefficients (and the offsets q0) are
chosen to minimise the condition number of the stacked base regressor along one period, subject
to position, velocity and acceleration limits. Every quantity is linear in x = (a, b, q0), so the
limits are linear inequalities; only the objective is nonlinear.

The condition number is that of the stacked base regressor with every column scaled to unit
norm (here and in :func:`excitation_condition_number`): unscaled, it would mostly measure the
units of the parameters (kg against kg m^2) rather than how well the motion excites them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

from ._checks import real_array
from .base_parameters import BaseParameters, base_parameters
from .robot import Robot

#: Default velocity and acceleration limits for every joint [rad/s, rad/s^2]: about half the
#: KUKA LWR4+'s rated joint speeds (110-180 deg/s), gentle enough for a first experiment.
DEFAULT_QD_MAX = 1.0
DEFAULT_QDD_MAX = 2.0

#: Default distance kept from each joint limit, as a fraction of the joint's range.
DEFAULT_POSITION_MARGIN = 0.02

#: SLSQP sees the limits on this many points per harmonic and period (at most ``samples``):
#: its quadratic subproblems cost ~ rows x variables^2, and between the points a trigonometric
#: polynomial of degree H overshoots by at most (pi / 20)^2 / 2 = 1.2 % (see _extents), which
#: the final scaling removes.
CONSTRAINT_POINTS_PER_HARMONIC = 20

#: SLSQP stops when log cond changes by less than this between iterations (0.01 % in cond);
#: the optimum is flat, tighter tolerances buy a few percent for several times the run time.
TOLERANCE = 1e-4

#: The returned trajectory is checked on a grid this many times denser than ``samples``.
CHECK_OVERSAMPLING = 10

# Central-difference step in q for the regressor's derivative (error ~h^2, rounding ~1e-16/h).
_Q_STEP = 1e-5
# Below this ratio of the Gram matrix's extreme eigenvalues (condition number > 1e6) squaring
# costs too many digits, and the singular values are taken from an SVD instead.
_GRAM_RELIABLE = 1e-12


@dataclass(frozen=True, eq=False)
class FourierTrajectory:
    """A periodic joint trajectory given by a finite Fourier series (Swevers et al. 1997).

    ``a`` and ``b`` are (n, H) velocity amplitudes, ``q0`` the (n,) offsets (the mean position
    over a period), ``base_frequency`` wf [rad/s]; the period is 2 pi / wf.
    """

    base_frequency: float
    a: NDArray[np.float64]
    b: NDArray[np.float64]
    q0: NDArray[np.float64]

    def __post_init__(self) -> None:
        wf = _finite_positive(self.base_frequency, "base_frequency")
        a = _finite_array(self.a, "a")
        b = _finite_array(self.b, "b")
        q0 = _finite_array(self.q0, "q0")
        if a.ndim != 2 or a.shape[0] < 1 or a.shape[1] < 1:
            raise ValueError(f"a: expected shape (n, H) with n, H >= 1, got {a.shape}")
        if b.shape != a.shape:
            raise ValueError(f"b: expected the shape of a {a.shape}, got {b.shape}")
        if q0.shape != (a.shape[0],):
            raise ValueError(f"q0: expected shape ({a.shape[0]},), got {q0.shape}")
        for name, value in (("a", a), ("b", b), ("q0", q0)):
            value.setflags(write=False)  # frozen means the arrays too
            object.__setattr__(self, name, value)
        object.__setattr__(self, "base_frequency", wf)

    @property
    def period(self) -> float:
        return 2.0 * np.pi / self.base_frequency

    @property
    def n(self) -> int:
        return self.a.shape[0]

    @property
    def harmonics(self) -> int:
        return self.a.shape[1]

    def evaluate(
        self, t: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """q, qd, qdd at times ``t``: (T, n) each for t of shape (T,), (n,) for a scalar t."""
        times = _finite_array(t, "t")
        if times.ndim > 1:
            raise ValueError(f"t: expected a scalar or shape (T,), got {times.shape}")
        Bq, Bqd, Bqdd = _basis(np.atleast_1d(times), self.base_frequency, self.harmonics)
        c = np.hstack([self.a, self.b])
        q, qd, qdd = Bq @ c.T + self.q0, Bqd @ c.T, Bqdd @ c.T
        if times.ndim == 0:
            return q[0], qd[0], qdd[0]
        return q, qd, qdd

    def sample(
        self, samples: int | None = None, *, fs: float | None = None
    ) -> tuple[NDArray[np.float64], ...]:
        """(t, q, qd, qdd) over one period, t in [0, period): ``samples`` equally spaced points,
        or a sampling rate ``fs`` [Hz] (t = k / fs), exactly one of the two."""
        if (samples is None) == (fs is None):
            raise ValueError("samples, fs: give exactly one of them")
        if samples is not None:
            count = _integer(samples, "samples", minimum=1)
            t = self.period * np.arange(count) / count
        else:
            rate = _finite_positive(fs, "fs")
            # t = k / fs for every k with t < period (the period need not be a multiple of 1/fs)
            t = np.arange(int(np.ceil(self.period * rate - 1e-9))) / rate
        return (t, *self.evaluate(t))

    def limits_margin(
        self,
        qlim: ArrayLike,
        qd_max: ArrayLike = DEFAULT_QD_MAX,
        qdd_max: ArrayLike = DEFAULT_QDD_MAX,
        samples: int = 2000,
    ) -> LimitMargins:
        """How far inside the limits the trajectory stays over the whole (continuous) period.

        Evaluated on ``samples`` points and corrected by a bound on the excursion between them
        (see :func:`_extents`), so each returned margin is a guaranteed lower bound; a negative
        entry means the limit may be (or is) exceeded.
        """
        low, high = _qlim(qlim, self.n)
        vel = _limit_vector(qd_max, "qd_max", self.n)
        acc = _limit_vector(qdd_max, "qdd_max", self.n)
        up, down, v, dv = _extents(self, samples)
        return LimitMargins(
            position=np.minimum(high - self.q0 - up, self.q0 - down - low),
            velocity=vel - v,
            acceleration=acc - dv,
        )

    def to_vector(self) -> NDArray[np.float64]:
        """The optimisation variables x = (a.ravel(), b.ravel(), q0)."""
        return np.concatenate([self.a.ravel(), self.b.ravel(), self.q0])

    @staticmethod
    def from_vector(
        x: ArrayLike, n: int, harmonics: int, base_frequency: float
    ) -> FourierTrajectory:
        """The inverse of :meth:`to_vector`."""
        n = _integer(n, "n", minimum=1)
        harmonics = _integer(harmonics, "harmonics", minimum=1)
        values = _finite_array(x, "x")
        size = n * (2 * harmonics + 1)
        if values.shape != (size,):
            raise ValueError(
                f"x: expected shape ({size},) for n={n}, H={harmonics}, got {values.shape}"
            )
        nh = n * harmonics
        return FourierTrajectory(
            base_frequency,
            values[:nh].reshape(n, harmonics),
            values[nh : 2 * nh].reshape(n, harmonics),
            values[2 * nh :],
        )


@dataclass(frozen=True, eq=False)
class LimitMargins:
    """Per-joint distance to the limits (positive: inside), lower bounds over the period."""

    position: NDArray[np.float64]  #: min over t of the distance to the nearer of qlim's bounds
    velocity: NDArray[np.float64]  #: qd_max - max |qd|
    acceleration: NDArray[np.float64]  #: qdd_max - max |qdd|

    @property
    def satisfied(self) -> bool:
        return bool(
            np.all(self.position >= 0)
            and np.all(self.velocity >= 0)
            and np.all(self.acceleration >= 0)
        )


def rest_to_rest(trajectory: FourierTrajectory) -> FourierTrajectory:
    """The nearest trajectory (least change of a, b) that starts and ends at rest.

    At t = 0 (and so at every multiple of the period) qd_i(0) = sum_l a_il and
    qdd_i(0) = wf sum_l l b_il: both vanish after removing from a_i its mean and from b_i its
    component along (1, 2, ..., H) (orthogonal projections onto the two hyperplanes). q0 is kept.
    The motion can then start from rest, run any number of periods and stop; the jerk at the
    ends is not zero. Needs H >= 2 (with one harmonic the only such trajectory is standstill).
    """
    if trajectory.harmonics < 2:
        raise ValueError("trajectory: starting at rest needs at least 2 harmonics")
    a, b = _rest_projection(trajectory.a, trajectory.b)
    return FourierTrajectory(trajectory.base_frequency, a, b, trajectory.q0)


def excitation_condition_number(
    robot: Robot,
    trajectory: FourierTrajectory,
    samples: int = 200,
    rotor: bool = False,
    friction: bool = False,
    scaled: bool = True,
) -> float:
    """Condition number of the stacked base regressor on ``samples`` equally spaced points of
    one period, each column scaled to unit norm (inf when the motion leaves a column zero).

    ``scaled=False`` gives the plain 2-norm condition number instead, the one
    :func:`dynid.identify.least_squares` reports; it depends on the parameters' units.
    """
    if trajectory.n != robot.n:
        raise ValueError(f"trajectory: expected {robot.n} joints, got {trajectory.n}")
    base = base_parameters(robot, "torque", rotor=rotor, friction=friction)
    count = _integer(samples, "samples", minimum=1)
    if count * robot.n < base.count:
        raise ValueError(
            f"samples: {count} samples give {count * robot.n} rows, fewer than the "
            f"{base.count} base parameters"
        )
    _, q, qd, qdd = trajectory.sample(count)
    W = base.reduce(robot.regressor(q, qd, qdd, rotor=rotor, friction=friction))
    W = W.reshape(-1, base.count)
    if scaled:
        s = _scaled_singular_values(W)[2]
    else:
        s = np.linalg.svd(W, compute_uv=False)[::-1]
    return float(s[-1] / s[0]) if s[0] > 0 else float("inf")


@dataclass(frozen=True, eq=False)
class ExcitationResult:
    """What :func:`optimize_excitation` found, with the condition numbers to report."""

    trajectory: FourierTrajectory  #: the optimised trajectory, within the limits
    condition_before: float  #: of the initial guess (excitation_condition_number, same samples)
    condition_after: float  #: of ``trajectory``
    iterations: int  #: SLSQP iterations
    success: bool  #: SLSQP converged (False also when the iteration limit was reached)
    message: str
    initial: FourierTrajectory = field(repr=False)  #: the feasible starting guess


def optimize_excitation(
    robot: Robot,
    *,
    harmonics: int = 5,
    period: float = 10.0,
    samples: int = 200,
    qd_max: ArrayLike | None = None,
    qdd_max: ArrayLike | None = None,
    rotor: bool = False,
    friction: bool = False,
    at_rest: bool = False,
    seed: int = 0,
    maxiter: int = 200,
    initial: FourierTrajectory | None = None,
    position_margin: float = DEFAULT_POSITION_MARGIN,
) -> ExcitationResult:
    """Fourier coefficients and offsets minimising the condition number of the base regressor.

    The objective, log cond of the column-scaled stacked base regressor on ``samples`` points of
    one period, is minimised by SLSQP with its analytic gradient, subject to
    ``qlim`` (shrunk by ``position_margin`` x range at each end), |qd| <= ``qd_max`` and
    |qdd| <= ``qdd_max`` at those points (None: DEFAULT_QD_MAX, DEFAULT_QDD_MAX; scalars or (n,)).
    ``at_rest`` adds qd(0) = qdd(0) = 0 (see :func:`rest_to_rest`). The start is ``initial`` or a
    random trajectory drawn with ``seed``, scaled to the limits. The result is afterwards checked
    on a grid CHECK_OVERSAMPLING times denser, with a bound on the excursion between its points,
    and its amplitudes shrunk about q0 if needed, so it meets every limit over the whole period.
    """
    n = robot.n
    harmonics = _integer(harmonics, "harmonics", minimum=2 if at_rest else 1)
    period = _finite_positive(period, "period")
    samples = _integer(samples, "samples", minimum=1)
    maxiter = _integer(maxiter, "maxiter", minimum=0)
    base = base_parameters(robot, "torque", rotor=rotor, friction=friction)
    if samples <= 2 * harmonics or samples * n < base.count:
        raise ValueError(
            f"samples: need more than 2*harmonics = {2 * harmonics} samples and at least "
            f"{base.count} regressor rows (samples * {n}), got {samples}"
        )
    vel = _limit_vector(DEFAULT_QD_MAX if qd_max is None else qd_max, "qd_max", n)
    acc = _limit_vector(DEFAULT_QDD_MAX if qdd_max is None else qdd_max, "qdd_max", n)
    margin = _finite_array(position_margin, "position_margin")
    if margin.ndim != 0 or not 0.0 <= margin < 0.5:
        raise ValueError(
            f"position_margin: expected a fraction in [0, 0.5), got {position_margin!r}"
        )
    span = robot.qlim[:, 1] - robot.qlim[:, 0]
    low, high = robot.qlim[:, 0] + margin * span, robot.qlim[:, 1] - margin * span
    wf = 2.0 * np.pi / period
    limits = (np.column_stack([low, high]), vel, acc)

    if initial is None:
        start = _random_start(np.random.default_rng(seed), n, harmonics, wf, low, high, at_rest)
    else:
        start = _check_initial(initial, n, harmonics, period, low, high, at_rest)
    scale = _limit_scale(start, *limits, CHECK_OVERSAMPLING * samples)
    # a random start is stretched to touch the nearest limit, a given one only shrunk if needed
    start = _scaled(start, scale if initial is None else min(scale, 1.0))

    t = period * np.arange(samples) / samples
    objective = _LogCondition(robot, base, t, wf, harmonics, rotor, friction)
    m = min(samples, CONSTRAINT_POINTS_PER_HARMONIC * harmonics)
    grid = _basis(period * np.arange(m) / m, wf, harmonics)
    constraints = [_inequalities(grid, n, low, high, vel, acc)]
    if at_rest:
        constraints.append(_rest_equalities(n, harmonics))
    x0 = start.to_vector()
    if maxiter > 0:
        result = minimize(
            objective.value,
            x0,
            jac=objective.gradient,
            method="SLSQP",
            constraints=constraints,
            options={"maxiter": maxiter, "ftol": TOLERANCE},
        )
        x, iterations, success, message = (
            result.x,
            int(result.nit),
            bool(result.success),
            result.message,
        )
    else:
        x, iterations, success, message = x0, 0, False, "maxiter = 0: the initial guess"

    final = FourierTrajectory.from_vector(x, n, harmonics, wf)
    if at_rest:
        final = rest_to_rest(final)  # remove SLSQP's residual in the equalities (~1e-10)
    # q0 is the mean of q over the constraint points, so inside the limits unless SLSQP stopped
    # infeasible; clipping keeps the scaling below well defined in that case too.
    final = FourierTrajectory(wf, final.a, final.b, np.clip(final.q0, low, high))
    scale = _limit_scale(final, *limits, CHECK_OVERSAMPLING * samples)
    if scale < 1.0:
        final = _scaled(final, scale)
        message += f"; amplitudes scaled by {scale:.6f} to meet the limits between samples"
    before = excitation_condition_number(robot, start, samples, rotor, friction)
    after = excitation_condition_number(robot, final, samples, rotor, friction)
    if not after < before:
        # SLSQP only promises a local improvement of a penalised model; never hand back worse.
        final, after, success = start, before, False
        message += "; no improvement on the initial guess, which is returned"
    return ExcitationResult(final, before, after, iterations, success, message, start)


# ---- the objective ----------------------------------------------------------------------------
class _LogCondition:
    """log cond of the column-scaled stacked base regressor W(x) and its gradient.

    With W's columns w_j of norm r_j, Ws = W diag(1/r), Ws = U S V^T, the first-order change of
    a singular value is ds_k = u_k^T d(Ws) v_k; differentiating the scaling too gives
    d log s_k = <u_k/s_k (v_k/r)^T - Ws diag(v_k^2/r), dW>. The state derivatives of W come
    from the regressor itself: exact differences in qdd (linear) and qd (quadratic), central ones
    in q; all perturbed states go to C++ in one batch call.
    """

    def __init__(
        self,
        robot: Robot,
        base: BaseParameters,
        t: NDArray[np.float64],
        wf: float,
        harmonics: int,
        rotor: bool,
        friction: bool,
    ) -> None:
        self.robot, self.base, self.rotor, self.friction = robot, base, rotor, friction
        self.n, self.harmonics, self.T = robot.n, harmonics, t.size
        self.basis = _basis(t, wf, harmonics)
        self.columns = base.independent
        # The gradient contracts with full-width regressors (cheaper than selecting columns)
        # and skips the Coulomb columns: d sign(qd)/d qd is zero almost everywhere, and a
        # difference across a zero crossing is not.
        first_fs = 10 * robot.n + (robot.n if rotor else 0) + robot.n
        self.smooth = base.independent < first_fs if friction else np.ones(base.count, bool)
        self._x: NDArray[np.float64] | None = None

    def _states(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        nh = self.n * self.harmonics
        c = np.hstack([x[:nh].reshape(self.n, -1), x[nh : 2 * nh].reshape(self.n, -1)])
        Bq, Bqd, Bqdd = self.basis
        return Bq @ c.T + x[2 * nh :], Bqd @ c.T, Bqdd @ c.T

    def _regressor(self, q: NDArray, qd: NDArray, qdd: NDArray) -> NDArray[np.float64]:
        return self.robot.regressor(q, qd, qdd, rotor=self.rotor, friction=self.friction)

    def _update(self, x: NDArray[np.float64]) -> None:
        if self._x is not None and np.array_equal(x, self._x):
            return  # SLSQP asks for value and gradient at the same point
        q, qd, qdd = self._states(x)
        Y = self._regressor(q, qd, qdd)
        Ws, r, s, V = _scaled_singular_values(Y[..., self.columns].reshape(-1, self.base.count))
        self._x = x.copy()
        self._state, self._Y, self._r, self._Ws, self._s, self._V = (q, qd, qdd), Y, r, Ws, s, V

    def value(self, x: NDArray[np.float64]) -> float:
        self._update(x)
        s_min = max(self._s[0], 1e-300)
        return float(np.log(self._s[-1] / s_min))

    def gradient(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        self._update(x)
        Ws, r, s, V = self._Ws, self._r, self._s, self._V
        s_min, v_min, v_max = max(s[0], 1e-300), V[:, 0], V[:, -1]
        # G = d log(s_max / s_min) / dW, (T n) x p
        G = np.outer(Ws @ v_max / s[-1] ** 2, v_max / r) - np.outer(
            Ws @ v_min / s_min**2, v_min / r
        )
        G -= Ws * ((v_max**2 - v_min**2) / r)
        G_full = np.zeros(self._Y.shape)
        G_full[..., self.columns[self.smooth]] = G.reshape(self.T, self.n, -1)[..., self.smooth]

        # five perturbations (q +- h, qd +- 1, qdd + 1) of each joint i at every sample
        n, h = self.n, _Q_STEP
        Q, QD, QDD = (np.tile(state, (5, n, 1, 1)) for state in self._state)
        eye = np.eye(n)[:, None, :]  # (joint i, 1, n): e_i at every sample
        Q[0] += h * eye
        Q[1] -= h * eye
        QD[2] += eye
        QD[3] -= eye
        QDD[4] += eye
        dY = self._regressor(Q.reshape(-1, n), QD.reshape(-1, n), QDD.reshape(-1, n))
        # c[k, t, i] = <G_t, Y_t(state perturbed by k in joint i)>; differences of these give
        # <G_t, dY_t / d state_i>, then the chain rule through the Fourier basis
        c = np.einsum("tjp,kitjp->kti", G_full, dY.reshape(5, n, self.T, n, -1))
        base = np.einsum("tjp,tjp->t", G_full, self._Y)[:, None]
        cq = (c[0] - c[1]) / (2 * h)
        cqd = (c[2] - c[3]) / 2.0  # exact: Y is quadratic in qd
        cqdd = c[4] - base  # exact: Y is linear in qdd
        Bq, Bqd, Bqdd = self.basis
        grad_c = cq.T @ Bq + cqd.T @ Bqd + cqdd.T @ Bqdd  # (n, 2H): [a | b]
        H = self.harmonics
        return np.concatenate([grad_c[:, :H].ravel(), grad_c[:, H:].ravel(), cq.sum(axis=0)])


def _scaled_singular_values(W: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
    """Ws = W with unit-norm columns, the norms r, Ws's singular values s (ascending) and right
    singular vectors V (columns). A zero column stays zero (s_min = 0, cond = inf)."""
    r = np.linalg.norm(W, axis=0)
    r = np.where(r > 0.0, r, 1.0)
    Ws = W / r
    # The p x p Gram matrix is far cheaper than an SVD of the (T n) x p matrix; its eigenvalues
    # are s^2, accurate while cond stays below ~1e6. einsum rather than BLAS: multithreaded
    # BLAS on matrices this small crawls when the cores are busy.
    lam, V = np.linalg.eigh(np.einsum("ki,kj->ij", Ws, Ws))
    if lam[0] > _GRAM_RELIABLE * lam[-1]:
        return Ws, r, np.sqrt(lam), V
    _, s, Vt = np.linalg.svd(Ws, full_matrices=False)
    return Ws, r, s[::-1], Vt[::-1].T


def _basis(t: NDArray[np.float64], wf: float, harmonics: int) -> tuple[NDArray[np.float64], ...]:
    """(T, 2H) matrices mapping the coefficients [a_i | b_i] of a joint to q_i - q0_i, qd_i, qdd_i."""
    w = wf * np.arange(1, harmonics + 1)
    S, C = np.sin(np.outer(t, w)), np.cos(np.outer(t, w))
    return np.hstack([S / w, -C / w]), np.hstack([C, S]), np.hstack([-S * w, C * w])


# ---- limits -----------------------------------------------------------------------------------
def _inequalities(
    basis: tuple[NDArray, ...], n: int, low: NDArray, high: NDArray, vel: NDArray, acc: NDArray
) -> dict:
    """SLSQP's linear inequalities d + E x >= 0 for every sample, joint and limit."""
    Bq, Bqd, Bqdd = basis
    T, H = Bq.shape[0], Bq.shape[1] // 2
    eye = np.eye(n)

    def per_joint(B: NDArray, offset: bool) -> NDArray:
        # rows (joint i, sample k); columns x = (a (n, H), b (n, H), q0 (n))
        tail = np.kron(eye, np.ones((T, 1))) if offset else np.zeros((n * T, n))
        return np.hstack([np.kron(eye, B[:, :H]), np.kron(eye, B[:, H:]), tail])

    Mq, Mqd, Mqdd = per_joint(Bq, True), per_joint(Bqd, False), per_joint(Bqdd, False)
    E = np.vstack([-Mq, Mq, -Mqd, Mqd, -Mqdd, Mqdd])
    d = np.concatenate([np.repeat(v, T) for v in (high, -low, vel, vel, acc, acc)])
    return {"type": "ineq", "fun": lambda x: d + E @ x, "jac": lambda x: E}


def _rest_equalities(n: int, harmonics: int) -> dict:
    """qd_i(0) = sum_l a_il = 0 and qdd_i(0) / wf = sum_l l b_il = 0."""
    eye = np.eye(n)
    A = np.zeros((2 * n, n * (2 * harmonics + 1)))
    A[:n, : n * harmonics] = np.kron(eye, np.ones(harmonics))
    A[n:, n * harmonics : 2 * n * harmonics] = np.kron(eye, np.arange(1.0, harmonics + 1))
    return {"type": "eq", "fun": lambda x: A @ x, "jac": lambda x: A}


def _rest_projection(a: NDArray, b: NDArray) -> tuple[NDArray, NDArray]:
    ell = np.arange(1.0, a.shape[1] + 1)
    return a - a.mean(axis=1, keepdims=True), b - np.outer(b @ ell, ell) / (ell @ ell)


def _extents(trajectory: FourierTrajectory, samples: int) -> tuple[NDArray[np.float64], ...]:
    """Upper bounds over the whole period of max(q - q0), max(q0 - q), max|qd|, max|qdd|.

    Each is a trigonometric polynomial p of degree H in theta = wf t. At its extreme t*,
    p'(t*) = 0 and |p''| <= H^2 max|p| (Bernstein), and a grid point lies within pi/N in theta,
    so the grid misses at most eps max|p| with eps = (pi H / N)^2 / 2; max|p| itself is at most
    (grid max) / (1 - eps).
    """
    count = _integer(samples, "samples", minimum=4 * trajectory.harmonics)
    _, q, qd, qdd = trajectory.sample(count)
    eps = 0.5 * (np.pi * trajectory.harmonics / count) ** 2
    p = q - trajectory.q0
    slack = eps / (1.0 - eps) * np.abs(p).max(axis=0)
    inflate = 1.0 / (1.0 - eps)
    return (
        p.max(axis=0) + slack,
        (-p).max(axis=0) + slack,
        inflate * np.abs(qd).max(axis=0),
        inflate * np.abs(qdd).max(axis=0),
    )


def _limit_scale(
    trajectory: FourierTrajectory, qlim: NDArray, vel: NDArray, acc: NDArray, samples: int
) -> float:
    """The factor on the amplitudes (about q0, which must be inside qlim) that brings the
    smallest guaranteed margin to zero: q - q0, qd and qdd all scale with it."""
    up, down, v, dv = _extents(trajectory, samples)
    room = np.concatenate([qlim[:, 1] - trajectory.q0, trajectory.q0 - qlim[:, 0], vel, acc])
    extent = np.concatenate([up, down, v, dv])
    moving = extent > 0
    if not np.any(moving):
        return 1.0  # standing still: nothing to scale
    # 1 - 1e-9: so that rounding cannot put the scaled extreme a hair outside; q0 on a bound
    # leaves no room at all (0), and nothing may flip the motion (a negative factor)
    return max(0.0, float(np.min(room[moving] / extent[moving])) * (1.0 - 1e-9))


def _scaled(trajectory: FourierTrajectory, scale: float) -> FourierTrajectory:
    if scale == 1.0:
        return trajectory
    return FourierTrajectory(
        trajectory.base_frequency, scale * trajectory.a, scale * trajectory.b, trajectory.q0
    )


def _random_start(
    rng: np.random.Generator,
    n: int,
    harmonics: int,
    wf: float,
    low: NDArray,
    high: NDArray,
    at_rest: bool,
) -> FourierTrajectory:
    """Random amplitudes falling as 1/l (each harmonic then adds a similar acceleration) and a
    random offset in the middle half of the range; the caller scales it to the limits."""
    ell = np.arange(1.0, harmonics + 1)
    a, b = rng.normal(size=(2, n, harmonics)) / ell
    if at_rest:
        a, b = _rest_projection(a, b)
    q0 = low + (high - low) * rng.uniform(0.25, 0.75, n)
    return FourierTrajectory(wf, a, b, q0)


def _check_initial(
    initial: FourierTrajectory,
    n: int,
    harmonics: int,
    period: float,
    low: NDArray,
    high: NDArray,
    at_rest: bool,
) -> FourierTrajectory:
    if not isinstance(initial, FourierTrajectory):
        # SPEC section 2: a wrong type is a ValueError too
        raise ValueError(  # noqa: TRY004
            f"initial: expected a FourierTrajectory, got {type(initial).__name__}"
        )
    if (initial.n, initial.harmonics) != (n, harmonics) or not np.isclose(initial.period, period):
        raise ValueError(
            f"initial: expected {n} joints, harmonics={harmonics}, period={period}, got "
            f"{initial.n}, {initial.harmonics}, {initial.period}"
        )
    if np.any(initial.q0 <= low) or np.any(initial.q0 >= high):
        raise ValueError("initial: q0 must lie strictly inside the joint limits less the margin")
    return rest_to_rest(initial) if at_rest else initial


# ---- argument checks (SPEC section 2: ValueError naming the argument) ----------------------------
def _finite_array(value: ArrayLike, name: str) -> NDArray[np.float64]:
    return real_array(value, name).copy()  # a copy: FourierTrajectory freezes its arrays


def _finite_positive(value: object, name: str) -> float:
    array = _finite_array(value, name) if not isinstance(value, bool) else np.array(np.nan)
    if array.ndim != 0 or not array > 0.0:
        raise ValueError(f"{name}: expected a positive finite number, got {value!r}")
    return float(array)


def _integer(value: object, name: str, minimum: int) -> int:
    # SPEC section 2: a wrong type is a ValueError too; True is not an integer here
    integral = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
    if integral and value >= minimum:
        return int(value)
    raise ValueError(f"{name}: expected an integer >= {minimum}, got {value!r}")


def _limit_vector(value: ArrayLike, name: str, n: int) -> NDArray[np.float64]:
    array = _finite_array(value, name)
    if array.ndim == 0:
        array = np.full(n, float(array))
    if array.shape != (n,) or np.any(array <= 0.0):
        raise ValueError(f"{name}: expected a positive number or {n} of them, got {value!r}")
    return array


def _qlim(value: ArrayLike, n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    limits = _finite_array(value, "qlim")
    if limits.shape != (n, 2) or np.any(limits[:, 0] >= limits[:, 1]):
        raise ValueError(f"qlim: expected ({n}, 2) rows [lower, upper] with lower < upper")
    return limits[:, 0], limits[:, 1]
