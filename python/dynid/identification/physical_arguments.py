"""Argument checks of :func:`dynid.identification.physical.physical_least_squares`
(docs/conventions.md, "Bad input": a ValueError whose
message starts with the argument's name, says what was expected and what was given)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import real_array
from ..model.link_frames import express_in_frames_of
from ..model.robot import Robot


def check_data(
    Y: ArrayLike, tau: ArrayLike, n: int, columns: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    Y = real_array(Y, "Y")
    tau = real_array(tau, "tau")
    if Y.ndim in (2, 3) and Y.shape[-1] != columns:
        raise ValueError(
            f"Y: expected {columns} columns (the regressor of the model with the "
            "rotor/friction options given, plus extra_columns), got "
            f"{Y.shape[-1]}"
        )
    if Y.ndim == 2:
        if Y.shape[0] == 0 or Y.shape[0] % n:
            raise ValueError(
                f"Y: expected (N, {columns}) with N a positive multiple of n = {n} "
                f"(rows sample after sample), got shape {Y.shape}"
            )
        Y = Y.reshape(-1, n, Y.shape[1])
        if tau.shape != (Y.shape[0] * n,):
            raise ValueError(f"tau: expected shape ({Y.shape[0] * n},) to match Y, got {tau.shape}")
        tau = tau.reshape(-1, n)
    elif Y.ndim == 3:
        if Y.shape[0] == 0 or Y.shape[1] != n:
            raise ValueError(f"Y: expected (T, {n}, {columns}) with T >= 1, got shape {Y.shape}")
        if tau.shape != Y.shape[:2]:
            raise ValueError(f"tau: expected shape {Y.shape[:2]} to match Y, got {tau.shape}")
    else:
        raise ValueError(f"Y: expected (T, n, P) or (N, P), got shape {Y.shape}")
    return Y, tau


def check_weights(weights: ArrayLike | None, T: int, n: int) -> NDArray[np.float64]:
    if weights is None:
        return np.ones((T, n))
    w = real_array(weights, "weights")
    if w.shape == (n,):
        w = np.broadcast_to(w, (T, n))
    elif w.shape == (T * n,):
        w = w.reshape(T, n)
    elif w.shape != (T, n):
        raise ValueError(
            f"weights: expected one per joint ({n},) or one per row ({T}, {n}) / "
            f"({T * n},), got shape {w.shape}"
        )
    if np.any(w < 0) or not np.any(w > 0):
        raise ValueError("weights: expected non-negative values, at least one positive")
    return np.array(w, dtype=float)


def check_prior(prior: Any, robot: Robot, rotor: bool, friction: bool) -> NDArray[np.float64]:
    """The prior's parameter vector in the robot's DH frames: as given when the two models have
    the same regressor (a frame 0 moved along gravity, e.g. a base-to-shoulder height in d1,
    keeps every link frame), else re-expressed by
    :func:`dynid.model.link_frames.express_in_frames_of`
    (e.g. a URDF's or the other convention's table of the same arm)."""
    if not isinstance(prior, Robot):
        raise ValueError(f"prior: expected a dynid.Robot, got {type(prior).__name__}")
    if (prior.n, prior.joint_types) != (robot.n, robot.joint_types):
        raise ValueError(
            f"prior: expected a model of the robot's joints ({robot.n} joints "
            f"{robot.joint_types!r}), got {prior.n} joints {prior.joint_types!r}"
        )
    bad = [f"link {i + 1}: {why}" for i in range(prior.n) if (why := prior._link_inconsistency(i))]
    if bad:
        raise ValueError("prior: expected a physically consistent model, " + "; ".join(bad))
    rng = np.random.default_rng(0)
    q = robot.random_configurations(4, seed=0)
    qd, qdd = rng.uniform(-1, 1, (2, 4, robot.n))
    mine, theirs = robot.regressor(q, qd, qdd), prior.regressor(q, qd, qdd)
    if not np.allclose(mine, theirs, rtol=1e-9, atol=1e-9 * np.abs(mine).max()):
        try:
            prior = express_in_frames_of(prior, robot)
        except ValueError as exc:
            raise ValueError(
                "prior: its standard parameters are not in the robot's DH frames (the two "
                f"regressors differ) and cannot be mapped to them: {exc}"
            ) from None
    values = prior.parameter_vector(rotor, friction)
    if np.any(values[10 * prior.n :] < 0):
        raise ValueError("prior: its Ia, Fv, Fs must be >= 0 (the estimate's are)")
    return values


def check_prior_weight(value: Any, prior: Any) -> float:
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"prior_weight: expected a number >= 0, got {value!r}")
    try:
        weight = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"prior_weight: expected a number >= 0, got {value!r}") from None
    if not np.isfinite(weight) or weight < 0:
        raise ValueError(f"prior_weight: expected a finite number >= 0, got {value!r}")
    if weight > 0 and prior is None:
        raise ValueError(f"prior_weight: {weight} > 0 needs a prior model (prior is None)")
    if weight == 0 and prior is not None:
        raise ValueError(
            "prior_weight: a prior is given but prior_weight is 0, so it would be "
            "ignored; give prior_weight > 0"
        )
    return weight


def check_mass_bounds(
    value: ArrayLike | None, n: int
) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
    if value is None:
        return None, None
    bounds = real_array(value, "mass_bounds", finite=False)
    if bounds.shape != (n, 2):
        raise ValueError(
            f"mass_bounds: expected shape ({n}, 2) [lower, upper] per link, got {bounds.shape}"
        )
    lower, upper = bounds[:, 0], bounds[:, 1]
    if np.any(np.isnan(bounds)) or not np.all(np.isfinite(lower)) or np.any(upper == -np.inf):
        raise ValueError(
            "mass_bounds: expected finite lower bounds and upper bounds that are "
            "finite or inf, got NaN or -inf or an infinite lower bound"
        )
    if np.any(lower < 0) or np.any(upper < lower):
        raise ValueError(
            f"mass_bounds: expected 0 <= lower <= upper per link, got {bounds.tolist()}"
        )
    return lower.copy(), upper.copy()


def check_total_mass(value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    bounds = real_array(value, "total_mass")
    if bounds.shape == ():
        bounds = np.array([bounds, bounds])
    if bounds.shape != (2,) or bounds[0] > bounds[1] or bounds[1] <= 0 or bounds[0] < 0:
        raise ValueError(
            f"total_mass: expected a mass > 0 in kg or (lower, upper) with "
            f"0 <= lower <= upper, upper > 0, got {value!r}"
        )
    return float(bounds[0]), float(bounds[1])


def check_nonnegative_extra(value: Any, k: int) -> NDArray[np.bool_]:
    """``nonnegative_extra``: None (no extra coefficient constrained) or k booleans."""
    if value is None:
        return np.zeros(k, dtype=bool)
    mask = np.asarray(value)
    if mask.dtype != np.bool_ or mask.shape != (k,):
        raise ValueError(
            f"nonnegative_extra: expected None or {k} booleans (one per extra column), got "
            f"{mask.dtype} of shape {mask.shape}"
        )
    return mask.copy()
