"""Designing an identification experiment: the optimised, rest-to-rest trajectory with its
limits, as ``dynid excite`` writes it (:class:`ExperimentTrajectory`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..model.robot import Robot
from .cartesian import KeepOut
from .optimization import DEFAULT_POSITION_MARGIN, ExcitationResult, optimize_excitation
from .torque_limits import torque_limit_vector
from .trajectory import DEFAULT_QD_MAX, DEFAULT_QDD_MAX, _integer, _limit_vector
from .trajectory_files import ExperimentTrajectory


def design_experiment(
    robot: Robot,
    *,
    qd_max: ArrayLike | None = None,
    qdd_max: ArrayLike | None = None,
    tau_max: ArrayLike | None = None,
    torque_model: Robot | None = None,
    harmonics: int = 5,
    period: float = 10.0,
    periods: int = 1,
    samples: int = 200,
    position_margin: float = DEFAULT_POSITION_MARGIN,
    rotor: bool = False,
    friction: bool = False,
    seed: int = 0,
    maxiter: int = 200,
    keep_out: KeepOut | None = None,
    progress: Callable[[int, float], None] | None = None,
) -> tuple[ExperimentTrajectory, ExcitationResult]:
    """An exciting trajectory that starts and ends at rest, within ``robot.qlim`` (less
    ``position_margin``), ``qd_max``, ``qdd_max`` and, if given, ``tau_max`` for the torque of
    ``torque_model`` (default ``robot``), outside ``keep_out`` (floor, box, capsules), played
    ``periods`` times: ``optimize_excitation`` with
    ``at_rest=True``, and the result with its joint names and limits, ready for
    :func:`dynid.export.trajectory_out.save_trajectory_folder`."""
    periods = _integer(periods, "periods", minimum=1)
    result = optimize_excitation(
        robot,
        harmonics=harmonics,
        period=period,
        samples=samples,
        qd_max=qd_max,
        qdd_max=qdd_max,
        rotor=rotor,
        friction=friction,
        at_rest=True,
        seed=seed,
        maxiter=maxiter,
        position_margin=position_margin,
        tau_max=tau_max,
        torque_model=torque_model,
        keep_out=keep_out,
        progress=progress,
    )
    n = robot.n
    limits: dict[str, Any] = {
        "q_min": robot.qlim[:, 0].tolist(),
        "q_max": robot.qlim[:, 1].tolist(),
        "position_margin": float(position_margin),
        "qd_max": _limit_vector(DEFAULT_QD_MAX if qd_max is None else qd_max, "qd_max", n).tolist(),
        "qdd_max": _limit_vector(
            DEFAULT_QDD_MAX if qdd_max is None else qdd_max, "qdd_max", n
        ).tolist(),
        "tau_max": None if tau_max is None else torque_limit_vector(tau_max, n).tolist(),
        "torque_model": (robot if torque_model is None else torque_model).name,
    }
    if keep_out is not None and keep_out.active:
        radii = None if keep_out.radii is None else np.atleast_1d(keep_out.radii).tolist()
        limits["keep_out"] = {
            "floor": keep_out.floor,
            "box": None if keep_out.box is None else list(keep_out.box),
            "capsule_radii": radii,
            "margin": keep_out.margin,
        }
    plan = ExperimentTrajectory(
        result.trajectory,
        tuple(robot.joint_names),
        periods=periods,
        ramp="rest_to_rest",
        limits=limits,
        model=robot.name,
        condition_number=float(result.condition_after),
    )
    return plan, result
