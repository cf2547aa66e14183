"""Joints at rest: velocities too small to be motion set to exactly zero (``prepare_log``'s
``rest_velocity``; docs/data.md, "Joints at rest").

Coulomb friction Fs sign(qd) is defined by the sign of qd. A joint standing still has qd = 0,
but a velocity differentiated from a quantized, filtered encoder angle is not: the angle
toggling by one count, or constant up to the filter's rounding, gives |qd| of 1e-17 to 1e-3
rad/s, and sign(qd) then adds +Fs or -Fs at random. At rest the static friction is anywhere in
[-Fs, Fs]; its best prediction is 0 = Fs sign(0). The lecture's hint (Robotics 2 notes, "further
practical hints": with friction in the model, data at velocities close to zero are unreliable)
drops such samples; here they are kept with qd_j = 0 (for the Coulomb term) when |qd_j| is below
a rest velocity v_j, given or estimated.

The estimate ("auto") is the velocity that one encoder count makes after the preparation's
low-pass: the position quantum delta_j of joint j toggling at the filter's cutoff f_c has a
velocity amplitude of about 2 pi f_c delta_j. Without a filter the differentiated velocity of a
quantized angle is exactly 0 or at least one count over the central difference's two steps,
fs delta_j / 2; the rest velocity is then fs delta_j / 4, which catches only what rounding made
of a zero.
delta_j is the smallest step |q_j[k+1] - q_j[k]| of the log as read that recurs: the steps are
grouped where they are equal up to QUANTUM_TOLERANCE (the rounding of a unit conversion such as
q = theta / N), and the smallest group of at least QUANTIZED_SHARE of the nonzero steps is one
encoder count. A smooth angle (a simulated log) has no recurring step, so it gets no rest
velocity (its small steps are only the speeds near a reversal; zeroing them would bias the
fit). On the Staubli TX40 (5 kHz, cutoff 100 Hz) the estimates are 1.3e-2 to 2e-2 rad/s, and its
held-out error falls from 62.6 to 44.2 % on the wrist (docs/real_data.md).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import real_array

#: A step value is a count when at least this share of the nonzero steps (and MIN_COUNTS of them)
#: equal it up to QUANTUM_TOLERANCE relative (the rounding of a conversion such as q = theta / N).
#: Encoder counts recur in 1.4-14 % of the Staubli TX40's steps; a smooth periodic trajectory
#: repeats a step once per period (0.2 % for 3 periods of 1000 samples), which stays below.
QUANTIZED_SHARE = 0.01
MIN_COUNTS = 5
QUANTUM_TOLERANCE = 1e-6


def rest_velocity(
    value: float | str | ArrayLike, q: NDArray[np.float64], fs: float, cutoff: float | None
) -> NDArray[np.float64]:
    """(n,) the rest velocity of each joint: ``value`` (a scalar or one per joint, >= 0) or
    "auto", estimated from the positions ``q`` (T, n) as read, sampled at ``fs`` [Hz], filtered
    at ``cutoff`` [Hz] (None: no filter)."""
    n = q.shape[1]
    if isinstance(value, str):
        if value != "auto":
            raise ValueError(f"rest_velocity: expected 'auto' or a velocity >= 0, got {value!r}")
        steps = np.abs(np.diff(q, axis=0))
        quantum = np.zeros(n)
        for j in range(n):
            quantum[j] = _count(steps[:, j][steps[:, j] > 0])
        rate = 2 * np.pi * cutoff if cutoff is not None else fs / 4
        return quantum * rate
    velocity = real_array(value, "rest_velocity")
    if velocity.ndim > 1 or (velocity.ndim == 1 and velocity.size != n):
        raise ValueError(
            f"rest_velocity: expected a scalar or {n} values (one per joint), got shape "
            f"{velocity.shape}"
        )
    if np.any(velocity < 0):
        raise ValueError(f"rest_velocity: expected values >= 0, got {velocity.tolist()}")
    return np.broadcast_to(velocity, (n,)).astype(float)


def _count(steps: NDArray[np.float64]) -> float:
    """The smallest recurring step (module docstring), or 0 when no step recurs."""
    if not steps.size:
        return 0.0
    ordered = np.sort(steps)
    # a new group where a step exceeds the previous one by more than the tolerance
    starts = np.concatenate(
        [[0], np.nonzero(np.diff(ordered) > QUANTUM_TOLERANCE * ordered[1:])[0] + 1]
    )
    sizes = np.diff(np.concatenate([starts, [ordered.size]]))
    enough = max(MIN_COUNTS, QUANTIZED_SHARE * ordered.size)
    recurring = np.nonzero(sizes >= enough)[0]
    return float(ordered[starts[recurring[0]]]) if recurring.size else 0.0


def at_rest(qd: ArrayLike, velocity: NDArray[np.float64]) -> NDArray[np.bool_]:
    """(T, n) True where |qd_j| < v_j: the joint is at rest."""
    return np.abs(np.asarray(qd, dtype=float)) < velocity
