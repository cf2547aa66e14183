"""Base parameters (dynamic coefficients) by the numerical method.

The standard parameters enter the dynamics only in certain combinations (notes, "Dynamic
parameters of robots 5"): some columns of the regressor are identically zero, others are fixed
linear combinations of earlier ones. Here the regressor is stacked on random samples, scaled
column by column, and factored by QR *without* pivoting, so that column k is kept exactly when it
is not in the span of the columns kept before it (greedy, left to right, in the standard order).
Each dropped column is then expressed on the kept ones, which gives

    Y @ pi == Y[:, independent] @ (beta @ pi)

for every sample, with beta = [I | T] (rearranged to the standard order).

Base parameters are structural: they depend on the DH table, the joint types and the direction
of gravity, not on the parameter values nor on the joint limits; the result is cached on the
robot per kind and per geometry, the CACHE_SIZE most recently used only (a mobile base or a
calibration sweep changes the base pose, gravity or transmission without end).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks as checks
from .._equality import ValueEquality
from .._threads import blas_single_threaded
from . import robot_fields
from .robot import Robot

#: A column is independent when, after scaling every column to unit norm, the part of it outside
#: the span of the columns kept before it has norm above this (|R_kk| of the QR factor). Exact
#: dependencies leave ~1e-15; genuine ones on the random samples are above ~1e-4.
RANK_TOLERANCE = 1e-8

#: Entries of beta are rounded to this many significant digits: the dependencies are exact
#: products of DH lengths (e.g. 0.4**2 = 0.16), the least-squares noise is ~1e-13.
SIGNIFICANT_DIGITS = 12

#: Within one dependent column's coefficients, an entry this much smaller than the largest is
#: treated as an exact zero (genuine ratios are products of DH lengths, far above it).
NOISE_RATIO = 1e-10

KINDS = ("torque", "gravity", "inertia")

#: Results kept on each robot (least recently used dropped first): the 7 kinds of regressor
#: (kind, rotor, friction) for one geometry, or a few for two.
CACHE_SIZE = 8
_CACHE_LOCK = threading.Lock()  # an OrderedDict's reordering is not atomic (robots are shared)


@dataclass(frozen=True, eq=False)
class BaseParameters(ValueEquality):
    """The base (grouped) parameters of a robot for one kind of regressor."""

    kind: str
    rotor: bool
    friction: bool
    count: int  #: p, the number of base parameters
    independent: NDArray[np.int64]  #: indices of the kept standard columns, increasing
    beta: NDArray[np.float64]  #: (p, P): base values = beta @ pi
    names: list[str]  #: one per base parameter; "R" marks a regrouped one (Khalil's notation)
    expressions: list[str]  #: each base parameter as Python arithmetic over parameter names
    parameter_names: list[str]  #: the P standard names, in column order
    singular_values: NDArray[np.float64]  #: of the column-scaled stacked regressor

    def values(self, robot: Robot) -> NDArray[np.float64]:
        """beta @ pi for the robot's current parameters."""
        return self.beta @ robot.parameter_vector(self.rotor, self.friction)

    def reduce(self, Y: NDArray[np.float64]) -> NDArray[np.float64]:
        """The base regressor: the independent columns of a standard regressor (..., P)."""
        return np.asarray(Y)[..., self.independent]


def base_parameters(
    robot: Robot, kind: str = "torque", rotor: bool = False, friction: bool = False
) -> BaseParameters:
    """Base parameters of ``robot`` for the torque, gravity or inertia-stack regressor.

    ``rotor`` and ``friction`` append the Ia and Fv/Fs columns as in :meth:`Robot.regressor`
    (the gravity regressor has neither; the inertia regressor has no friction). A
    :class:`dynid.ClosedChain` answers with its own :meth:`~dynid.ClosedChain.base_parameters`.
    """
    if not isinstance(robot, Robot) and hasattr(robot, "closure"):
        # a closed chain (model/closed_chain.py imports this module: no import back)
        return robot.base_parameters(kind, rotor=rotor, friction=friction)
    checks.robot(robot)
    if not isinstance(kind, str) or kind not in KINDS:
        raise ValueError(f"kind: expected one of {KINDS}, got {kind!r}")
    rotor, friction = checks.flag(rotor, "rotor"), checks.flag(friction, "friction")
    if kind == "gravity" and (rotor or friction):
        raise ValueError("rotor/friction: the gravity regressor has no drive-term columns")
    if kind == "inertia" and friction:
        raise ValueError("friction: the inertia regressor has no friction columns")
    # Everything the structure depends on (docs/base_parameters.md, "Base parameters": not the
    # parameter values, nor the limits): the fields flagged structural in dynid.model.robot_fields.
    key = (kind, bool(rotor), bool(friction), *robot_fields.structure_key(robot))
    with _CACHE_LOCK:
        cache = robot.__dict__.setdefault("_base_parameter_cache", OrderedDict())
        found = cache.get(key)
        if found is not None:
            cache.move_to_end(key)
            return found
    found = _compute(robot, kind, bool(rotor), bool(friction))  # outside the lock: may take long
    with _CACHE_LOCK:
        cache[key] = found
        cache.move_to_end(key)  # another thread may have stored it meanwhile
        while len(cache) > CACHE_SIZE:
            cache.popitem(last=False)
    return found


def stacked_regressor(
    robot: Robot, kind: str, rotor: bool, friction: bool, samples: int, seed: int = 0
) -> NDArray[np.float64]:
    """The regressor of ``kind`` on ``samples`` random states, stacked into one (rows, P) matrix.

    The configurations ignore the joint limits (docs/base_parameters.md, "Base parameters": base
    parameters are structural): revolute joints cover the full circle and prismatic ones [-1, 1] m,
    so that tight limits cannot make a generic dependency look structural (or hide one)."""
    rng = np.random.default_rng(seed)
    revolute = np.array([t == "R" for t in robot.joint_types])
    q = rng.uniform(-1.0, 1.0, (samples, robot.n)) * np.where(revolute, np.pi, 1.0)
    if kind == "gravity":
        Y = robot.gravity_regressor(q)
    elif kind == "inertia":
        Y = robot.inertia_regressor(q, rotor=rotor)
    else:
        qd, qdd = rng.normal(size=(2, samples, robot.n))
        Y = robot.regressor(q, qd, qdd, rotor=rotor, friction=friction)
    return Y.reshape(-1, Y.shape[-1])


@blas_single_threaded  # small dense work: threads only wait for cores (_threads.py)
def _compute(robot: Robot, kind: str, rotor: bool, friction: bool) -> BaseParameters:
    n = robot.n
    rows_per_sample = n * (n + 1) // 2 if kind == "inertia" else n
    columns = 10 * n + (n if rotor else 0) + (2 * n if friction else 0)
    samples = max(20, (4 * columns) // rows_per_sample + 1)
    W = stacked_regressor(robot, kind, rotor, friction, samples)

    return from_stacked_regressor(
        W, robot.parameter_names(rotor, friction), kind=kind, rotor=rotor, friction=friction
    )


def from_stacked_regressor(
    W: NDArray[np.float64], names_std: list[str], *, kind: str, rotor: bool, friction: bool
) -> BaseParameters:
    """Base parameters from a regressor stacked on random samples (rows, P), P = len(names_std):
    the greedy left-to-right column selection and the regrouping of the module docstring. Any
    model linear in its standard parameters uses it (a serial robot, a closed chain)."""
    columns = W.shape[1]
    norms = np.linalg.norm(W, axis=0)
    nonzero = norms > RANK_TOLERANCE * norms.max()
    scaled = np.where(nonzero, W / np.where(nonzero, norms, 1.0), 0.0)
    R = np.linalg.qr(scaled, mode="r")
    independent = np.flatnonzero(nonzero & (np.abs(np.diag(R)) > RANK_TOLERANCE))
    dependent = np.setdiff1d(np.arange(columns), independent)

    # W[:, dependent] = W[:, independent] @ T, exactly up to rounding. Solved on the scaled
    # columns (then unscaled) so that columns of very different magnitude keep full precision.
    T_scaled, *_ = np.linalg.lstsq(scaled[:, independent], scaled[:, dependent], rcond=None)
    T = T_scaled * norms[dependent] / norms[independent][:, None]
    # Entries far below the largest of their column are rounding noise of exact zeros.
    column_size = np.max(np.abs(T), axis=0, initial=0.0)
    T[np.abs(T) < NOISE_RATIO * column_size] = 0.0
    T = round_significant(T)
    p = independent.size
    beta = np.zeros((p, columns))
    beta[np.arange(p), independent] = 1.0
    beta[:, dependent] = T

    expressions = [linear_expression(row, names_std) for row in beta]
    names = [
        names_std[k] + ("R" if np.count_nonzero(beta[j]) > 1 else "")
        for j, k in enumerate(independent)
    ]
    return BaseParameters(
        kind=kind,
        rotor=rotor,
        friction=friction,
        count=p,
        independent=independent,
        beta=beta,
        names=names,
        expressions=expressions,
        parameter_names=names_std,
        singular_values=np.linalg.svd(scaled, compute_uv=False),
    )


def round_significant(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Round to SIGNIFICANT_DIGITS significant digits; tiny entries become exact zeros."""
    flat = [float(f"{x:.{SIGNIFICANT_DIGITS}g}") for x in values.ravel()]
    rounded = np.array(flat).reshape(values.shape)
    rounded[np.abs(rounded) < 10.0 ** (-SIGNIFICANT_DIGITS)] = 0.0
    return rounded


def linear_expression(row: NDArray[np.float64], names: list[str]) -> str:
    """``row @ values`` as Python arithmetic over ``names``, e.g. "mz2 + 0.4*m3 - my3"."""
    terms = []
    for k in np.flatnonzero(row):
        c = float(row[k])
        magnitude = "" if abs(c) == 1.0 else f"{abs(c)!r}*"
        sign = "-" if c < 0 else "+"
        terms.append((sign, magnitude + names[k]))
    text = ("-" if terms[0][0] == "-" else "") + terms[0][1]
    for sign, term in terms[1:]:
        text += f" {sign} {term}"
    return text
