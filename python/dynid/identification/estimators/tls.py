"""TLS: errors in variables, where the regressor itself is noisy -- the accelerations
differentiated twice from measured positions (generalized total least squares, Van Huffel &
Vandewalle, The Total Least Squares Problem, SIAM 1991, ch. 3; mixed LS-TLS, Golub, Hoffman &
Stewart 1987).

Least squares on a noisy regressor is biased: E[A^T A] = A0^T A0 + sum_i C_i, where C_i is the
covariance of row i's regressor error, so the normal matrix is too large and the estimate
shrinks towards zero (attenuation). TLS removes this when the error covariance of the rows of
[A | b] is known up to one factor: theta = -v[:p] / v[p], v the generalized eigenvector of the
smallest eigenvalue lambda of ([A | b]^T [A | b], C), C = sum_i blkdiag(C_i, sigma_tau_j^2).

**Noise model.** The regressor is linear in the accelerations: Y(q, qd, qdd) = Y(q, qd, 0) +
sum_m qdd_m g_m(q) with g_m = Y(q, 0, e_m) - Y(q, 0, 0) (computed by the model, blocks
included). An acceleration error delta_m (variance ``acceleration_noise``_m^2, independent
between joints, rad/s^2) makes row i's error sum_m delta_m g_im, so C_i = sum_m sigma_m^2
g_im g_im^T -- different in every row and between columns, which is the column scaling of TLS
done exactly. Columns without an acceleration part (gravity alone, friction, offsets,
position torques) have no error: they are the exact columns of mixed LS-TLS. The errors of
q (tiny against its range) and of qd (for central differences sigma_qd / sigma_qdd =
dt / sqrt(12)) are neglected. The torque noise sigma_tau_j is estimated from the residuals:
sigma_tau_j^2 = mean_j r_i^2 - mean_j theta^T C_i theta. With it the GTLS eigenvalue is exactly
1 and the first p rows of (S - C) [theta; -1] = 0 are the corrected normal equations

    (A^T W A - sum_i w_i^2 C_i) theta = A^T W b        (Fuller, Measurement Error Models,
                                                         1987, sect. 2.2; Kukush & Van Huffel)

solved here through the triangular factor R of the weighted A, theta = R^-1 (I - M)^-1 z with
M = R^-T (sum_i w_i^2 C_i) R^-1 (the share of each direction's energy that is noise; its
largest eigenvalue is reported and must be below 1). Rows are weighted per joint as WLS, w_j =
1 / sqrt(mean_j r_i^2), re-estimated from the corrected fit until the weights settle.

**Covariance.** The sandwich of these estimating equations: scores psi_i = w_i^2 (a_i r_i +
C_i theta), H = A^T W A - sum_i w_i^2 C_i, V from the scores summed over blocks of contiguous
samples (:mod:`._rows`): differentiated accelerations are correlated over neighbouring samples
and all joints' rows of one sample share the same delta.

**The physically consistent fit** would minimise the corrected quadratic theta^T H theta -
2 theta^T A^T W b under the constraints (convex when H > 0), which the row weights the physical
fit takes cannot express: ``physical=True`` with this method is refused.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from ..identify import VARIANCE_FLOOR
from ._rows import Rows, block_sums, estimate, positive_number, sandwich, stacked_rows
from .base import EstimatorFit, Problem

#: Samples per evaluation of the acceleration part of the regressor (n + 1 regressor calls).
CHUNK = 2048
MAX_ITERATIONS = 50
#: The weights have settled when they change by less than this (relative).
TOLERANCE = 1e-10
#: The largest noise share allowed: beyond it the corrected normal matrix is (nearly) singular.
MAX_NOISE_SHARE = 1.0 - 1e-6


def tls(problem: Problem) -> EstimatorFit:
    """The errors-in-variables estimate with the accelerations' noise
    ``options["acceleration_noise"]`` (rad/s^2, one number or one per joint), its sandwich
    covariance and a report of the noise model (module docstring)."""
    sigma_a = _acceleration_noise(problem.options.get("acceleration_noise"), problem.n)
    rows = stacked_rows(problem)
    index = np.full(problem.tau.shape, -1, dtype=np.int64)
    index[rows.sample, np.array(rows.joints)[rows.joint]] = np.arange(rows.N)
    q = np.concatenate([run.q for run in problem.runs])  # the stacked samples' positions
    K = _noise_gram(problem, q, rows, index, sigma_a)  # (joints, p, p): sum_i C_i per joint
    variance = np.asarray(problem.start.noise_variance, dtype=float)
    iterations, converged = 0, False
    for iterations in range(1, MAX_ITERATIONS + 1):  # noqa: B007 (reported)
        w = 1.0 / np.sqrt(_floored(variance))
        theta, share, H, R = _corrected(rows, K, w)
        r = rows.b - rows.A @ theta
        new = np.array([np.mean(x**2) for x in rows.per_joint(r)])
        settled = np.max(np.abs(new - variance) / np.maximum(new, 1e-300)) < TOLERANCE
        variance = new
        if settled:
            converged = True
            break
    w = 1.0 / np.sqrt(_floored(variance))
    theta, share, H, R = _corrected(rows, K, w)
    r = rows.b - rows.A @ theta
    Ctheta = _noise_times(problem, q, rows, index, sigma_a, theta)  # C_i theta per row
    wi2 = (w**2)[rows.joint]
    scores = wi2[:, None] * (rows.A * r[:, None] + Ctheta)
    covariance = sandwich(H, block_sums(rows, scores), rows.N, problem.p)
    counts = np.array([x.size for x in rows.per_joint(r)], dtype=float)
    propagated = np.array([theta @ K[k] @ theta for k in range(len(rows.joints))]) / counts
    torque_noise = np.maximum(variance - propagated, 0.0)
    cond = float(np.linalg.cond(R))
    result = estimate(
        problem, rows, theta, covariance, variance, method="tls", rank=problem.p,
        condition_number=cond,
    )  # fmt: skip
    report = {
        "acceleration_noise": [float(x) for x in sigma_a],
        "equation_noise": [float(np.sqrt(x)) for x in variance],  # 1 / the rows' weights
        "torque_noise": [float(np.sqrt(x)) for x in torque_noise],
        "propagated_noise": [float(np.sqrt(x)) for x in propagated],
        "noise_share": float(share),
        "iterations": iterations,
        "converged": converged,
    }
    notes = []
    # Beyond the residual variance's sampling error: the noise given explains more than all.
    too_large = propagated > variance * (1.0 + 3.0 * np.sqrt(2.0 / np.maximum(counts, 1.0)))
    if np.any(too_large):
        notes.append(
            "tls: the accelerations' noise explains more than the whole residual on joint(s) "
            + ", ".join(str(j + 1) for j, x in zip(rows.joints, too_large) if x)
            + ": acceleration_noise is probably too large"
        )
    return EstimatorFit(result, None, report, tuple(notes))


def _acceleration_noise(value: object, n: int) -> NDArray[np.float64]:
    """``acceleration_noise``: a number > 0 or n numbers >= 0 (not all 0), rad/s^2."""
    if value is None:
        raise ValueError(
            "acceleration_noise: method 'tls' needs the standard deviation of the "
            "accelerations' noise (rad/s^2; --acceleration-noise), which no fit can tell "
            "from the torques alone (docs/identification.md, 'TLS')"
        )
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return np.full(n, positive_number(value, "acceleration_noise"))
    if isinstance(value, Sequence) and not isinstance(value, str) and len(value) == n:
        ok = all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and 0 <= x < np.inf
            for x in value
        )
        if ok and any(x > 0 for x in value):
            return np.array(value, dtype=float)
    raise ValueError(
        f"acceleration_noise: expected a number > 0 or {n} numbers >= 0 (rad/s^2), got {value!r}"
    )


def _floored(variance: NDArray[np.float64]) -> NDArray[np.float64]:
    largest = variance.max()
    if not largest > 0:
        return np.ones_like(variance)
    return np.maximum(variance, VARIANCE_FLOOR * largest)


def _acceleration_part(problem: Problem, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """(c, n, m, p): g_m = Y(q, 0, e_m) - Y(q, 0, 0) at the positions q (c, n), the
    regressor's derivative by the acceleration of joint m (the regressor is linear in qdd)."""
    zero = np.zeros_like(q)
    static = problem.model.regressor(q, zero, zero)
    parts = []
    for m in range(problem.n):
        unit = zero.copy()
        unit[:, m] = 1.0
        parts.append(problem.model.regressor(q, zero, unit) - static)
    return np.stack(parts, axis=2)


def _chunks(problem: Problem) -> list[slice]:
    T = problem.tau.shape[0]
    return [slice(a, min(a + CHUNK, T)) for a in range(0, T, CHUNK)]


def _noise_gram(
    problem: Problem,
    q: NDArray[np.float64],
    rows: Rows,
    index: NDArray[np.int64],
    sigma_a: NDArray[np.float64],
) -> NDArray[np.float64]:
    """K_j = sum over joint j's rows of C_i = sum_m sigma_m^2 g_im g_im^T, (joints, p, p)."""
    K = np.zeros((len(rows.joints), problem.p, problem.p))
    for samples in _chunks(problem):
        g = _acceleration_part(problem, q[samples]) * sigma_a[None, None, :, None]
        for k, j in enumerate(rows.joints):
            t = index[samples, j] >= 0
            gj = g[t, j].reshape(-1, problem.p)  # every (sample, m) pair of joint j's rows
            K[k] += gj.T @ gj
    return K


def _noise_times(
    problem: Problem,
    q: NDArray[np.float64],
    rows: Rows,
    index: NDArray[np.int64],
    sigma_a: NDArray[np.float64],
    theta: NDArray[np.float64],
) -> NDArray[np.float64]:
    """(N, p): C_i theta = sum_m sigma_m^2 g_im (g_im^T theta) for every row."""
    out = np.zeros((rows.N, problem.p))
    for samples in _chunks(problem):
        g = _acceleration_part(problem, q[samples])
        gt = g @ theta  # (c, n, m)
        Cth = np.einsum("tjmp,tjm,m->tjp", g, gt, sigma_a**2)
        at = index[samples]
        mask = at >= 0
        out[at[mask]] = Cth[mask]
    return out


def _corrected(
    rows: Rows, K: NDArray[np.float64], w: NDArray[np.float64]
) -> tuple[NDArray[np.float64], float, NDArray[np.float64], NDArray[np.float64]]:
    """theta of the corrected normal equations with per-joint weights ``w``, the largest noise
    share, H = A^T W A - sum_j w_j^2 K_j and the triangular factor R of the weighted A."""
    p = rows.A.shape[1]
    wi = w[rows.joint]
    Rb = scipy.linalg.qr(
        np.column_stack([rows.A * wi[:, None], rows.b * wi]), mode="r", check_finite=False
    )[0][: p + 1]
    R, z = Rb[:p, :p], Rb[:p, p]
    Kw = np.einsum("k,kab->ab", w**2, K)
    # Column scaling D: R_s = R D^-1, so M = R_s^-T (D^-1 Kw D^-1) R_s^-1 is unit-free.
    d = np.linalg.norm(R, axis=0)
    d[d == 0] = 1.0
    Rs = R / d
    Ks = Kw / np.outer(d, d)
    X = scipy.linalg.solve_triangular(Rs, Ks, trans="T")  # R_s^-T K_s
    M = scipy.linalg.solve_triangular(Rs, X.T, trans="T").T  # R_s^-T K_s R_s^-1
    M = 0.5 * (M + M.T)
    share = float(np.linalg.eigvalsh(M).max())
    if not share < MAX_NOISE_SHARE:
        raise ValueError(
            f"acceleration_noise: the accelerations' noise would explain {100 * share:.4g} % of "
            "a direction of the regressor (the corrected normal matrix is not positive "
            "definite): the noise given is larger than the data allow"
        )
    y = np.linalg.solve(np.eye(p) - M, z)
    theta = scipy.linalg.solve_triangular(Rs, y) / d
    H = R.T @ R - Kw
    return theta, share, 0.5 * (H + H.T), R
