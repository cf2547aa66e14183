"""Separable nonlinear least squares: a block's nonlinear parameters (the Stribeck friction's
velocity scales) estimated on the training logs by variable projection.

The torque model tau = F theta_F + Phi(rho) theta_Phi is linear in every coefficient theta and
nonlinear only in the few parameters rho of the blocks that have a nonlinear part
(:meth:`dynid.identification.blocks.Block.nonlinear`); F are the columns that do not depend on
rho (the robot's base columns, computed once, and the other blocks'). Variable projection
(Golub & Pereyra, SIAM J. Numer. Anal. 10(2), 1973; review in Inverse Problems 19, 2003)
eliminates theta: for fixed rho the best theta is a linear least-squares solution, and rho
minimises the norm of the projected residual

    r(rho) = P_perp[F, Phi(rho)] W tau

(W the rows' weights). Here P_perp[F, Phi] = P_perp(C) P_perp(F) with C = P_perp(F) W Phi: the
orthonormal basis of W F is computed once per weighting, and each evaluation projects only the
block's few columns. The outer problem is ``scipy.optimize.least_squares`` (trust region
reflective) over log rho within the block's bounds, with Kaufman's Jacobian (Kaufman, BIT 15,
1975): dr/d log rho_i = -P_perp[F, Phi] W d(Phi theta_Phi)/d log rho_i, which drops a term
proportional to the residual and is the Gauss-Newton Jacobian of the full problem with theta
eliminated. The objective is not convex in rho: the problem is solved from each of the blocks'
starting values, and again from the best of them parameter by parameter (:meth:`_Problem.start`).

Weights: ``method="ols"`` weighs every row 1. Otherwise (WLS, and the registered estimators,
which start from WLS) rho is first estimated unweighted, each joint's noise variance is taken
from those residuals as :func:`dynid.least_squares` does (sigma_j^2 = ||r_j||^2 / (N_j (N - p)
/ N), p counting rho), and rho is estimated again with rows weighted 1 / sigma_j.

Uncertainty: the covariance of rho is s^2 (J^T J)^-1 with J the Jacobian above at the estimate
(the rho block of the full problem's Gauss-Newton covariance, by the Schur complement), s^2 = 1
with WLS weights (variances taken as known, as WLS does) and ||r||^2 / (N - p) for OLS; the
linear coefficients fitted afterwards with rho fixed get, by the delta method, G Cov(rho) G^T
added to their covariance, G = d theta / d rho = -(W A)^+ W d(Phi theta_Phi)/d rho with A all
the columns (:meth:`Separable.widen`). Both use the weights the final fit uses (sigma_j from the
unweighted residuals at the estimate, as :func:`dynid.identify_log`'s WLS computes them).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from ..logs.log_files import Log
from .blocks.base import Block, Nonlinear
from .blocks.rigid_body import RigidBody
from .identify import VARIANCE_FLOOR, LeastSquaresResult, _excluded, relative_std

#: Relative singular-value cut of the bases (as the least squares' rank tolerance).
RANK_TOLERANCE = 1e-10
#: Tolerances of the outer problem (scipy's ftol, xtol, gtol).
TOLERANCE = 1e-12
#: Largest number of evaluations of the outer problem, per weighting.
MAX_EVALUATIONS = 200


@dataclass(frozen=True, eq=False)
class Separable:
    """The blocks with their nonlinear parameters estimated, what the estimate did (``notes``)
    and the covariance that rho's uncertainty adds to the linear coefficients (``added``,
    (p, p) in the order of theta; None without nonlinear parameters)."""

    blocks: tuple[Block, ...]
    notes: tuple[str, ...] = ()
    added: NDArray[np.float64] | None = field(default=None, repr=False)
    #: the base columns of each training log (T_r, n, count), computed here once, for the
    #: least squares that follows (None without nonlinear parameters)
    rigid_columns: tuple[NDArray[np.float64], ...] | None = field(default=None, repr=False)

    def widen(self, fit: LeastSquaresResult) -> LeastSquaresResult:
        """``fit`` (OLS or WLS with rho fixed at its estimate) with ``added`` in its covariance
        and standard deviations; a registered estimator's fit is returned as it is (its
        covariance is conditional on rho, which a note says)."""
        if self.added is None or fit.method not in ("ols", "wls"):
            return fit
        covariance = fit.covariance + self.added
        std = np.sqrt(np.maximum(np.diag(covariance), 0.0))
        return replace(
            fit, covariance=covariance, std=std, relative_std=relative_std(fit.theta, std)
        )


def estimate_nonlinear(
    rigid: RigidBody,
    blocks: Sequence[Block],
    runs: Sequence[Log],
    row_masks: Sequence[NDArray[np.bool_] | None],
    *,
    method: str,
    exclude_joints: Sequence[int] = (),
) -> Separable:
    """The blocks (in order) with the nonlinear parameters of those that have some estimated
    on the prepared training ``runs`` (q, qd, qdd, tau; ``row_masks`` the rows kept per log,
    None for all), the other blocks unchanged (module docstring). Without a nonlinear block:
    the blocks as given, nothing computed."""
    blocks = tuple(blocks)
    if all(b.nonlinear() is None for b in blocks):
        return Separable(blocks)
    problem = _Problem(rigid, blocks, runs, row_masks, exclude_joints)
    unit = np.ones(problem.N)
    x, evaluations = problem.start(unit)
    weights = unit
    if method != "ols":  # WLS: 1 / sigma_j from the unweighted fit, then again
        weights = problem.joint_weights(x)
        x, more = problem.solve(x, weights)
        evaluations += more
        weights = problem.joint_weights(x)  # those of the final fit at the estimate
    cov_rho, added = problem.covariance(x, weights, weighted=method != "ols")
    std = np.sqrt(np.maximum(np.diag(cov_rho), 0.0))
    std[~np.isfinite(np.diag(cov_rho))] = np.inf
    fitted = problem.with_parameters(x, std)
    values = np.exp(np.clip(x, problem.lower, problem.upper))
    estimates = ", ".join(f"{a} {v:.4g} ± {s:.2g}" for a, v, s in zip(problem.names, values, std))
    notes = [
        f"nonlinear parameters estimated by separable least squares (variable projection, "
        f"{'OLS' if method == 'ols' else 'WLS'} rows, {evaluations} evaluations): {estimates}"
    ]
    bound = [
        name
        for name, v, lo, hi in zip(problem.names, x, problem.lower, problem.upper)
        if np.isclose(v, lo, rtol=0, atol=1e-6) or np.isclose(v, hi, rtol=0, atol=1e-6)
    ]
    if bound:
        notes.append(
            f"{', '.join(bound)} on a bound of their range (a constrained estimate: their "
            "standard deviations are those of the unconstrained linearisation)"
        )
    if method not in ("ols", "wls"):
        notes.append(
            "the standard deviations of the linear coefficients are those of the estimator "
            "with the nonlinear parameters fixed (their own uncertainty not added)"
        )
    return Separable(fitted, tuple(notes), added, problem.rigid_columns)


class _Problem:
    """The stacked training rows: F (columns that do not depend on rho), tau, the joint of each
    row, and the states to evaluate the nonlinear blocks' columns at."""

    def __init__(
        self,
        rigid: RigidBody,
        blocks: tuple[Block, ...],
        runs: Sequence[Log],
        row_masks: Sequence[NDArray[np.bool_] | None],
        exclude_joints: Sequence[int],
    ) -> None:
        self.blocks = blocks
        self.nonlinear = [i for i, b in enumerate(blocks) if b.nonlinear() is not None]
        parts: list[Nonlinear] = [blocks[i].nonlinear() for i in self.nonlinear]  # type: ignore[misc]
        self.names = [name for part in parts for name in part.names]
        self.lower = np.log(np.concatenate([part.lower for part in parts]))
        self.upper = np.log(np.concatenate([part.upper for part in parts]))
        # The blocks' starting values (the first: their current values), in log rho.
        count = max(len(part.starts) for part in parts)
        self.starts = [
            np.log(np.concatenate([part.starts[min(s, len(part.starts) - 1)] for part in parts]))
            for s in range(count)
        ]
        q = np.concatenate([run.q for run in runs])
        qd = np.concatenate([_velocity(run) for run in runs])
        keep = np.concatenate(
            [np.ones(run.tau.shape, bool) if m is None else m for run, m in zip(runs, row_masks)]
        )
        keep[:, sorted(_excluded(exclude_joints, q.shape[1]))] = False
        self.q, self.qd, self.keep = q, qd, keep
        self.tau = np.concatenate([run.tau for run in runs])[keep]
        self.joint = np.nonzero(keep)[1]
        self.N = int(keep.sum())
        # The columns that do not change with rho, once: the base columns (one C++ batch call
        # per log) and the other blocks'.
        self.rigid_columns = tuple(rigid.columns(*_signals(run)) for run in runs)
        fixed = [np.concatenate(self.rigid_columns)]
        fixed += [b.columns(q, qd) for i, b in enumerate(blocks) if i not in self.nonlinear]
        self.F = np.concatenate(fixed, axis=2)[keep]
        # Where each group of columns sits in theta: rigid, then the blocks in order.
        starts = np.cumsum([0, rigid.size, *(b.size for b in blocks)])
        fixed_index = [np.arange(rigid.size)] + [
            np.arange(starts[i + 1], starts[i + 2]) for i in range(len(blocks))
        ]
        self.F_index = np.concatenate(
            [fixed_index[0]]
            + [fixed_index[i + 1] for i in range(len(blocks)) if i not in self.nonlinear]
        )
        self.Phi_index = np.concatenate([fixed_index[i + 1] for i in self.nonlinear])
        self.p = int(starts[-1])
        self._basis: tuple[bytes, NDArray[np.float64]] | None = None

    # ------------------------------------------------------------------ evaluation

    def with_parameters(
        self, x: NDArray[np.float64], std: NDArray[np.float64] | None = None
    ) -> tuple[Block, ...]:
        """The blocks with rho = exp(x) (and these standard deviations of rho)."""
        out = list(self.blocks)
        values = np.clip(np.exp(x), np.exp(self.lower), np.exp(self.upper))
        std = np.full(values.size, np.inf) if std is None else std
        k = 0
        for i in self.nonlinear:
            size = out[i].nonlinear().size  # type: ignore[union-attr]
            out[i] = out[i].with_parameters(values[k : k + size], std[k : k + size])
            k += size
        return tuple(out)

    def basis_F(self, weights: NDArray[np.float64]) -> NDArray[np.float64]:
        """Orthonormal basis of the weighted fixed columns (cached per weighting)."""
        key = weights.tobytes()
        if self._basis is None or self._basis[0] != key:
            self._basis = (key, _basis(weights[:, None] * self.F))
        return self._basis[1]

    def evaluate(
        self, x: NDArray[np.float64], weights: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """r (N,), Kaufman's Jacobian J (N, k), the block's coefficients theta_Phi and the
        weighted derivative rows W d(Phi theta_Phi)/d log rho (N, k), at rho = exp(x)."""
        blocks = self.with_parameters(x)
        U = self.basis_F(weights)
        b = weights * self.tau
        b -= U @ (U.T @ b)
        Phi = np.concatenate([blocks[i].columns(self.q, self.qd) for i in self.nonlinear], axis=2)
        C = weights[:, None] * Phi[self.keep]
        C -= U @ (U.T @ C)
        Uc, coefficients = _solve(C, b)
        r = b - Uc @ (Uc.T @ b)
        D = self.derivatives(blocks, coefficients, weights)
        J = D - U @ (U.T @ D)
        J -= Uc @ (Uc.T @ J)
        return r, -J, coefficients, D

    def derivatives(
        self, blocks: tuple[Block, ...], coefficients: NDArray[np.float64], weights: NDArray
    ) -> NDArray[np.float64]:
        """(N, k) weighted rows of d(Phi theta_Phi)/d log rho."""
        parts, k = [], 0
        for i in self.nonlinear:
            size = blocks[i].size
            d = blocks[i].torque_derivatives(self.q, self.qd, coefficients[k : k + size])
            parts.append(d[:, self.keep].T)
            k += size
        return weights[:, None] * np.concatenate(parts, axis=1)

    def solve(
        self, x0: NDArray[np.float64], weights: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], int]:
        """The outer problem from x0 (log rho): trust region reflective within the bounds."""
        cache: dict[bytes, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}

        def both(x: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
            key = x.tobytes()
            if key not in cache:
                cache.clear()
                r, J, _, _ = self.evaluate(x, weights)
                cache[key] = (r, J)
            return cache[key]

        start = np.clip(x0, self.lower, self.upper)
        outcome = least_squares(
            lambda x: both(x)[0],
            start,
            jac=lambda x: both(x)[1],
            bounds=(self.lower, self.upper),
            method="trf",
            x_scale="jac",
            ftol=TOLERANCE,
            xtol=TOLERANCE,
            gtol=TOLERANCE,
            max_nfev=MAX_EVALUATIONS,
        )
        return outcome.x, int(outcome.nfev)

    def start(self, weights: NDArray[np.float64]) -> tuple[NDArray[np.float64], int]:
        """A start for the final solve: the outer problem solved from each of the blocks'
        starting values (``Nonlinear.starts``), then, parameter by parameter, the value of the
        start that fits best the rows the parameter acts on (those where its torque derivative
        is not zero: its joint's rows for a decoupled drive), which is solved again; the best
        of all these. The objective is not convex in rho: a drive whose stiction column
        vanishes (vs below its smallest speeds) or spans every speed (vs above them) is a local
        minimum, and each drive may need another start."""
        solutions, evaluations = [], 0
        for x0 in self.starts:
            x, count = self.solve(x0, weights)
            evaluations += count
            r, _, _, D = self.evaluate(x, weights)
            solutions.append((float(r @ r), x, r, D))
        acts = np.zeros((self.lower.size, self.N), dtype=bool)  # rows each parameter acts on
        for _, _, _, D in solutions:
            acts |= (D != 0).T
        combined = np.array(
            [
                min(solutions, key=lambda s: float(s[2][acts[i]] @ s[2][acts[i]]))[1][i]
                for i in range(self.lower.size)
            ]
        )
        x, count = self.solve(combined, weights)
        r = self.evaluate(x, weights)[0]
        best = min(solutions, key=lambda s: s[0])
        return (x if float(r @ r) <= best[0] else best[1]), evaluations + count

    def joint_weights(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """1 / sigma_j per row from the unweighted residuals at rho = exp(x), as the WLS of
        :func:`dynid.least_squares` (the variances floored at VARIANCE_FLOOR of the largest;
        equal weights when every joint is fitted exactly)."""
        r = self.evaluate(x, np.ones(self.N))[0]
        joints = np.unique(self.joint)
        dof = self.N - self.p - x.size
        squares = np.array([np.sum(r[self.joint == j] ** 2) for j in joints])
        counts = np.array([np.sum(self.joint == j) for j in joints], dtype=float)
        variance = squares / (counts * dof / self.N)
        if variance.max() == 0:
            return np.ones(self.N)
        floored = np.maximum(variance, VARIANCE_FLOOR * variance.max())
        sigma = np.zeros(int(self.joint.max()) + 1)
        sigma[joints] = np.sqrt(floored)
        return 1.0 / sigma[self.joint]

    def covariance(
        self, x: NDArray[np.float64], weights: NDArray[np.float64], *, weighted: bool
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Cov(rho) (k, k) in log rho converted to rho, and G Cov(log rho) G^T (p, p) in the
        order of theta (module docstring)."""
        r, J, _, D = self.evaluate(x, weights)
        dof = self.N - self.p - x.size
        scale = 1.0 if weighted else float(r @ r) / max(dof, 1)
        cov_log = scale * _inverse_normal(J)
        values = np.exp(x)
        cov_rho = cov_log * np.outer(values, values)  # d rho = rho d log rho
        blocks = self.with_parameters(x)
        Phi = np.concatenate([blocks[i].columns(self.q, self.qd) for i in self.nonlinear], axis=2)
        A = weights[:, None] * np.concatenate([self.F, Phi[self.keep]], axis=1)
        # G = d theta / d log rho = -(W A)^+ W d(Phi theta_Phi)/d log rho (Kaufman's term).
        G_parts = -np.linalg.lstsq(A, D, rcond=None)[0]
        G = np.zeros((self.p, x.size))
        G[np.concatenate([self.F_index, self.Phi_index])] = G_parts
        finite = np.where(np.isfinite(cov_log), cov_log, 0.0)
        added = G @ finite @ G.T
        unknown = ~np.isfinite(np.diag(cov_log))
        if unknown.any():  # a rho the data do not fix: the coefficients it moves have no std
            moved = np.abs(G[:, unknown]).max(axis=1) > 0
            added[moved, :] = np.inf
            added[:, moved] = np.inf
        return cov_rho, added


def _velocity(run: Log) -> NDArray[np.float64]:
    return _signals(run)[1]


def _signals(run: Log) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    assert run.qd is not None and run.qdd is not None  # identify_log's prepared logs have them
    return run.q, run.qd, run.qdd


def _basis(A: NDArray[np.float64]) -> NDArray[np.float64]:
    """Orthonormal basis of the column space of A (SVD of the column-scaled matrix, singular
    values below RANK_TOLERANCE of the largest dropped: rank deficiency is the final fit's to
    report)."""
    norms = np.linalg.norm(A, axis=0)
    scaled = A[:, norms > 0] / norms[norms > 0]
    if scaled.shape[1] == 0:
        return np.zeros((A.shape[0], 0))
    U, s, _ = np.linalg.svd(scaled, full_matrices=False)
    return U[:, s > RANK_TOLERANCE * s[0]]


def _solve(
    C: NDArray[np.float64], b: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Basis of C's columns and the minimum-norm (column-scaled) solution of C theta = b
    (QR, then the SVD of the small triangular factor: C D^-1 = (Q U) S V^T)."""
    norms = np.linalg.norm(C, axis=0)
    safe = np.where(norms > 0, norms, 1.0)
    Q, R = np.linalg.qr(C / safe)
    U, s, Vt = np.linalg.svd(R)
    U = Q @ U
    rank = int(np.sum(s > RANK_TOLERANCE * s[0])) if s.size and s[0] > 0 else 0
    U, s, Vt = U[:, :rank], s[:rank], Vt[:rank]
    theta = (Vt.T @ ((U.T @ b) / s)) / safe
    return U, theta


def _inverse_normal(J: NDArray[np.float64]) -> NDArray[np.float64]:
    """(J^T J)^-1 by the SVD of the column-scaled J; the parameters in a direction J does not
    see (relative singular value below RANK_TOLERANCE) get inf rows and columns."""
    norms = np.linalg.norm(J, axis=0)
    k = J.shape[1]
    out = np.full((k, k), np.inf)
    seen = norms > 0
    if not seen.any():
        return out
    _, s, Vt = np.linalg.svd(J[:, seen] / norms[seen], full_matrices=False)
    good = s > RANK_TOLERANCE * s[0]
    inverse = (Vt[good].T / s[good] ** 2) @ Vt[good]
    inverse /= np.outer(norms[seen], norms[seen])
    index = np.nonzero(seen)[0]
    out[np.ix_(index, index)] = inverse
    if not good.all():  # parameters entering a direction J does not see
        free = np.abs(Vt[~good]).max(axis=0) > 1e-8
        out[index[free], :] = np.inf
        out[:, index[free]] = np.inf
    return out
