"""The paper's identification: dynamic coefficients from the controller's numeric M(q) and g(q).

Gaz, Flacco, De Luca, "Identifying the dynamic model used by the KUKA LWR: a reverse engineering
approach", ICRA 2014, Sect. V: g(q) = Y_g(q) pi_g (17) and the inertia stack m(q) = Y_m(q) pi_m
(18) are stacked over N configurations (21)-(22), reduced to base coefficients (23) and solved by
least squares (24)-(25). From the coefficients alone the model is rebuilt: g(q), M(q), the
Coriolis terms by Christoffel symbols (15)-(16) and the joint torques tau_J (26).

The two observations of Sect. VI are handled: joint 1's gravity row is left out (its axis is
vertical, so the controller's value is calibration noise), and elements of M that are zero in all
the data (the paper's M_76) are detected and turned into the linear constraints on the
coefficients that they imply, which the fit then satisfies exactly.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from .._equality import ValueEquality
from ..model.base_parameters import (
    BaseParameters,
    base_parameters,
    linear_expression,
    round_significant,
)
from ..model.robot import Robot
from .identify import LeastSquaresResult, RankDeficientError, least_squares, relative_std

#: An element of M counts as identically zero when |M_ij| <= this * max|M| in every sample.
ZERO_ELEMENT_TOLERANCE = 1e-12


@dataclass(frozen=True)
class ZeroElement:
    """An element of M that the data show to be identically zero, and what it implies."""

    row: int  #: 0-based indices (row >= column), i.e. M[row, column] == M[column, row] == 0
    column: int
    constraints: list[str]  #: readable linear constraints on the standard parameters, "... = 0"


@dataclass(eq=False)
class IdentifiedModel(ValueEquality):
    """The model rebuilt from identified coefficients; usable like a Robot for prediction.

    ``gravity``, ``mass_matrix``, ``coriolis``, ``coriolis_matrix`` and ``rnea`` (the joint
    torques of eq. (26)) take one sample (n,) or T samples (T, n). They run on two robots of the
    same structure whose standard parameters reproduce the identified coefficients (each base
    coefficient on its representative column, zeros elsewhere): M(q) and g(q) are then exactly
    Y_m(q) pi_m and Y_g(q) pi_g, and the Coriolis matrix is the Christoffel one of that M.
    """

    structure: Robot
    gravity_base: BaseParameters
    inertia_base: BaseParameters
    gravity_fit: LeastSquaresResult
    inertia_fit: LeastSquaresResult
    pi_g: NDArray[np.float64]  #: identified gravity coefficients (p_g,)
    pi_m: NDArray[np.float64]  #: identified inertia coefficients (p_m,)
    zero_elements: list[ZeroElement] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._gravity_robot = _robot_with(self.structure, self.gravity_base, self.pi_g)
        self._inertia_robot = _robot_with(self.structure, self.inertia_base, self.pi_m)
        self._inertia_robot.gravity_vector = (0.0, 0.0, 0.0)

    @property
    def n(self) -> int:
        return self.structure.n

    def gravity(self, q: ArrayLike) -> NDArray[np.float64]:
        """g_hat(q) = Y_g(q) pi_g, eq. (17)."""
        return self._gravity_robot.gravity(q)

    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]:
        """M_hat(q) from the inertia stack Y_m(q) pi_m, eq. (18)."""
        return self._inertia_robot.mass_matrix(q)

    def coriolis_matrix(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
        """S_hat(q, qd) from the Christoffel symbols of M_hat, eq. (16)."""
        return self._inertia_robot.coriolis_matrix(q, qd)

    def coriolis(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
        """c_hat(q, qd) = S_hat qd, eq. (15)."""
        return self._inertia_robot.coriolis(q, qd)

    def rnea(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """tau_J_hat = M_hat qdd + c_hat + g_hat, eq. (26)."""
        return self._inertia_robot.rnea(q, qd, qdd) + self.gravity(q)

    def coefficients(self) -> dict[str, list]:
        """The identified coefficients with their expressions, for reports and JSON."""
        out: dict[str, list] = {}
        for label, base, fit in (
            ("gravity", self.gravity_base, self.gravity_fit),
            ("inertia", self.inertia_base, self.inertia_fit),
        ):
            out[label] = [
                {"name": nm, "expression": ex, "value": float(v), "std": float(s)}
                for nm, ex, v, s in zip(base.names, base.expressions, fit.theta, fit.std)
            ]
        return out


def identify_from_controller(
    structure: Robot,
    q: ArrayLike,
    g: ArrayLike,
    M: ArrayLike,
    *,
    exclude_gravity_joints: Sequence[int] = (0,),
    method: str = "wls",
) -> IdentifiedModel:
    """Identify the gravity and inertia coefficients from controller readings (Sect. V).

    Parameters
    ----------
    structure
        A robot with the right DH table, joint types and gravity direction; its parameter values
        are not used.
    q, g, M
        (N, n), (N, n) and (N, n, n): configurations and the controller's numeric g(q), M(q).
    exclude_gravity_joints
        0-based joints whose gravity component is left out (paper: joint 1, Sect. VI-1).
    method
        ``"wls"`` (default) or ``"ols"`` (see :func:`dynid.identification.identify.least_squares`).
        The controller's numeric errors grow with the values, differently for each element of g and
        M, so weighting each element by its own residual variance gives honest standard
        deviations where the pooled variance of OLS understates them.
    """
    checks.robot(structure, "structure")
    n = structure.n
    exclude_gravity_joints = checks.indices(exclude_gravity_joints, "exclude_gravity_joints", n)
    q = _samples(q, "q", (n,))
    g = _samples(g, "g", (n,))
    M = _samples(M, "M", (n, n))
    if not (len(q) == len(g) == len(M)):
        raise ValueError(f"g, M: expected {len(q)} samples like q, got {len(g)} and {len(M)}")

    gravity_base = base_parameters(structure, "gravity")
    inertia_base = base_parameters(structure, "inertia")
    Yg = gravity_base.reduce(structure.gravity_regressor(q))  # (N, n, p_g), eq. (21)
    gravity_fit = least_squares(
        Yg,
        g,
        method=method,
        exclude_joints=exclude_gravity_joints,
        names=gravity_base.names,
    )

    rows, cols = np.tril_indices(n)
    stack = M[:, rows, cols]  # the inertia stack m(q), eq. (18)
    Ym = inertia_base.reduce(structure.inertia_regressor(q))  # (N, n(n+1)/2, p_m), eq. (22)
    zero_elements, null_space = _zero_elements(M, Ym, inertia_base, rows, cols)
    if not zero_elements:
        inertia_fit = least_squares(Ym, stack, method=method, names=inertia_base.names)
    else:
        try:
            reduced = least_squares(Ym @ null_space, stack, method=method)
        except RankDeficientError:
            # Name the unexcited coefficients: the unconstrained fit fails the same way.
            least_squares(Ym, stack, method=method, names=inertia_base.names)
            raise
        inertia_fit = _expand(reduced, null_space, inertia_base.names)

    return IdentifiedModel(
        structure=structure.copy(),
        gravity_base=gravity_base,
        inertia_base=inertia_base,
        gravity_fit=gravity_fit,
        inertia_fit=inertia_fit,
        pi_g=gravity_fit.theta,
        pi_m=inertia_fit.theta,
        zero_elements=zero_elements,
    )


def payload_mass_estimates(
    base: BaseParameters, before: ArrayLike, after: ArrayLike
) -> list[dict[str, float | str]]:
    """Payload mass from the change of identified coefficients, as in paper eqs. (31)-(32).

    A payload on link n changes m_n, m_n c_n and I_n. A base coefficient whose expression holds
    m_n with factor k but no other parameter of link n changes by exactly k * m_L, so each such
    coefficient gives an estimate m_L = (after - before) / k. The factors come from the base
    parameter expressions (for the LWR: d1 in pi_g(12), d2 in pi_g(7)), not from fixed indices.
    """
    before = real_array(before, "before")
    after = real_array(after, "after")
    for name, value in (("before", before), ("after", after)):
        if value.shape != (base.count,):
            raise ValueError(
                f"{name}: expected shape ({base.count},) (one value per base coefficient), "
                f"got {value.shape}"
            )
    last = base.parameter_names.index(f"m{_link_count(base)}")
    link_columns = slice(last, last + 10)
    estimates: list[dict[str, float | str]] = []
    for k, row in enumerate(base.beta):
        others = np.delete(row[link_columns], 0)
        if row[last] != 0.0 and not np.any(others):
            estimates.append(
                {
                    "coefficient": base.names[k],
                    "expression": base.expressions[k],
                    "factor": float(row[last]),
                    "mass": float((after[k] - before[k]) / row[last]),
                }
            )
    return estimates


# ---- helpers ------------------------------------------------------------------------------------


def _link_count(base: BaseParameters) -> int:
    return sum(1 for name in base.parameter_names if name.startswith("m") and name[1:].isdigit())


def _samples(value: ArrayLike, name: str, shape: tuple[int, ...]) -> NDArray[np.float64]:
    array = real_array(value, name)
    if array.ndim == len(shape):
        array = array[None]
    if array.shape[1:] != shape or array.shape[0] < 1:
        raise ValueError(
            f"{name}: expected shape (N, {', '.join(map(str, shape))}), got {array.shape}"
        )
    return array


def _zero_elements(
    M: NDArray, Ym: NDArray, base: BaseParameters, rows: NDArray, cols: NDArray
) -> tuple[list[ZeroElement], NDArray[np.float64]]:
    """Elements of M that are zero in all the data although the structure allows them, and an
    orthonormal basis of the coefficients that satisfy the constraints they imply."""
    scale = float(np.max(np.abs(M)))
    constraints = []
    found = []
    for r, (i, k) in enumerate(zip(rows, cols)):
        structural = Ym[:, r, :]
        if np.all(np.abs(M[:, i, k]) <= ZERO_ELEMENT_TOLERANCE * scale) and np.any(structural):
            # Y_m,r(q) pi_m = 0 for every q: pi_m is orthogonal to the row space of these rows.
            _, s, vt = np.linalg.svd(structural, full_matrices=False)
            space = vt[s > 1e-10 * s[0]]
            constraints.append(space)
            texts = [
                linear_expression(row, base.parameter_names) + " = 0"
                for row in _echelon(space @ base.beta)
            ]
            found.append(ZeroElement(int(i), int(k), texts))
    p = base.count
    if not constraints:
        return found, np.eye(p)
    C = np.vstack(constraints)
    _, s, vt = np.linalg.svd(C)
    rank = int(np.sum(s > 1e-10 * s[0]))
    basis = vt[rank:].T
    basis[np.abs(basis) < 1e-12] = 0.0  # constrained coefficients come out exactly zero
    return found, basis


def _echelon(rows: NDArray[np.float64]) -> NDArray[np.float64]:
    """Reduced row echelon form (pivots left to right), so that each constraint reads with a
    leading parameter of coefficient 1, e.g. "Ixz7 = 0" rather than a rotated combination."""
    A = rows.copy()
    pivot_row = 0
    for col in range(A.shape[1]):
        if pivot_row == A.shape[0]:
            break
        k = pivot_row + int(np.argmax(np.abs(A[pivot_row:, col])))
        if abs(A[k, col]) < 1e-9 * np.abs(A).max():
            continue
        A[[pivot_row, k]] = A[[k, pivot_row]]
        A[pivot_row] /= A[pivot_row, col]
        others = np.arange(A.shape[0]) != pivot_row
        A[others] -= np.outer(A[others, col], A[pivot_row])
        pivot_row += 1
    return round_significant(A[:pivot_row])


def _expand(
    reduced: LeastSquaresResult, null_space: NDArray[np.float64], names: list[str]
) -> LeastSquaresResult:
    """Map a fit in the constrained coordinates z (pi = N z) back to the coefficients."""
    if null_space.shape[0] == null_space.shape[1]:
        return reduced
    theta = null_space @ reduced.theta
    covariance = null_space @ reduced.covariance @ null_space.T
    std = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    return replace(
        reduced,
        theta=theta,
        std=std,
        relative_std=relative_std(theta, std),
        covariance=covariance,
        names=names,
    )


def _robot_with(structure: Robot, base: BaseParameters, coefficients: NDArray) -> Robot:
    """A robot of the same structure whose standard parameters give these base coefficients."""
    robot = structure.rigid_body()
    pi = np.zeros(10 * robot.n)
    pi[base.independent] = coefficients  # beta[:, independent] = I, so beta @ pi = coefficients
    robot.params = pi
    return robot
