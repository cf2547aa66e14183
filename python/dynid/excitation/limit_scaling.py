"""The limits that are not linear in the Fourier coefficients (joint torques, Cartesian
keep-out) over the whole period, and the amplitude factor about q0 that meets them.

Shrinking the amplitudes about q0 moves the motion towards standing still at q0, which meets
every such limit when q0 does (gravity within the torque limits, the arm outside the keep-out);
:meth:`NonlinearLimits.scale` finds the largest factor by bisection, keeping as its answer only
factors whose trajectory the checks over the whole period accept
(:func:`dynid.excitation.torque_limits.torque_extents`,
:func:`dynid.excitation.cartesian.keep_out_holds`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from .cartesian import KeepOut, capsule_pairs, constraint_labels, constraint_values, keep_out_holds
from .torque_limits import torque_extents
from .trajectory import FourierTrajectory

#: With torque limits or a keep-out, random starts drawn at most this many times to find a mean
#: position q0 with room for the motion (start_with_room).
START_DRAWS = 100


def scaled(trajectory: FourierTrajectory, factor: float) -> FourierTrajectory:
    """The amplitudes a, b times ``factor``, q0 kept."""
    return FourierTrajectory(
        trajectory.base_frequency, factor * trajectory.a, factor * trajectory.b, trajectory.q0
    )


def start_with_room(
    start: FourierTrajectory,
    redraw: Callable[[], FourierTrajectory],
    robot: Robot,
    model: Robot,
    torque: NDArray | None,
    space: KeepOut | None,
) -> FourierTrajectory:
    """The random start redrawn (up to START_DRAWS times) until gravity at q0 takes at most half
    of each torque limit, leaving the other half to the motion, and the arm standing at q0 is
    outside the keep-out by twice its margin; else the draw needing least."""
    best, best_load = start, np.inf
    for _ in range(START_DRAWS):
        load = 0.0
        if torque is not None:
            load = float(np.max(np.abs(model.gravity(start.q0)) / torque)) / 0.5
        if space is not None:
            values = keep_out_at(robot, space, start.q0, start.q0)
            room = float(values.min(initial=np.inf)) / (2 * space.margin + 1e-12)
            load = max(load, 2.0 - min(room, 2.0))  # 1 when the room is exactly twice the margin
        if load < best_load:
            best, best_load = start, load
        if load <= 1.0:
            break
        start = redraw()
    return best


def keep_out_at(robot: Robot, space: KeepOut, q: NDArray, q_ref: NDArray) -> NDArray:
    """The keep-out constraint values (>= 0 outside) of the arm standing at ``q``."""
    radii, pairs = capsule_pairs(robot, space, q_ref)
    return constraint_values(robot, space, radii, pairs, np.atleast_2d(q))[0][0]


class NonlinearLimits:
    """The torque and keep-out limits over the whole period, and the largest amplitude factor
    (about q0) that meets them."""

    def __init__(
        self,
        robot: Robot,
        model: Robot,
        torque: NDArray | None,
        space: KeepOut | None,
        q_ref: NDArray,
        samples: int,
    ) -> None:
        self.robot, self.model, self.torque, self.space = robot, model, torque, space
        self.q_ref, self.samples = q_ref, samples

    def holds(self, trajectory: FourierTrajectory) -> bool:
        if self.torque is not None and np.any(
            torque_extents(self.model, trajectory, self.samples) > self.torque
        ):
            return False
        return self.space is None or keep_out_holds(
            self.robot, self.space, trajectory, self.samples, self.q_ref
        )

    def scale(self, trajectory: FourierTrajectory) -> float:
        """1.0 if ``trajectory`` holds, else the largest factor found by bisection (to 1e-6) whose
        scaled trajectory holds; ValueError when even standing at q0 does not (factor 0)."""
        if self.holds(trajectory):
            return 1.0
        q0 = trajectory.q0
        if self.torque is not None:
            at_rest = np.abs(self.model.gravity(q0))
            if np.any(at_rest > self.torque):
                joint = int(np.argmax(at_rest - self.torque))
                raise ValueError(
                    f"tau_max: the gravity torque at the mean position q0 alone "
                    f"({at_rest[joint]:.4g}) exceeds the limit of joint {joint + 1} "
                    f"({self.torque[joint]:.4g}): no amplitude helps"
                )
        if self.space is not None:
            values = keep_out_at(self.robot, self.space, q0, self.q_ref)
            if np.any(values < 0):
                _, pairs = capsule_pairs(self.robot, self.space, self.q_ref)
                label = constraint_labels(self.robot.n, self.space, pairs)[int(np.argmin(values))]
                raise ValueError(
                    f"keep_out: the arm standing at the mean position q0 violates it ({label}, "
                    f"by {-values.min():.4g} m): no amplitude helps"
                )
        low, high = 0.0, 1.0  # low always holds (0: standing still at q0)
        while high - low > 1e-6:
            middle = 0.5 * (low + high)
            low, high = (middle, high) if self.holds(scaled(trajectory, middle)) else (low, middle)
        return low
