"""A least-squares result as a robot: the physically consistent standard parameters whose base
parameters are the estimate, when there are any (issue 21: "a least-squares result exports
when its parameters are physically consistent").

A least-squares fit estimates the base parameters theta = beta @ pi (lecture p. 25: the
standard parameters pi are not identifiable one by one), so it holds no robot. Many standard
parameter vectors share those base values; the estimate is *physically consistent* when one of
them is: every link a possible rigid body (its pseudo-inertia positive definite, Wensing et al.
2017), Ia, Fv, Fs >= 0. Finding the closest one is the SDP of
:func:`dynid.physical_least_squares` with the data replaced by the base map itself: rows
beta_k . pi = theta_k, each weighted by 1 / std_k, so the distance is counted in standard
deviations. When every base parameter of that robot is within one standard deviation of the
estimate (``MATCH_STD``: the data cannot tell them apart), it is the answer, with a warning
naming the distance when it is not zero (to the solver's accuracy); further away, the estimate
lies outside the physical set and the fit with the constraints (``--physical``) is the answer.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..model.robot import Robot
from .log_identification import LogIdentification
from .physical import physical_least_squares

#: A base parameter is matched when the consistent robot's value is within this many of its
#: standard deviations of the estimate (the data cannot tell the two models apart: a noisy
#: estimate of a real arm often lies just outside the physical set, e.g. a small product of
#: inertia near the triangle inequality's bound) ...
MATCH_STD = 1.0
#: ... or within this fraction of the largest |theta| (noise-free estimates have std ~ 0; the
#: SDP solver's relative accuracy is ~1e-8).
MATCH_RELATIVE = 1e-6
#: Beyond this many standard deviations (or MATCH_RELATIVE) a match is reported in a warning.
REPORT_STD = 0.01


def consistent_robot(result: LogIdentification) -> Robot:
    """The physically consistent robot whose base parameters (rigid body, Ia, Fv, Fs) equal
    ``result.theta``'s, for a least-squares result; a physically consistent result's own robot.

    The coefficients after the base parameters (asymmetric friction, offsets, position torque)
    are no part of a robot, as for a physically consistent result. A UserWarning when the
    robot's base parameters differ from the estimate's by more than the solver's accuracy but
    within one standard deviation; ValueError when no consistent robot is that close (naming
    the base parameter furthest from one, in standard deviations) or when the result holds no
    base parameters to match.
    """
    if result.physical is not None:
        return result.robot
    count = result.count
    theta = np.asarray(result.theta[:count], dtype=float)
    scale = float(np.abs(theta).max()) if count else 0.0
    if count == 0 or scale == 0.0:
        raise ValueError("result: no base parameters to build a robot from")
    std = np.asarray(result.std[:count], dtype=float)
    known = np.isfinite(std)
    if not known.all():
        unknown = [result.names[k] for k in np.flatnonzero(~known)]
        raise ValueError(
            f"result: {', '.join(unknown)} not determined by the data (infinite std); "
            "identify with --physical (and a --prior) to export a model"
        )
    tolerance = np.maximum(MATCH_STD * std, MATCH_RELATIVE * scale)
    robot, n = result.robot, result.n
    # The stacked form of physical_least_squares wants whole samples of n rows: the count
    # rows of beta, padded with zero rows of weight zero.
    rows = -(-count // n) * n
    A = np.zeros((rows, result.beta.shape[1]))
    A[:count] = result.beta
    b = np.zeros(rows)
    b[:count] = theta
    weights = np.zeros(rows)
    weights[:count] = 1.0 / tolerance
    fit = physical_least_squares(
        robot, A, b, rotor=result.rotor, friction=result.friction, weights=weights
    )
    gap = np.abs(fit.base_values - theta)
    distance = gap / tolerance
    worst = int(np.argmax(distance))
    with np.errstate(divide="ignore", invalid="ignore"):
        in_std = np.where(std > 0, gap / std, np.inf)
    if distance[worst] <= 1.0:
        far = int(np.argmax(np.where(gap > MATCH_RELATIVE * scale, in_std, 0.0)))
        if gap[far] > MATCH_RELATIVE * scale and in_std[far] > REPORT_STD:
            warnings.warn(
                f"result: the estimate lies just outside the physically consistent set; the "
                f"robot written is the closest consistent one, within {in_std[far]:.2g} std of "
                f"the estimate ({result.names[far]})",
                UserWarning,
                stacklevel=2,
            )
        return fit.robot
    raise ValueError(
        f"result: its base parameters are not physically consistent: no rigid bodies with "
        f"Ia, Fv, Fs >= 0 have them ({result.names[worst]} is {in_std[worst]:.3g} std from "
        "the closest physically consistent value); identify with --physical to export a model"
    )
