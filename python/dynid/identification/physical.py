"""Physically consistent identification: least squares over the standard parameters subject to
every link being a rigid body that can exist (docs/identification.md,
"Physically consistent identification").

Unconstrained least squares estimates the base parameters; on weakly exciting data the
estimate, mapped back to any set of standard parameters, can have negative masses, inertias
violating the triangle inequality, negative rotor inertias or friction, and an M(q) that is not
positive definite: a model that cannot be simulated. Here the standard parameters themselves are
estimated by a convex semidefinite programme (Wensing, Kim, Slotine, "Linear matrix inequalities
for physically consistent inertial parameter identification", IEEE RA-L 3(1), 2018; see
:mod:`dynid.model.pseudo_inertia`):

    minimise    || W (Y pi - tau) ||^2 / || W tau ||^2  +  prior_weight * d(pi, pi_prior)
    subject to  J_i(pi) - margin * I_4  positive semidefinite      (every link i)
                Ia >= 0,  Fv >= 0,  Fs >= 0,  optional bounds on each m_i and on sum m_i,
                the extra columns' coefficients marked ``nonnegative_extra`` >= 0.

The first term is the weighted residual relative to the weighted torques (scale-free: 1e-4 is a
1 % relative RMS error). The second is zero without a prior; with one it is the sum over the
links of || S_i (J_i - J_i,prior) S_i ||_F^2 / m_i,prior^2, S_i = diag(1/L_i, 1/L_i, 1/L_i, 1),
L_i^2 = tr(Sigma_i,prior) / m_i,prior (the prior link's mean squared distance of its mass from the
frame origin), i.e. each link's relative change of mass, first and second moments; plus, for the
drive terms, ((x_k - x_k,prior) / s_k)^2 with s_k = RMS(tau_j) / RMS(column k) on joint j's rows
(the value that would explain joint j's whole torque alone). So ``prior_weight`` is the price of
a 100 % change of one link in units of squared relative residual: with 1e-4, moving a link's
parameters by 10 % is worth 0.1 % relative RMS residual. Directions the data cannot see (the
null space of Y) cost nothing in the first term and come from the prior; well-excited ones
follow the data as long as prior_weight is small against the residual's curvature.

Identifiability: the data determine at most the base parameters (beta pi, Y pi = Y_b beta pi)
and the extra coefficients, and only those the weighted data excite. Their number is the rank
of the weighted regressor's base and extra columns, computed as :func:`dynid.least_squares`
computes it (singular values of the column-scaled matrix above ``rank_tolerance`` times the
largest; here of the compressed triangle the solver sees). Below the count the result says so
(``rank``, ``parameter_count``, ``unidentified``) and a UserWarning names the parameters:
along the unexcited directions the estimate is the prior's, or, without a prior, whatever
point of the optimal set the interior-point solver stops at (not the data's: such base
values can be off by 100 % and more on noise-free data, the residual being optimal either way).

The solver is Clarabel (interior point, open source, PyPI) through cvxpy. The problem is solved in
scaled units (the stacked weighted regressor is QR-compressed to its P x P triangle, its columns
scaled to unit norm, the torques to unit norm) and the objective is written as the Euclidean
norm of the stacked residual and prior terms (a second-order cone; same minimiser as the sum of
squares), so the solver's absolute tolerance ~1e-8 applies to the residual itself, not to its
square.

Units: before anything else the weights are divided by the power of two that brings their
largest to [0.5, 1) (a common factor cancels in the relative residual), Y and tau by those that
bring their largest magnitude to [0.5, 1), as :func:`dynid.least_squares` does; the parameters
are then estimated in units of 2^e, e = (tau's exponent) - (Y's), and multiplied back by 2^e at
the end. The margin, the mass bounds and the prior, which are in the parameters' units, are
divided by 2^e too. So the solver sees the same problem whatever the magnitudes of Y, tau and
the weights (issue 22: |w tau| beyond ~1e154 overflowed the torques' norm and fitted zero
torques, below ~1e-162 it underflowed to the same effect): Y times 2^a, tau times 2^b, the
weights times 2^c, and margin, mass_bounds, total_mass and the prior times 2^(b - a) give the
estimate times 2^(b - a), exactly (other factors: the same problem up to rounding). The margin,
the bounds and the prior do not follow the data's units by themselves: with tau times 2^b and
the default margin, the margin is 2^-b times smaller relative to the parameters (negligible for
b > 0; for b << 0 it can exclude them: give margin in the parameters' units).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
import scipy.linalg.lapack
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import positive
from .._equality import ValueEquality
from ..errors import PhysicalIdentificationError
from ..model.base_parameters import base_parameters
from ..model.pseudo_inertia import nearest_with_margin, pseudo_inertia, standard_from_pseudo_inertia
from ..model.robot import Robot
from ._qr import exponent, solve_triangular_system, upper_triangle
from .identify import IDENTIFIABLE_TOLERANCE, _check_rank_tolerance, _rank_message, _unscale
from .physical_arguments import (
    check_data,
    check_mass_bounds,
    check_nonnegative_extra,
    check_prior,
    check_prior_weight,
    check_total_mass,
    check_weights,
)

#: Default margin: J_i - margin * I_4 must be positive semidefinite (SI units: kg for the mass
#: entry, kg m^2 for the second-moment block). It means m_i >= 1e-6 kg and, approximately (for
#: margin << m_i), every principal second moment of the mass about the centre of mass
#: (Sigma_c = 0.5 tr(I_c) E - I_c) at least 1e-6 kg m^2, i.e. each principal moment of inertia
#: about the centre of mass at least 2e-6 kg m^2 and the triangle inequalities holding with
#: 2e-6 kg m^2 to spare. Strictly positive, so a solution on the boundary of the feasible set is
#: still a physical link; small against real links (a 0.3 kg hand of 5 cm radius: 3e-4 kg m^2).
DEFAULT_MARGIN = 1e-6

#: Configurations at which the identified M(q) is checked positive definite after the solve.
CHECK_CONFIGURATIONS = 200

#: A solver's constraint violation is projected away (see :func:`physical_least_squares`) only
#: when it is below this fraction of the link's pseudo-inertia norm; a larger one is a failure.
PROJECTION_TOLERANCE = 1e-6

#: The solver: Clarabel handles the semidefinite and second-order cones of this problem to
#: ~1e-8 directly. SCS (first order) is not used as a fallback: its default accuracy (1e-4) is
#: not enough for the noise-free recovery this module promises, and a silent switch to a less
#: accurate solver would hide a failure instead of reporting it.
SOLVER = "CLARABEL"


@dataclass(eq=False)
class PhysicalResult(ValueEquality):
    """A physically consistent estimate (see :func:`physical_least_squares`); pickles, copies
    and compares by value."""

    robot: Robot  #: copy of the model with the identified parameters (consistent, M(q) > 0)
    params: NDArray[np.float64]  #: (n, 10) standard parameters
    Ia: NDArray[np.float64] | None  #: (n,) when rotor=True
    Fv: NDArray[np.float64] | None  #: (n,) when friction=True
    Fs: NDArray[np.float64] | None  #: (n,) when friction=True
    extra: NDArray[np.float64]  #: (extra_columns,) the coefficients of the extra columns
    theta: NDArray[np.float64]  #: (P + extra_columns,) the whole estimate, Y @ theta predicts tau
    base_values: NDArray[np.float64]  #: base.beta @ pi (p,), base of the torque regressor
    base_names: list[str]
    rank: int  #: numerical rank of the weighted regressor's base and extra columns
    parameter_count: int  #: their number, p + extra_columns: full rank when rank equals it
    unidentified: list[str]  #: those (base_names, then extra[k]) the data leave undetermined
    residual_rms: NDArray[np.float64]  #: (n,) per joint RMS of tau - Y theta (torque units)
    status: str  #: the solver's status ("optimal")
    objective: float  #: the cost minimised (relative squared residual + prior term)
    solver: str
    solve_time: float  #: seconds in the solver (cvxpy's report)
    setup_time: float  #: seconds outside the solver: checks, compression, cvxpy's compilation
    min_eigenvalues: NDArray[np.float64]  #: (n,) smallest eigenvalue of each link's J_i
    min_mass_matrix_eigenvalue: float  #: smallest eigenvalue of M(q) over the checked q
    projected: tuple[int, ...] = ()  #: links (0-based) moved onto the margin after the solve
    projection: float = 0.0  #: largest relative change made by that projection
    options: dict[str, Any] = field(default_factory=dict)


def physical_least_squares(
    robot: Robot,
    Y: ArrayLike,
    tau: ArrayLike,
    rotor: bool = False,
    friction: bool = False,
    weights: ArrayLike | None = None,
    prior: Robot | None = None,
    prior_weight: float = 0.0,
    mass_bounds: ArrayLike | None = None,
    total_mass: float | Sequence[float] | None = None,
    margin: float = DEFAULT_MARGIN,
    extra_columns: int = 0,
    nonnegative_extra: ArrayLike | None = None,
    rank_tolerance: float = 1e-10,
) -> PhysicalResult:
    """Physically consistent least squares over the standard parameters (module docstring).

    Parameters
    ----------
    robot
        The model (DH table, joint types, gravity); its parameters are not used.
    Y, tau
        The standard regressor of T samples, (T, n, P + extra_columns), and the torques (T, n);
        or stacked (N, P + extra_columns) and (N,), N = T n, rows sample after sample (joint 1
        to n of sample 1, then sample 2, ...: ``Y3.reshape(-1, P)``). The first P columns are
        those of ``robot.regressor(q, qd, qdd, rotor, friction)``.
    rotor, friction
        Whether Y has the Ia (n) and Fv, Fs (2n) columns.
    weights
        Multipliers of the residual rows (the weighted residual is w * (Y theta - tau)): None
        (all 1), one per joint (n,), or one per row ((T, n) or (N,)). ``dynid.least_squares``'s
        WLS is w_j = 1 / sigma_j, sigma_j the joint's noise standard deviation. Non-negative,
        at least one positive.
    prior, prior_weight
        A physically consistent Robot of the same arm (same joints; in any DH table: its
        parameters are re-expressed in robot's frames when its regressor differs, see
        :func:`dynid.model.link_frames.express_in_frames_of`) and the weight of the distance to it
        (module docstring); the directions the data cannot see come from it. prior_weight > 0
        needs a prior, a prior needs prior_weight > 0.
    mass_bounds
        (n, 2) lower and upper bound on each link's mass in kg (upper may be inf).
    total_mass
        The sum of the link masses in kg: a number (equality) or (lower, upper).
    margin
        J_i - margin I_4 positive semidefinite (see :data:`DEFAULT_MARGIN`), > 0.
    extra_columns
        Number of trailing columns of Y whose coefficients are not standard parameters (e.g.
        torque offsets): unconstrained, except those marked in ``nonnegative_extra``.
    nonnegative_extra
        None, or (extra_columns,) booleans: the extra coefficients constrained >= 0 (e.g. the
        asymmetric friction coefficients Fv+, Fv-, Fs+, Fs- of
        :mod:`dynid.identification.friction_models`); after the solve, values negative by a solver
        tolerance are set to 0, as for Ia, Fv, Fs.
    rank_tolerance
        The rank test's, as for :func:`dynid.least_squares`: in (0, 1).

    Identifiability (module docstring): ``result.rank`` of ``result.parameter_count`` base
    parameters and extra coefficients are determined by the weighted data; ``unidentified``
    names those entering a direction the data do not see (as least_squares' infinite standard
    deviations; the extra columns are ``extra[k]``). When rank < parameter_count a UserWarning
    names them and says what fixes them instead: the prior, or without one nothing but the
    constraints and where the solver stops.

    After the solve, each link's pseudo-inertia is moved to the nearest matrix (Frobenius norm)
    with eigenvalues >= margin, and Ia, Fv, Fs negative by a solver tolerance set to 0: this
    removes the solver's ~1e-9 constraint violations, so the margin holds exactly; a change
    larger than ``PROJECTION_TOLERANCE`` relative is reported as a failure instead. The result
    is then checked: every link consistent and M(q) positive definite at
    ``CHECK_CONFIGURATIONS`` random q within the limits. Drive terms that are not estimated are
    zero in ``result.robot`` (its rnea is Y @ theta without the extra columns).

    Raises ValueError naming a bad argument, :class:`PhysicalIdentificationError` (with the
    solver's status) when the solve fails, is infeasible or inaccurate.
    """
    import cvxpy as cp

    started = time.perf_counter()
    if not isinstance(robot, Robot):
        raise ValueError(f"robot: expected a dynid.Robot, got {type(robot).__name__}")
    rotor, friction = checks.flag(rotor, "rotor"), checks.flag(friction, "friction")
    n = robot.n
    P = robot.parameter_vector(rotor, friction).size
    k = checks.count(extra_columns, "extra_columns", 0)
    nonnegative = check_nonnegative_extra(nonnegative_extra, k)
    Y3, tau2 = check_data(Y, tau, n, P + k)
    w = check_weights(weights, Y3.shape[0], n)
    margin = positive(margin, "margin")
    prior_weight = check_prior_weight(prior_weight, prior)
    prior_x = check_prior(prior, robot, rotor, friction) if prior is not None else None
    lower, upper = check_mass_bounds(mass_bounds, n)
    total = check_total_mass(total_mass)
    rank_tolerance = _check_rank_tolerance(rank_tolerance)
    base = base_parameters(robot, "torque", rotor=rotor, friction=friction)

    # Units (module docstring): weights, Y and tau by powers of two (exact), the parameters, so
    # the margin, the bounds and the prior, in units of 2^unit; everything below until the
    # unscaling is in these units.
    y_max, tau_max = np.array([np.abs(Y3).max()]), np.array([np.abs(tau2).max()])
    sizes = f"max |Y| {y_max[0]:.3g}, max |tau| {tau_max[0]:.3g}"
    y_exp, tau_exp = exponent(y_max) or 0, exponent(tau_max) or 0
    unit = tau_exp - y_exp
    Y3, tau2 = np.ldexp(Y3, -y_exp), np.ldexp(tau2, -tau_exp)
    w = np.ldexp(w, -(exponent(w) or 0))
    margin_s = float(np.ldexp(margin, -unit))
    if lower is not None:
        assert upper is not None  # check_mass_bounds gives both or neither
        lower, upper = np.ldexp(lower, -unit), np.ldexp(upper, -unit)
    if total is not None:
        total = (float(np.ldexp(total[0], -unit)), float(np.ldexp(total[1], -unit)))
    if prior_x is not None:
        prior_x = np.ldexp(prior_x, -unit)

    # Scaled, compressed residual: rows weighted, columns to unit norm, torques to unit norm,
    # then A_s = Q R so that ||A_s z - b_s||^2 = ||R z - Q^T b_s||^2 + r0^2 (r0 constant).
    A = (Y3 * w[:, :, None]).reshape(-1, P + k)
    b = (tau2 * w).reshape(-1)
    column = _column_norms(A)
    b_norm = float(_column_norms(b[:, None])[0])  # 1 for b = 0
    R, c, r0 = _compressed(A / column, b / b_norm)
    names = [*base.names, *(f"extra[{j}]" for j in range(k))]
    seen = np.concatenate([base.independent, P + np.arange(k)])
    rank, unidentified, rank_message = _identifiability(R, c, seen, names, rank_tolerance)

    J = [cp.Variable((4, 4), symmetric=True, name=f"J{i + 1}") for i in range(n)]
    drive_count = (n if rotor else 0) + (2 * n if friction else 0)
    drive = cp.Variable(drive_count, nonneg=True, name="drive") if drive_count else None
    free = cp.Variable(k, name="extra") if k else None
    parts = [_STANDARD_FROM_J @ cp.vec(Ji, order="F") for Ji in J]
    parts += [v for v in (drive, free) if v is not None]
    x = cp.hstack(parts)
    terms = [R @ cp.multiply(column / b_norm, x) - c, np.array([r0])]
    constraints = [Ji - margin_s * np.eye(4) >> 0 for Ji in J]
    if free is not None and nonnegative.any():
        constraints += [free[np.flatnonzero(nonnegative)] >= 0]
    masses = cp.hstack([Ji[3, 3] for Ji in J])
    if lower is not None and upper is not None:
        constraints += [masses >= lower]
        finite = np.isfinite(upper)
        if finite.any():
            constraints += [masses[np.flatnonzero(finite)] <= upper[finite]]
    if total is not None:
        constraints += [cp.sum(masses) >= total[0], cp.sum(masses) <= total[1]]
    if prior_x is not None:
        terms += _prior_terms(J, drive, prior_x, prior_weight, Y3, tau2, n, rotor, friction)
    problem = cp.Problem(cp.Minimize(cp.norm(cp.hstack(terms), 2)), constraints)
    try:
        problem.solve(solver=SOLVER)
    except cp.error.SolverError as exc:
        raise PhysicalIdentificationError(
            f"the physically consistent fit failed: the solver {SOLVER} stopped with an error "
            f"({exc}); no model is returned",
            "solver_error",
        ) from None
    solve_time = problem.solver_stats.solve_time
    solve_time = float(solve_time) if solve_time is not None else float("nan")
    setup = time.perf_counter() - started - (solve_time if np.isfinite(solve_time) else 0.0)
    status = str(problem.status)
    if status != cp.OPTIMAL:
        why = {
            cp.INFEASIBLE: " (the constraints cannot all hold: check mass_bounds, total_mass "
            "and margin against each other)",
            cp.OPTIMAL_INACCURATE: " (the solver did not reach its tolerances)",
        }
        raise PhysicalIdentificationError(
            f"the physically consistent fit failed: solver {SOLVER} status {status!r}"
            f"{why.get(status, '')}; no model is returned",
            status,
        )

    # Remove the solver's tiny constraint violations (documented above), then check.
    params = np.empty((n, 10))
    projected, worst = [], 0.0
    for i, Ji in enumerate(J):
        raw = 0.5 * (Ji.value + Ji.value.T)
        fixed = nearest_with_margin(raw, margin_s)
        change = float(np.linalg.norm(fixed - raw) / np.linalg.norm(raw))
        if change > 0:
            projected.append(i)
            worst = max(worst, change)
        params[i] = standard_from_pseudo_inertia(fixed)
    drive_values = np.maximum(drive.value, 0.0) if drive is not None else np.zeros(0)
    if worst > PROJECTION_TOLERANCE:
        raise PhysicalIdentificationError(
            f"the physically consistent fit failed: solver {SOLVER} reported {status!r} but its "
            f"solution violates the margin by {worst:.3g} (relative); no model is returned",
            "inaccurate",
        )
    extra = np.asarray(free.value, dtype=float) if free is not None else np.zeros(0)
    extra[nonnegative] = np.maximum(extra[nonnegative], 0.0)
    theta = np.concatenate([params.reshape(-1), drive_values, extra])
    residual_rms = np.sqrt(np.mean((tau2 - Y3 @ theta) ** 2, axis=0))  # |tau2| < 1: no overflow
    # Back to the units given (exact powers of two), a ValueError if they overflow.
    theta = _unscale(theta, unit, "Y, tau", "the estimate theta ~ tau / Y", sizes)
    residual_rms = _unscale(residual_rms, tau_exp, "tau", "the residual RMS", sizes)
    params = theta[: 10 * n].reshape(n, 10).copy()
    drive_values, extra = theta[10 * n : P].copy(), theta[P:].copy()
    identified = _identified_robot(robot, params, drive_values, rotor, friction)
    min_eig = np.array([np.linalg.eigvalsh(pseudo_inertia(p))[0] for p in params])
    mass_eig = _check(identified, min_eig)
    if rank_message:
        decided = (
            f"These directions come from the prior (prior_weight {prior_weight:g}), not from "
            "the data."
            if prior is not None
            else "Without a prior nothing fixes these directions: the estimate along them is "
            "wherever the solver stopped within the physical constraints, arbitrary (give a "
            "prior)."
        )
        warnings.warn(
            f"physical_least_squares: {rank_message} {decided} result.rank and "
            "result.unidentified report them.",
            UserWarning,
            stacklevel=2,
        )
    return PhysicalResult(
        robot=identified,
        params=params,
        Ia=drive_values[:n].copy() if rotor else None,
        Fv=drive_values[n * rotor : n * rotor + n].copy() if friction else None,
        Fs=drive_values[n * rotor + n :].copy() if friction else None,
        extra=extra,
        theta=theta,
        base_values=base.beta @ theta[:P],
        base_names=list(base.names),
        rank=rank,
        parameter_count=seen.size,
        unidentified=unidentified,
        residual_rms=residual_rms,
        status=status,
        objective=float(problem.value) ** 2,
        solver=SOLVER,
        solve_time=solve_time,
        setup_time=setup,
        min_eigenvalues=min_eig,
        min_mass_matrix_eigenvalue=mass_eig,
        projected=tuple(projected),
        projection=worst,
        options={
            "rotor": rotor,
            "friction": friction,
            "prior_weight": prior_weight,
            "margin": margin,
            "extra_columns": k,
            "nonnegative_extra": np.flatnonzero(nonnegative).tolist(),
            "prior": prior is not None,
            "rank_tolerance": rank_tolerance,
        },
    )


# --------------------------------------------------------------------------- the problem


def _standard_from_vec_j() -> NDArray[np.float64]:
    """G (10, 16) with pi_i = G vec(J_i) (column-major vec) for a symmetric J_i: the linear map
    of :func:`dynid.model.pseudo_inertia.standard_from_pseudo_inertia`, which reads each
    off-diagonal pair as the mean of its two entries."""
    return np.column_stack(
        [standard_from_pseudo_inertia(unit.reshape(4, 4, order="F")) for unit in np.eye(16)]
    )


_STANDARD_FROM_J = _standard_from_vec_j()


def _prior_terms(
    J: list,
    drive: Any,
    prior_x: NDArray[np.float64],
    weight: float,
    Y3: NDArray[np.float64],
    tau2: NDArray[np.float64],
    n: int,
    rotor: bool,
    friction: bool,
) -> list:
    """sqrt(weight) times the scaled deviations from the prior (module docstring)."""
    import cvxpy as cp

    root = np.sqrt(weight)
    terms = []
    for i, Ji in enumerate(J):
        Jp = pseudo_inertia(prior_x[10 * i : 10 * i + 10])
        mass = Jp[3, 3]
        length = np.sqrt(np.trace(Jp[:3, :3]) / mass)
        s = np.array([1 / length, 1 / length, 1 / length, 1.0])
        scale = root * np.outer(s, s) / mass
        terms.append(cp.vec(cp.multiply(scale, Ji - Jp), order="F"))
    if drive is not None:
        joints = np.concatenate([np.arange(n)] * ((1 if rotor else 0) + (2 if friction else 0)))
        columns = 10 * n + np.arange(joints.size)
        rms_tau = np.sqrt(np.mean(tau2**2, axis=0))[joints]
        rms_col = np.sqrt(np.mean(Y3[:, joints, columns] ** 2, axis=0))
        scale = np.ones(joints.size)
        usable = (rms_tau > 0) & (rms_col > 0)
        scale[usable] = rms_tau[usable] / rms_col[usable]
        terms.append(root * (drive - prior_x[10 * n :]) / scale)
    return terms


def _identified_robot(
    robot: Robot,
    params: NDArray[np.float64],
    drive: NDArray[np.float64],
    rotor: bool,
    friction: bool,
) -> Robot:
    identified = robot.copy()
    identified.params = params
    n = robot.n
    zeros = np.zeros(n)
    identified.Ia = drive[:n] if rotor else zeros
    offset = n if rotor else 0
    identified.Fv = drive[offset : offset + n] if friction else zeros
    identified.Fs = drive[offset + n : offset + 2 * n] if friction else zeros
    return identified


def _check(robot: Robot, min_eig: NDArray[np.float64]) -> float:
    """Every link consistent and M(q) positive definite at random q: the smallest eigenvalue."""
    bad = [i + 1 for i in range(robot.n) if robot._link_inconsistency(i)]
    if bad or not robot.is_physically_consistent():
        raise PhysicalIdentificationError(
            f"the physically consistent fit failed its check: link(s) {bad} not physically "
            f"consistent after the solve (smallest pseudo-inertia eigenvalues {min_eig})",
            "inconsistent",
        )
    q = robot.random_configurations(CHECK_CONFIGURATIONS, seed=0)
    smallest = float(np.linalg.eigvalsh(robot.mass_matrix(q)).min())
    if not smallest > 0:
        raise PhysicalIdentificationError(
            f"the physically consistent fit failed its check: M(q) is not positive definite "
            f"(smallest eigenvalue {smallest:.3g} over {CHECK_CONFIGURATIONS} configurations)",
            "not_positive_definite",
        )
    return smallest


def _identifiability(
    R: NDArray[np.float64],
    c: NDArray[np.float64],
    columns: NDArray[np.int64],
    names: list[str],
    tolerance: float,
) -> tuple[int, list[str], str]:
    """The rank of the fit's system A z = b restricted to ``columns`` (R, c: its compressed
    triangle, ||A z - b||^2 = ||R z - c||^2 + r0^2), the names of the parameters entering a
    null direction and, below full rank, dynid.least_squares' message naming them ("" at full
    rank): least_squares' rank test (_qr.solve_triangular_system) on the triangle of
    [A[:, columns] | b], padded with zero rows when the data have fewer rows than columns."""
    count = columns.size
    factor = np.zeros((count + 1, count + 1))
    top = upper_triangle(np.column_stack([R[:, columns], c]))
    factor[: top.shape[0]] = top
    _, _, rank, null, _ = solve_triangular_system(factor, count, tolerance)
    if rank == count:
        return rank, [], ""
    free = np.abs(null).max(axis=1) > IDENTIFIABLE_TOLERANCE
    return rank, [names[j] for j in np.flatnonzero(free)], _rank_message(rank, count, null, names)


def _compressed(
    A: NDArray[np.float64], b: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """R, c = Q^T b and r0 with ||A z - b||^2 = ||R z - c||^2 + r0^2 for every z, from one
    Householder QR of [A | b] without forming Q: its triangle is [[R, c], [0, r0]]."""
    rows, columns = A.shape
    # LAPACK's geqrf directly: scipy.linalg.qr(mode="r") would also zero the whole (rows, P)
    # lower part, which costs as much as the factorisation here.
    factor, _, _, info = scipy.linalg.lapack.dgeqrf(np.column_stack([A, b]), overwrite_a=True)
    if info != 0:
        raise ValueError(f"Y: the QR factorisation failed (LAPACK info {info})")
    k = min(rows, columns)
    R, c = np.triu(factor[:k, :columns]), factor[:k, columns].copy()
    r0 = abs(float(factor[columns, columns])) if rows > columns else 0.0
    return R, c, r0


def _column_norms(A: NDArray[np.float64]) -> NDArray[np.float64]:
    # Norms of columns divided by their largest entry: no overflow of the squares.
    peak = np.abs(A).max(axis=0)
    peak[peak == 0] = 1.0
    norms = peak * np.linalg.norm(A / peak, axis=0)
    norms[norms == 0] = 1.0  # a column that is zero everywhere keeps the unit scale
    return norms
