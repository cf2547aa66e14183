"""The pieces of :func:`dynid.identify_drive_gains`'s stacked system and its solvers.

- :class:`CurrentModel`: the unknowns (the torque model's coefficients, the drive gains, the
  payload's estimated parameters), each group's slice by name, and the rows of a run;
- :func:`payload_vector`: the known part of the payload's standard parameters pi_L and which of
  them are unknowns (with a known mass only);
- :func:`visible_payload`: the payload parameters the base parameters tell apart;
- :func:`total_least_squares` (TLS, Gautier & Briot, FIGAROH) and :func:`current_least_squares`
  (maximum likelihood for white current noise), both on the triangular factors of [A | b]
  (``dynid.identification._qr``). docs/drive_gains.md gives the reasons and the measured accuracy.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._core import physical_inconsistency, standard_parameters
from ._qr import GroupedTriangularFactors
from .blocks.drive_gains import DriveGains
from .blocks.model import IdentificationModel
from .identify import VARIANCE_FLOOR, RankDeficientError
from .payload import PAYLOAD_NAMES

#: "nls": function evaluations per Levenberg-Marquardt run: converged fits need 5-500; beyond,
#: the fit is running towards an infinite scale (a model that misses a term: gains of 1e9).
MAX_EVALUATIONS = 1000
#: "nls": a fit whose gains end more than this factor from the start's (in magnitude) ran away
#: towards an infinite scale (a model missing friction: gains of 1e25 that "converge"); with 5 %
#: current noise and the payload's mass alone, sound fits move up to 7 times from the WLS start.
DRIFT_LIMIT = 10.0
#: "nls": largest relative standard deviation of a gain accepted (beyond, the data do not fix
#: the scale: a likelihood that is flat along it).
MAX_RELATIVE_STD = 0.5


#: Name of the group of the payload's estimated parameters among the unknowns.
PAYLOAD = "payload"
#: Name of the group of the torque model's coefficients (base parameters and column blocks).
TORQUE = "torque"


@dataclass(frozen=True, eq=False)
class CurrentModel:
    """The unknowns x of identification from currents, in this order and each group's slice by
    name (:meth:`slice`): ``"torque"``, the torque model's coefficients (``torque``: the base
    parameters, then its column blocks); ``"drive_gains"``, the gains k (``gains``, the
    drive-gain block); ``"payload"``, the payload's parameters that are estimated (``estimated``,
    indices into the 10 standard parameters; none when the whole payload is known, whose
    parameters are ``known``). A run's rows (:meth:`rows`; module docstring of
    :mod:`dynid.identification.drive_gains`):

        unloaded:  [Y | -diag(i) | 0] x = 0
        loaded:    [Y | -diag(i) | Y_n,estimated] x = -Y_n pi_known
    """

    torque: IdentificationModel
    gains: DriveGains
    known: NDArray[np.float64]
    estimated: tuple[int, ...]

    @property
    def n(self) -> int:
        return self.torque.n

    def sizes(self) -> dict[str, int]:
        """The groups of unknowns in order, with their sizes."""
        gains = self.gains
        return {TORQUE: self.torque.size, gains.key: gains.size, PAYLOAD: len(self.estimated)}

    @property
    def size(self) -> int:
        return sum(self.sizes().values())

    def slice(self, key: str) -> slice:
        """The unknowns of the group ``key`` ("torque", "drive_gains" or "payload")."""
        start = 0
        for name, size in self.sizes().items():
            if name == key:
                return slice(start, start + size)
            start += size
        raise ValueError(f"key: expected one of {', '.join(self.sizes())}, got {key!r}")

    def names(self, torque_names: list[str]) -> list[str]:
        """The unknowns' names, ``torque_names`` those of the torque model's coefficients."""
        return [*torque_names, *self.gains.names(), *(PAYLOAD_NAMES[c] for c in self.estimated)]

    def rows(
        self,
        q: NDArray[np.float64],
        qd: NDArray[np.float64],
        qdd: NDArray[np.float64],
        current: NDArray[np.float64],
        loaded: bool,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(A, b): (T, n, size) and (T, n), the rows of T samples of a run."""
        n = self.n
        A = np.zeros((q.shape[0], n, self.size))
        A[:, :, self.slice(TORQUE)] = self.torque.regressor(q, qd, qdd)
        A[:, :, self.slice(self.gains.key)] = self.gains.columns(current)
        b = np.zeros((q.shape[0], n))
        if loaded:
            # The payload on the last link: the rule of change of the parameters (notes p. 33),
            # the last link's 10 standard columns.
            rigid = self.torque.rigid
            Yn = rigid.robot.regressor(
                q, qd, qdd, rotor=rigid.rotor, friction=rigid.friction,
                columns=np.arange(10 * (n - 1), 10 * n),
            ).reshape(q.shape[0], n, 10)  # fmt: skip
            A[:, :, self.slice(PAYLOAD)] = Yn[:, :, list(self.estimated)]
            b = -(Yn @ self.known)
        return A, b


def payload_vector(
    payload: ArrayLike | Mapping[str, Any] | None, mass: float | None
) -> tuple[NDArray[np.float64], list[int]]:
    """The known part of pi_L (10,) and the indices of its estimated entries."""
    if (payload is None) == (mass is None):
        raise ValueError(
            "payload, payload_mass: give exactly one: the payload's 10 parameters (or mass, com, "
            "inertia) or its mass alone; without either the scale of (theta, k) is undetermined"
        )
    if mass is not None:
        value = checks.real_array(mass, "payload_mass")
        if value.ndim != 0 or not value > 0:
            raise ValueError(f"payload_mass: expected a positive mass in kg, got {mass!r}")
        known = np.zeros(10)
        known[0] = float(value)
        return known, list(range(1, 10))
    if isinstance(payload, Mapping):
        unknown = sorted(set(payload) - {"mass", "com", "inertia"})
        if unknown or "mass" not in payload or "com" not in payload:
            raise ValueError(
                "payload: expected a mapping with mass, com and optionally inertia (about the "
                f"centre of mass, frame n), got the keys {sorted(payload)}"
            )
        m = checks.real_array(payload["mass"], "payload.mass")
        if m.ndim != 0 or not m > 0:
            raise ValueError(f"payload.mass: expected a positive mass, got {payload['mass']!r}")
        com = checks.real_array(payload["com"], "payload.com")
        inertia = checks.real_array(payload.get("inertia", np.zeros((3, 3))), "payload.inertia")
        if com.shape != (3,) or inertia.shape != (3, 3):
            raise ValueError(
                f"payload: expected com (3,) and inertia (3, 3), got {com.shape} and "
                f"{inertia.shape}"
            )
        why = physical_inconsistency(float(m), inertia) if "inertia" in payload else ""
        if why:  # (a point mass, without inertia, is possible)
            raise ValueError(f"payload.inertia: the payload is not physically possible: {why}")
        return np.asarray(standard_parameters(float(m), com, inertia), dtype=float), []
    assert payload is not None  # exactly one of payload, mass was given
    known = checks.real_array(payload, "payload")
    if known.shape != (10,):
        raise ValueError(
            f"payload: expected the 10 standard parameters (m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, "
            f"Iyz, Izz) in frame n, got shape {known.shape}"
        )
    if not known[0] > 0:
        raise ValueError(f"payload: expected a positive mass (first entry), got {known[0]!r}")
    return known.copy(), []


def visible_payload(beta_n: NDArray[np.float64]) -> list[int]:
    """Among the payload's first moments and inertia (columns 1..9 of beta's last-link block),
    those the base parameters tell apart, greedily left to right (as base_parameters picks its
    columns); ValueError when the mass is not distinguishable from them."""
    scale = np.linalg.norm(beta_n, axis=0)
    scale[scale == 0] = 1.0
    B = beta_n / scale
    kept: list[int] = []
    for c in range(1, 10):
        if _rank(B[:, [*kept, c]]) > len(kept):
            kept.append(c)
    if _rank(B[:, [0, *kept]]) <= len(kept):
        raise ValueError(
            "payload_mass: on this structure the payload's mass acts on the joint torques only "
            "through combinations its other parameters also enter, so a known mass cannot fix "
            "the scale; give the whole payload (payload=...)"
        )
    return kept


def _rank(M: NDArray[np.float64]) -> int:
    s = scipy.linalg.svdvals(M)
    return int(np.count_nonzero(s > 1e-10 * max(s[0], 1.0))) if s.size else 0


def total_least_squares(
    factors: GroupedTriangularFactors,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """TLS of the stacked [A | b] from its triangular factor (the same right singular vectors),
    rows unweighted as in FIGAROH, columns scaled to unit norm (units do not matter). Returns x
    and the first-order covariance of an unweighted fit with per-joint noise sigma_j (from the
    TLS residuals): G^-1 (sum_j sigma_j^2 A_j^T A_j) G^-1, G = A^T A."""
    p = factors.p
    x = tls_solution(factors.combined())
    shift = (factors.b_exp or 0) - (factors.a_exp or 0)  # back from the factors' units
    Rs = [R[:, :p] for R in factors.factors.values()]
    rows = factors.rows
    variance = factors.residual_squares(x) / (factors.samples * (rows - p) / rows)
    scale = np.sqrt(sum(np.sum(R**2, axis=0) for R in Rs))
    scale[scale == 0] = 1.0
    G = sum((R / scale).T @ (R / scale) for R in Rs)
    H = sum(v * (R / scale).T @ (R / scale) for v, R in zip(variance, Rs))
    inverse = np.linalg.pinv(G, hermitian=True)
    covariance = (inverse @ H @ inverse) / np.outer(scale, scale)
    return np.ldexp(x, shift), np.ldexp(covariance, 2 * shift)


def current_least_squares(
    factors: GroupedTriangularFactors, starts: list[NDArray[np.float64]], gains: slice
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Weighted nonlinear least squares on the currents, from the first of ``starts`` (the WLS
    and TLS solutions) from which it converges.

    Joint j's equations Y theta - i k_j = d, divided by k_j, are i = (Y theta - d) / k_j: the
    measured current as the output, so white current noise e_j is the residual and minimising
    sum_j ||A_j x - b_j||^2 / (s_j k_j)^2 is maximum likelihood (s_j the current noise, from the
    residuals, re-estimated twice). Each joint's term is ||R_j [x; -1]||^2 / (s_j k_j)^2 with R_j
    its triangular factor, so the fit never returns to the samples. A fit counts when
    Levenberg-Marquardt converges within MAX_EVALUATIONS with the gains within DRIFT_LIMIT of
    the start's; the covariance is the Gauss-Newton (J^T J)^-1. WLS first: biased low but sane,
    the fit converges from it in a few iterations; TLS breaks down at high noise (gains of the
    wrong sign at 5 % current noise on the LWR) and costs the full MAX_EVALUATIONS then."""
    from scipy.optimize import least_squares as nonlinear_least_squares

    shift = (factors.b_exp or 0) - (factors.a_exp or 0)
    Rs = list(factors.factors.values())
    gain = [gains.start + j for j in factors.joints]  # k_j among the unknowns x
    rows = factors.rows
    size = starts[0].size
    dof = factors.samples * (rows - size) / rows
    for start in starts:
        if not np.any(factors.residual_squares(np.ldexp(start, -shift)) > 0):
            return start, np.zeros((size, size))  # noise-free: exact already

    def squares(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.array([np.sum((R @ np.append(x, -1.0)) ** 2) for R in Rs])

    def noise(x: NDArray[np.float64]) -> NDArray[np.float64]:
        s = np.sqrt(squares(x) / dof) / np.abs(x[gain])
        return np.maximum(s, np.sqrt(VARIANCE_FLOOR) * s.max())

    def residual(x: NDArray[np.float64], s: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.concatenate(
            [R @ np.append(x, -1.0) / (sj * x[g]) for R, sj, g in zip(Rs, s, gain)]
        )

    def jacobian(x: NDArray[np.float64], s: NDArray[np.float64]) -> NDArray[np.float64]:
        blocks = []
        for R, sj, g in zip(Rs, s, gain):
            r = R @ np.append(x, -1.0)
            block = R[:, :-1] / (sj * x[g])
            block[:, g] -= r / (sj * x[g] ** 2)
            blocks.append(block)
        return np.vstack(blocks)

    best = None
    for start in starts:
        x = np.ldexp(start, -shift)  # the factors' units
        for _ in range(3):
            fit = nonlinear_least_squares(
                residual,
                x,
                jac=jacobian,
                args=(noise(x),),
                method="lm",
                x_scale="jac",
                xtol=1e-15,
                ftol=1e-15,
                gtol=1e-15,
                max_nfev=MAX_EVALUATIONS,
            )
            x, converged = fit.x, fit.status > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.abs(x[gain] / np.ldexp(start, -shift)[gain])
        if not (converged and np.all(ratio < DRIFT_LIMIT) and np.all(ratio > 1 / DRIFT_LIMIT)):
            continue  # no optimum, or one at a runaway scale (non-finite ratios fail too)
        best = x
        break
    if best is None:
        # The likelihood keeps rising towards an infinite common scale, where the payload's
        # rows stop mattering: they do not explain the data (a missing column, a wrong payload,
        # too much noise for what the payload shows).
        raise RankDeficientError(
            "the currents do not fix the scale: the nonlinear fit does not converge from its "
            "WLS and TLS starts (it runs towards an infinite scale): the payload's torques are "
            "too small against the noise, or not what the loaded run shows; use a heavier "
            "payload or more (richer) loaded motion, check the payload and the model's columns "
            "(rotor, friction, offset)"
        )
    flipped = [j + 1 for j, g in zip(factors.joints, gain) if best[g] * starts[0][g] < 0]
    if flipped:
        warnings.warn(
            f"the gains of joint(s) {', '.join(map(str, flipped))} have the other sign than in "
            "the least-squares start: the likelihood has competing optima at this noise level "
            "(measured with the payload's mass alone and 5 % current noise on the LWR, "
            "docs/drive_gains.md); give the whole payload or record more loaded motion",
            RuntimeWarning,
            stacklevel=3,
        )
    J = jacobian(best, noise(best))
    _, sv, Vt = np.linalg.svd(J, full_matrices=False)
    covariance = (Vt.T / sv**2) @ Vt
    relative = np.sqrt(np.diag(covariance)[gain]) / np.abs(best[gain])
    if not relative.max() < MAX_RELATIVE_STD:
        raise RankDeficientError(
            "the currents do not fix the scale: the gains' relative standard deviations reach "
            f"{100 * relative.max():.3g} %; record more (or richer) loaded motion, or give the "
            "whole payload rather than its mass"
        )
    return np.ldexp(best, shift), np.ldexp(covariance, 2 * shift)


def tls_solution(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """x = -v[:-1] / v[-1], v the right singular vector of the smallest singular value of R
    (the R of [A | b]) with unit-norm columns."""
    scale = np.linalg.norm(R, axis=0)
    scale[scale == 0] = 1.0
    _, _, Vt = scipy.linalg.svd(R / scale, lapack_driver="gesvd")
    v = Vt[-1] / scale
    if abs(v[-1]) <= 1e-12 * np.abs(v).max():
        raise RankDeficientError(
            "method: the total least-squares problem has no solution (the smallest singular "
            "vector of [A | b] does not involve the payload column): use method='wls'"
        )
    return -v[:-1] / v[-1]
