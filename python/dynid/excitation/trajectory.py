"""Exciting trajectories for identification: the finite Fourier series, its limits and its cond.

Notes, "Identification experiments": the motion must be "sufficiently exciting", i.e. explore the
workspace and involve every component of the dynamic model, and be periodic with multiple
frequency components. Following Swevers et al. (IEEE Trans. RA 13(5), 1997), joint i moves as

    q_i(t) = q0_i + sum_{l=1..H} a_il/(wf l) sin(wf l t) - b_il/(wf l) cos(wf l t)
    qd_i   =        sum_l a_il cos(wf l t) + b_il sin(wf l t)
    qdd_i  =        sum_l wf l (-a_il sin(wf l t) + b_il cos(wf l t))

so a_il, b_il are velocity amplitudes [rad/s or m/s]. This module holds the trajectory itself
(:class:`FourierTrajectory`), its distance to the joint limits, the rest-to-rest projection and
the condition number that measures its excitation; choosing the coefficients is
:mod:`dynid.excitation.optimization`.

The condition number is that of the stacked base regressor with every column scaled to unit
norm (here and in the optimiser): unscaled, it would mostly measure the units of the
parameters (kg against kg m^2) rather than how well the motion excites them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import count, real_array
from ..model.base_parameters import base_parameters
from ..model.robot import Robot

#: Default velocity and acceleration limits for every joint [rad/s, rad/s^2]: about half the
#: KUKA LWR4+'s rated joint speeds (110-180 deg/s), gentle enough for a first experiment.
DEFAULT_QD_MAX = 1.0
DEFAULT_QDD_MAX = 2.0

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
        c = np.hstack([self.a, self.b])
        with np.errstate(over="ignore", invalid="ignore"):
            Bq, Bqd, Bqdd = _basis(np.atleast_1d(times), self.base_frequency, self.harmonics)
            q, qd, qdd = Bq @ c.T + self.q0, Bqd @ c.T, Bqdd @ c.T
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd)) and np.all(np.isfinite(qdd))):
            # Finite but huge coefficients or times overflow: an error, never a silent NaN.
            raise ValueError(
                "t: q, qd or qdd overflow at these times with this trajectory's "
                "coefficients (a, b, q0, base_frequency); use smaller values"
            )
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
    :func:`dynid.identification.identify.least_squares` reports; it depends on the parameters'
    units.
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
    s = _scaled_singular_values(W)[2] if scaled else np.linalg.svd(W, compute_uv=False)[::-1]
    return float(s[-1] / s[0]) if s[0] > 0 else float("inf")


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
    """(T, 2H) matrices mapping the coefficients [a_i | b_i] of a joint to q_i - q0_i, qd_i and
    qdd_i."""
    w = wf * np.arange(1, harmonics + 1)
    S, C = np.sin(np.outer(t, w)), np.cos(np.outer(t, w))
    return np.hstack([S / w, -C / w]), np.hstack([C, S]), np.hstack([-S * w, C * w])


def _basis_states(
    x: NDArray[np.float64], n: int, harmonics: int, basis: tuple[NDArray[np.float64], ...]
) -> tuple[NDArray[np.float64], ...]:
    """q, qd, qdd (T, n) of the optimiser's vector x = [a (n H), b (n H), q0 (n)] on the
    :func:`_basis` of its time grid (the layout of :meth:`FourierTrajectory.to_vector`)."""
    nh = n * harmonics
    c = np.hstack([x[:nh].reshape(n, -1), x[nh : 2 * nh].reshape(n, -1)])
    Bq, Bqd, Bqdd = basis
    return Bq @ c.T + x[2 * nh :], Bqd @ c.T, Bqdd @ c.T


# ---- limits -----------------------------------------------------------------------------------
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


# ---- argument checks (docs/conventions.md, "Bad input": ValueError naming the argument) ----------
def _finite_array(value: ArrayLike, name: str) -> NDArray[np.float64]:
    return real_array(value, name).copy()  # a copy: FourierTrajectory freezes its arrays


def _finite_positive(value: object, name: str) -> float:
    # Any object goes to real_array, which raises the ValueError naming it for non-numbers.
    array = (
        _finite_array(cast(ArrayLike, value), name)
        if not isinstance(value, bool)
        else np.array(np.nan)
    )
    if array.ndim != 0 or not array > 0.0:
        raise ValueError(f"{name}: expected a positive finite number, got {value!r}")
    return float(array)


def _integer(value: object, name: str, minimum: int) -> int:
    return count(value, name, minimum)


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
