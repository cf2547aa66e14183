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
low-pass: the position quantum delta_j of joint j (the 1st percentile of the nonzero
|q_j[k+1] - q_j[k]| of the log as read: a quantized angle moves by whole counts) toggling at the
filter's cutoff f_c has a velocity amplitude of about 2 pi f_c delta_j; without a filter, one
count per sample, fs delta_j. On the Staubli TX40 (5 kHz, cutoff 100 Hz) that is 6e-4 to 1.4e-2
rad/s, and its held-out error with rest velocities falls from 62.6 to 41.6 % on the wrist
(docs/real_data.md). An angle that is not quantized (a simulated, exact log) moves by tiny
steps near a reversal, so its estimate is tiny and nothing but rounding-level velocities change.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import real_array

#: The percentile of the nonzero position steps taken as the quantum (robust to a rare
#: sub-count step from interpolation or a coupled joint's mixed encoders).
QUANTUM_PERCENTILE = 1.0


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
            moving = steps[:, j][steps[:, j] > 0]
            quantum[j] = np.percentile(moving, QUANTUM_PERCENTILE) if moving.size else 0.0
        rate = 2 * np.pi * cutoff if cutoff is not None else fs
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


def at_rest(qd: ArrayLike, velocity: NDArray[np.float64]) -> NDArray[np.bool_]:
    """(T, n) True where |qd_j| < v_j: the joint is at rest."""
    return np.abs(np.asarray(qd, dtype=float)) < velocity
