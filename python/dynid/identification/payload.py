"""Payload estimation: mass, centre of mass and inertia of a load on the last link.

Rule of change (notes "Rule of change in dynamic parameters", p. 33; Gaz & De Luca, "Payload
estimation based on identified coefficients of robot dynamics - with an application to collision
detection", IEEE/RSJ IROS 2017): a rigid payload on link n changes only link n's standard
parameters, and additively when all are taken in frame n about its origin:
pi_n -> pi_n + pi_L with pi_L = (m_L, m_L c_L, I_L,O), I_L,O the payload's inertia about the
origin of frame n (Steiner). The model stays linear in the parameters, so the torques of the
loaded arm differ from those of the unloaded one by the last link's 10 regressor columns Y_n:

    tau_loaded - tau_unloaded = Y_n(q, qd, qdd) pi_L,

with tau_unloaded what the (identified) model of the unloaded arm predicts along the same motion.
Least squares on this difference (:func:`dynid.least_squares`: QR + SVD, per-joint noise for WLS,
joint exclusions) gives pi_L with its covariance; then m_L, the centre of mass
c_L = (m_L c_L) / m_L and the inertia about the centre of mass I_L,C = I_L,O - S(m_L c_L) / m_L
with S(h) = |h|^2 E - h h^T (Steiner back), their standard deviations by the delta method
(first-order propagation of the covariance through this map, exact for the linear parts m_L and
I_L,O, an approximation for c_L and I_L,C when m_L is small against its std).

From static data (qd = qdd = 0, e.g. the gravity vectors a controller returns) the inertia does
not enter the torques: only m_L and m_L c_L are identifiable (``inertia=False``). That is the
setting of paper eqs. (31)-(32) (:func:`dynid.payload_mass_estimates`), which read the mass alone
off the two gravity coefficients where m_n appears with no other parameter of link n.

The same rule of change applies to identified base coefficients (Gaz & De Luca's title): every
coefficient is linear in the standard parameters (``base.beta``), so a payload changes it by its
link-n part. :func:`payload_from_identified` solves the changes of the paper's gravity and
inertia coefficients (static controller readings, :func:`dynid.identify_from_controller`) for all
10 payload parameters; eqs. (31)-(32) are its rows that hold m_n alone.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .._checks import real_array
from .._equality import ValueEquality
from ..model.robot import PARAMETER_FIELDS, Robot
from .from_controller import IdentifiedModel
from .identify import LeastSquaresResult, RankDeficientError, least_squares

#: Names of the payload's standard parameters, in the order of the regressor columns
#: (docs/conventions.md, "Inertial parameters").
PAYLOAD_NAMES = tuple(f"{field}_L" for field in PARAMETER_FIELDS)
#: A mass estimate is "significant" (centre of mass and inertia about it reported) when above
#: SIGNIFICANCE standard deviations and above MASS_FLOOR times the arm's total link mass.
SIGNIFICANCE = 3.0
MASS_FLOOR = 1e-9
FRAMES = ("flange", "tool")
# Upper-triangle order of the inertia entries in the parameter vector: xx, xy, xz, yy, yz, zz.
_ROWS, _COLS = np.array([0, 0, 0, 1, 1, 2]), np.array([0, 1, 2, 1, 2, 2])


@dataclass(frozen=True, eq=False)
class PayloadEstimate(ValueEquality):
    """A payload's inertial parameters estimated by :func:`estimate_payload` (from torques) or
    :func:`payload_from_identified` (from identified coefficients).

    ``com`` and ``inertia`` are in ``frame`` (the last DH frame n, "flange", or the robot's tool
    frame, "tool"); ``parameters`` are always the standard parameters in frame n. ``com``,
    ``inertia`` and their std are None when the mass is not significantly positive (at most
    ``SIGNIFICANCE`` std or ``MASS_FLOOR`` times the arm's mass: no payload, or too little data):
    the centre of mass of a zero mass is undefined; ``inertia`` is also None with
    ``inertia=False``.

    From :func:`estimate_payload` the standard deviations reflect the noise of the loaded arm's
    torques (the least-squares residuals); an error of the unloaded model used for
    ``tau_unloaded`` is not in them. From :func:`payload_from_identified` they come from the
    covariances of both identifications.
    """

    mass: float  #: m_L [kg]
    mass_std: float
    com: NDArray[np.float64] | None  #: (3,) centre of mass c_L [m]
    com_std: NDArray[np.float64] | None
    inertia: NDArray[np.float64] | None  #: (3, 3) about the centre of mass [kg m^2]
    inertia_std: NDArray[np.float64] | None
    parameters: NDArray[np.float64]  #: (10,) or (4,) pi_L = (m, mx, my, mz[, Ixx..Izz about O_n])
    parameters_std: NDArray[np.float64]
    frame: str  #: "flange" or "tool"
    #: the least-squares fit of pi_L (residuals, condition number, ...); None from
    #: :func:`payload_from_identified`, which solves for pi_L from coefficient changes
    fit: LeastSquaresResult | None
    #: the width (samples) of the Bartlett kernel behind the standard deviations
    #: (:mod:`dynid.identification.serial_correlation`); 1: the rows taken as independent, as
    #: :func:`estimate_payload` and :func:`payload_from_identified` do
    bartlett_width: int = 1

    def as_dict(self) -> dict[str, object]:
        """JSON-ready values (floats, nested lists, None): mass, com, inertia with their std,
        the standard parameters and the frame."""

        def plain(value: NDArray[np.float64] | None) -> list | None:
            return None if value is None else np.asarray(value).tolist()

        return {
            "mass": self.mass,
            "mass_std": self.mass_std,
            "com": plain(self.com),
            "com_std": plain(self.com_std),
            "inertia": plain(self.inertia),
            "inertia_std": plain(self.inertia_std),
            "parameters": dict(zip(PAYLOAD_NAMES, self.parameters.tolist())),
            "parameters_std": dict(zip(PAYLOAD_NAMES, self.parameters_std.tolist())),
            "frame": self.frame,
            "bartlett_width": self.bartlett_width,
        }


def estimate_payload(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    tau: ArrayLike,
    *,
    tau_unloaded: ArrayLike | None = None,
    inertia: bool = True,
    exclude_joints: Sequence[int] = (),
    method: str = "ols",
    frame: str = "flange",
) -> PayloadEstimate:
    """Estimate a payload on the last link from torques of the loaded arm (rule of change).

    Parameters
    ----------
    robot
        The model of the unloaded arm: its kinematics (DH, gravity, tool) give Y_n and, unless
        ``tau_unloaded`` is given, ``robot.rnea(q, qd, qdd)`` (drive terms included) is the
        unloaded torque; pass ``robot.rigid_body()`` for link-side torques without the drive
        terms (e.g. the LWR's joint torque sensors, paper eq. (7)).
    q, qd, qdd, tau
        (T, n) samples of the loaded arm: positions, velocities, accelerations and the measured
        joint torques (or one sample (n,)).
    tau_unloaded
        (T, n) torques the identified model of the unloaded arm predicts along the same samples,
        e.g. ``Y_base @ beta`` from identified base coefficients; default ``robot.rnea``.
    inertia
        True: the 10 parameters (mass, first moments, inertia). False: mass and first moments
        only, for static data (all qd = qdd = 0), where the inertia does not act.
    exclude_joints
        0-based joints whose torques are left out (uninformative or unreliable sensors), as in
        :func:`dynid.least_squares`.
    method
        "ols" or "wls" (:func:`dynid.least_squares`).
    frame
        "flange": centre of mass and inertia in the last DH frame n; "tool": in the robot's tool
        frame (``robot.tool`` maps frame n to it).

    Raises
    ------
    RankDeficientError (a ValueError) naming the payload parameters the data do not determine
    (e.g. the inertia from static data, or what a planar arm cannot see); ValueError for bad
    arguments.
    """
    checks.robot(robot)
    inertia = checks.flag(inertia, "inertia")
    exclude_joints = checks.indices(exclude_joints, "exclude_joints", robot.n)
    if not isinstance(frame, str) or frame not in FRAMES:
        raise ValueError(f"frame: expected one of {FRAMES}, got {frame!r}")
    q, qd, qdd, tau = (
        _samples(value, name, robot.n)
        for value, name in ((q, "q"), (qd, "qd"), (qdd, "qdd"), (tau, "tau"))
    )
    shape = q.shape
    for value, name in ((qd, "qd"), (qdd, "qdd"), (tau, "tau")):
        if value.shape != shape:
            raise ValueError(f"{name}: expected the shape of q {shape}, got {value.shape}")
    if tau_unloaded is None:
        tau_unloaded = robot.rnea(q, qd, qdd)
    else:
        tau_unloaded = _samples(tau_unloaded, "tau_unloaded", robot.n)
        if tau_unloaded.shape != shape:
            raise ValueError(
                f"tau_unloaded: expected the shape of q {shape}, got {tau_unloaded.shape}"
            )
    static = not (np.any(qd) or np.any(qdd))
    if not inertia and not static:
        raise ValueError(
            "inertia: False fits the mass and first moments only, exact for static data "
            "(qd = qdd = 0) where the payload's inertia does not act; the data move: use "
            "inertia=True"
        )
    columns = 10 if inertia else 4
    Y = robot.regressor(q, qd, qdd)[..., 10 * (robot.n - 1) : 10 * (robot.n - 1) + columns]
    names = list(PAYLOAD_NAMES[:columns])
    rows = shape[0] * (robot.n - len(exclude_joints))
    if rows < columns:
        raise RankDeficientError(
            f"q: {shape[0]} sample(s) give {rows} torque equations for the {columns} payload "
            "parameters; use many more samples (a well-excited trajectory)"
        )
    try:
        fit = least_squares(
            Y, tau - tau_unloaded, method=method, exclude_joints=exclude_joints, names=names
        )
    except RankDeficientError as exc:
        hint = (
            " Static data (qd = qdd = 0) do not excite the inertia: pass inertia=False."
            if static and inertia
            else ""
        )
        raise RankDeficientError(f"the data do not determine the payload: {exc}{hint}") from None
    return _physical(fit.theta, fit.covariance, robot, frame, fit)


def payload_from_identified(
    unloaded: IdentifiedModel, loaded: IdentifiedModel, *, frame: str = "flange"
) -> PayloadEstimate:
    """The payload from the change of the paper's identified coefficients (Gaz & De Luca 2017).

    ``unloaded`` and ``loaded`` are :func:`dynid.identify_from_controller` results for the arm
    without and with the payload (the controller's numeric g(q) and M(q), paper Sect. V). A
    payload changes the standard parameters of link n only, pi_n -> pi_n + pi_L (notes p. 33), so
    each base coefficient changes by its expression's link-n part (``base.beta``'s last-link
    columns B_n, gravity and inertia coefficients stacked):

        [pi_g^L - pi_g; pi_m^L - pi_m] = [B_g,n; B_m,n] pi_L.

    The gravity coefficients see m_L and m_L c_L, the inertia coefficients the inertia as well,
    so (for the LWR) all 10 payload parameters follow from static readings. Solved by least
    squares with each change weighted by its standard deviation (floored at 1e-6 of the largest,
    unweighted when all are zero: noise-free fits); the covariance of pi_L is propagated exactly
    (linear map) from the sum of the two fits' covariances. Paper eqs. (31)-(32)
    (:func:`dynid.payload_mass_estimates`) are the rows of this system holding m_n alone.
    """
    for name, model in (("unloaded", unloaded), ("loaded", loaded)):
        if not isinstance(model, IdentifiedModel):
            raise ValueError(
                f"{name}: expected a dynid.IdentifiedModel (identify_from_controller), got "
                f"{type(model).__name__}"
            )
    if not isinstance(frame, str) or frame not in FRAMES:
        raise ValueError(f"frame: expected one of {FRAMES}, got {frame!r}")
    robot = unloaded.structure
    same = all(
        np.array_equal(getattr(a, field), getattr(b, field))
        for a, b in (
            (unloaded.gravity_base, loaded.gravity_base),
            (unloaded.inertia_base, loaded.inertia_base),
        )
        for field in ("independent", "beta")
    )
    if not same or not np.array_equal(robot.dh, loaded.structure.dh):
        raise ValueError(
            "loaded: identified on another structure than unloaded (different DH "
            "table or base coefficients): the coefficients cannot be compared"
        )
    last = slice(10 * (robot.n - 1), 10 * robot.n)
    B = np.vstack([unloaded.gravity_base.beta[:, last], unloaded.inertia_base.beta[:, last]])
    change = np.concatenate([loaded.pi_g - unloaded.pi_g, loaded.pi_m - unloaded.pi_m])
    covariance = scipy.linalg.block_diag(
        unloaded.gravity_fit.covariance + loaded.gravity_fit.covariance,
        unloaded.inertia_fit.covariance + loaded.inertia_fit.covariance,
    )
    std = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    std = np.where(np.isfinite(std), std, 0.0)  # unknown: unweighted
    weight = 1.0 / np.maximum(std, 1e-6 * std.max()) if std.max() > 0 else np.ones_like(std)
    weighted = B * weight[:, None]
    scale = np.linalg.norm(weighted, axis=0)
    scale[scale == 0] = 1.0
    # Full V: with fewer coefficients than 10 the null space has more directions than rows.
    U, sv, Vt = np.linalg.svd(weighted / scale, full_matrices=True)
    rank = int(np.count_nonzero(sv > 1e-10 * sv[0])) if sv[0] > 0 else 0
    if rank < B.shape[1]:
        unseen = np.abs(Vt[rank:]).max(axis=0) > 1e-8
        raise RankDeficientError(
            "the coefficient changes do not determine the payload: rank "
            f"{rank} < {B.shape[1]}; not determined: "
            f"{', '.join(n for n, u in zip(PAYLOAD_NAMES, unseen) if u)}"
        )
    solve = (Vt.T / sv / scale[:, None]) @ U[:, :rank].T * weight  # pi_L = solve @ change
    theta = solve @ change
    if np.all(np.isfinite(covariance)):
        propagated = solve @ covariance @ solve.T
    else:  # a fit without degrees of freedom for its noise: unknown uncertainty
        propagated = np.full((theta.size, theta.size), np.inf)
    return _physical(theta, propagated, robot, frame, None)


def physical_from_parameters(
    theta: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(m, c (3), I_C (6, upper triangle xx xy xz yy yz zz)) from pi = (m, h, I_O (6)) and the
    Jacobian of that map (delta method): c = h / m, I_C = I_O - S(h) / m, S(h) = |h|^2 E - h h^T.
    With 4 entries (no inertia), (m, c) and its 4x4 Jacobian."""
    m, h = theta[0], theta[1:4]
    phi = np.concatenate([[m], h / m])
    G = np.zeros((theta.size, theta.size))
    G[0, 0] = 1.0
    G[1:4, 0] = -h / m**2
    G[1:4, 1:4] = np.eye(3) / m
    if theta.size == 4:
        return phi, G
    S6 = (h @ h * np.eye(3) - np.outer(h, h))[_ROWS, _COLS]
    # d S6 / d h, rows xx xy xz yy yz zz
    dS = np.array(
        [
            [0, 2 * h[1], 2 * h[2]],
            [-h[1], -h[0], 0],
            [-h[2], 0, -h[0]],
            [2 * h[0], 0, 2 * h[2]],
            [0, -h[2], -h[1]],
            [2 * h[0], 2 * h[1], 0],
        ]
    )
    G[4:, 0] = S6 / m**2
    G[4:, 1:4] = -dS / m
    G[4:, 4:] = np.eye(6)
    return np.concatenate([phi, theta[4:] - S6 / m]), G


def _physical(
    theta: NDArray[np.float64],
    covariance: NDArray[np.float64],
    robot: Robot,
    frame: str,
    fit: LeastSquaresResult | None,
) -> PayloadEstimate:
    parameters_std = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    mass, mass_std = float(theta[0]), float(parameters_std[0])
    total = float(np.abs(robot.params[:, 0]).sum()) or 1.0
    common: dict[str, Any] = {
        "mass": mass,
        "mass_std": mass_std,
        "parameters": theta.copy(),
        "parameters_std": parameters_std,
        "frame": frame,
        "fit": fit,
    }
    if not mass > max(SIGNIFICANCE * mass_std, MASS_FLOOR * total):
        return PayloadEstimate(com=None, com_std=None, inertia=None, inertia_std=None, **common)
    phi, G = physical_from_parameters(theta)
    L = _frame_map(robot, frame, theta.size)
    phi = L @ phi + _frame_offset(robot, frame, theta.size)
    if np.all(np.isfinite(covariance)):
        variance = np.diag(L @ G @ covariance @ G.T @ L.T)
        std = np.sqrt(np.maximum(variance, 0.0))
    else:  # no degrees of freedom for the noise (least_squares warned): unknown uncertainty
        std = np.full(theta.size, np.inf)
    com, com_std = phi[1:4], std[1:4]
    inertia = inertia_std = None
    if theta.size == 10:
        inertia, inertia_std = _symmetric(phi[4:]), _symmetric(std[4:])
    return PayloadEstimate(
        com=com, com_std=com_std, inertia=inertia, inertia_std=inertia_std, **common
    )


def _frame_map(robot: Robot, frame: str, size: int) -> NDArray[np.float64]:
    """The linear part of (m, c, I_C) in frame n -> in the tool frame: c' = R^T (c - p),
    I_C' = R^T I_C R, with (R, p) = robot.tool; identity for the flange."""
    L = np.eye(size)
    if frame == "flange":
        return L
    R = np.asarray(robot.tool)[:3, :3]
    L[1:4, 1:4] = R.T
    if size == 10:
        for k in range(6):
            unit = np.zeros(6)
            unit[k] = 1.0
            L[4:, 4 + k] = (R.T @ _symmetric(unit) @ R)[_ROWS, _COLS]
    return L


def _frame_offset(robot: Robot, frame: str, size: int) -> NDArray[np.float64]:
    offset = np.zeros(size)
    if frame == "tool":
        tool = np.asarray(robot.tool)
        offset[1:4] = -tool[:3, :3].T @ tool[:3, 3]
    return offset


def _symmetric(six: NDArray[np.float64]) -> NDArray[np.float64]:
    out = np.zeros((3, 3))
    out[_ROWS, _COLS] = six
    out[_COLS, _ROWS] = six
    return out


def _samples(value: ArrayLike, name: str, n: int) -> NDArray[np.float64]:
    array = real_array(value, name)
    if array.ndim == 1:
        array = array[np.newaxis]
    if array.ndim != 2 or array.shape[1] != n or array.shape[0] == 0:
        raise ValueError(f"{name}: expected shape (T, {n}) or ({n},), got {np.shape(value)}")
    return array
