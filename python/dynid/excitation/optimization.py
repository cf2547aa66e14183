"""Optimising an exciting trajectory: Fourier coefficients minimising the regressor's cond.

The coefficients a, b and the offsets q0 of a :class:`dynid.excitation.FourierTrajectory`
(Swevers et al., IEEE Trans. RA 13(5), 1997) are chosen to minimise the condition number of the
stacked, column-scaled base regressor along one period, subject to position, velocity and
acceleration limits. Every quantity is linear in x = (a, b, q0), so the limits are linear
inequalities; only the objective is nonlinear. SLSQP minimises it with the analytic gradient of
:class:`_LogCondition`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

from .._threads import blas_single_threaded
from ..model.base_parameters import BaseParameters, base_parameters
from ..model.robot import Robot
from .cartesian import KeepOut, KeepOutConstraint
from .limit_scaling import NonlinearLimits, start_with_room
from .torque_limits import TORQUE_MARGIN, TorqueConstraint, torque_limit_vector
from .trajectory import (
    DEFAULT_QD_MAX,
    DEFAULT_QDD_MAX,
    FourierTrajectory,
    _basis,
    _basis_states,
    _extents,
    _finite_array,
    _finite_positive,
    _integer,
    _limit_vector,
    _rest_projection,
    _scaled_singular_values,
    excitation_condition_number,
    rest_to_rest,
)

#: Default distance kept from each joint limit, as a fraction of the joint's range.
DEFAULT_POSITION_MARGIN = 0.02

#: SLSQP sees the limits on this many points per harmonic and period (at most ``samples``):
#: its quadratic subproblems cost ~ rows x variables^2, and between the points a trigonometric
#: polynomial of degree H overshoots by at most (pi / 20)^2 / 2 = 1.2 % (see
#: excitation._extents), which the final scaling removes.
CONSTRAINT_POINTS_PER_HARMONIC = 20

#: SLSQP stops when log cond changes by less than this between iterations (0.01 % in cond);
#: the optimum is flat, tighter tolerances buy a few percent for several times the run time.
TOLERANCE = 1e-4

#: The returned trajectory is checked on a grid this many times denser than ``samples``.
CHECK_OVERSAMPLING = 10

# Central-difference step in q for the regressor's derivative (error ~h^2, rounding ~1e-16/h).
_Q_STEP = 1e-5


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


@blas_single_threaded  # many small dense products: one BLAS thread is fastest (issue 13)
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
    tau_max: ArrayLike | None = None,
    torque_model: Robot | None = None,
    keep_out: KeepOut | None = None,
    progress: Callable[[int, float], None] | None = None,
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

    ``tau_max`` (a scalar or (n,), None: no torque limit) adds |tau| <= tau_max, the torque of
    ``torque_model`` (default ``robot``; e.g. a prior model with the drive terms) by rnea along
    the motion: SLSQP sees it on the constraint points with TORQUE_MARGIN kept free, and the
    start and the result are shrunk about q0 until the bound of
    :func:`dynid.excitation.torque_limits.torque_extents` holds over the whole period.
    ``keep_out`` (:class:`dynid.excitation.cartesian.KeepOut`) keeps the link origins and the
    tool point above a floor and inside a box, and non-adjacent links (capsules) apart: SLSQP
    sees them on the constraint points with ``keep_out.margin`` free, and the start and the result
    are shrunk about q0 until they hold over the whole period (cartesian.keep_out_holds).
    ``progress(iteration, cond)`` is called after each SLSQP iteration.
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
    torque = None if tau_max is None else torque_limit_vector(tau_max, n)
    model = robot if torque_model is None else torque_model
    if torque is not None and (not isinstance(model, Robot) or model.n != n):
        raise ValueError(f"torque_model: expected a Robot with {n} joints, got {model!r}")
    if keep_out is not None and not isinstance(keep_out, KeepOut):
        raise ValueError(f"keep_out: expected a KeepOut, got {type(keep_out).__name__}")
    space = keep_out if keep_out is not None and keep_out.active else None
    check = CHECK_OVERSAMPLING * samples

    if initial is None:
        rng = np.random.default_rng(seed)
        start = _random_start(rng, n, harmonics, wf, low, high, at_rest)
        if torque is not None or space is not None:

            def redraw() -> FourierTrajectory:
                return _random_start(rng, n, harmonics, wf, low, high, at_rest)

            start = start_with_room(start, redraw, robot, model, torque, space)
    else:
        start = _check_initial(initial, n, harmonics, period, low, high, at_rest)
    scale = _limit_scale(start, *limits, check)
    # a random start is stretched to touch the nearest limit, a given one only shrunk if needed
    start = _scaled(start, scale if initial is None else min(scale, 1.0))
    q_ref = start.q0  # the configuration the capsules' segment lengths are measured at
    nonlinear = NonlinearLimits(robot, model, torque, space, q_ref, check)
    # then shrunk until its torque and keep-out limits hold everywhere
    start = _scaled(start, nonlinear.scale(start))

    t = period * np.arange(samples) / samples
    objective = _LogCondition(robot, base, t, wf, harmonics, rotor, friction)
    m = min(samples, CONSTRAINT_POINTS_PER_HARMONIC * harmonics)
    grid = _basis(period * np.arange(m) / m, wf, harmonics)
    constraints: list[Any] = [_inequalities(grid, n, low, high, vel, acc)]  # SciPy's dicts
    points = period * np.arange(m) / m
    if torque is not None:
        limit = (1.0 - TORQUE_MARGIN) * torque
        constraints.append(TorqueConstraint(model, points, wf, harmonics, limit).as_dict())
    if space is not None:
        # the Cartesian motion needs a finer grid than the joints' 20 H: samples points
        keep_t = period * np.arange(samples) / samples
        keeping = KeepOutConstraint(robot, space, keep_t, wf, harmonics, q_ref)
        if not keeping.empty:  # SLSQP refuses a constraint of no rows
            constraints.append(keeping.as_dict())
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
            callback=None if progress is None else _Progress(progress, objective),
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
    scale = _limit_scale(final, *limits, check)
    if torque is not None or space is not None:
        scale = min(scale, 1.0) * nonlinear.scale(_scaled(final, min(scale, 1.0)))
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


class _Progress:
    """SLSQP's callback: ``report(iteration, cond)`` after each iteration."""

    def __init__(self, report: Callable[[int, float], None], objective: _LogCondition) -> None:
        self.report, self.objective, self.iteration = report, objective, 0

    def __call__(self, x: NDArray[np.float64]) -> None:
        self.iteration += 1
        self.report(self.iteration, float(np.exp(self.objective.value(x))))


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
        return _basis_states(x, self.n, self.harmonics, self.basis)

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
        # docs/conventions.md, "Bad input": a wrong type is a ValueError too
        raise ValueError(f"initial: expected a FourierTrajectory, got {type(initial).__name__}")
    if (initial.n, initial.harmonics) != (n, harmonics) or not np.isclose(initial.period, period):
        raise ValueError(
            f"initial: expected {n} joints, harmonics={harmonics}, period={period}, got "
            f"{initial.n}, {initial.harmonics}, {initial.period}"
        )
    if np.any(initial.q0 <= low) or np.any(initial.q0 >= high):
        raise ValueError("initial: q0 must lie strictly inside the joint limits less the margin")
    return rest_to_rest(initial) if at_rest else initial
