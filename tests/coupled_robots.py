"""The coupled-wrist PUMA 560 of the transmission tests (docs/transmission.md): motor 5 turns with
joint 4, motor 6 with joints 4 and 5. The ratios are the tests' own: the PUMA's published
coupling ratios are not in puma560()'s references."""

from __future__ import annotations

import numpy as np

import dynid

T_WRIST = np.array([[1.0, 0.0, 0.0], [0.2, 1.0, 0.0], [-0.15, 0.3, 1.0]])


def coupled_puma() -> dynid.Robot:
    robot = dynid.models.puma560()
    T = np.eye(6)
    T[3:, 3:] = T_WRIST
    robot.transmission = T
    return robot
