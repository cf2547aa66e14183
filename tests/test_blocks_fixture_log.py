"""The log of tests/data/results_before_blocks/ (written by dynid before the column blocks):
a 3-harmonic trajectory of models.planar_2r() with asymmetric friction, offsets, a position
torque on joint 2 and seeded noise, rebuilt here to identify it again."""

from __future__ import annotations

import numpy as np

import dynid
from dynid.logs import Log
from test_log_identification import fourier_log


def fixture_log(robot: dynid.Robot) -> Log:
    log = fourier_log(robot, 3, seconds=10.0)
    rng = np.random.default_rng(5)
    qd = log.qd
    friction = np.where(qd > 0, 0.3 * qd + 0.2, np.where(qd < 0, 0.5 * qd - 0.1, 0.0))
    position = np.zeros_like(log.tau)
    position[:, 1] = 0.05 * np.sin(log.q[:, 1]) - 0.02 * np.cos(log.q[:, 1])
    tau = log.tau + friction + position + np.array([0.1, -0.2])
    tau = tau + rng.normal(scale=0.01, size=tau.shape)
    return Log(t=log.t, q=log.q, tau=tau, qd=log.qd, qdd=log.qdd, source="planar-2r-fixture")
