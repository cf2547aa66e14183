"""The drive-gain block: tau_j = k_j i_j, for a log of motor currents i instead of torques.

k_j is joint j's drive gain (motor torque constant times gear ratio, torque per unit of the
logged current). The torque model Y theta = tau then reads Y theta - diag(i) k = 0 (Gautier &
Briot, "Global identification of joint drive gains and dynamic parameters of robots", ASME J.
Dyn. Syst. Meas. Control 136(5), 2014): the columns -diag(i) come from the measurement, so this
is a :class:`~.base.MeasurementBlock`, and its coefficients are kept out of the torque model's
theta in the result's ``drive_gains`` report (result.json ``drive_gains``: ``gains``, their
standard deviations, the payload that fixed the scale, the runs; written by
:func:`dynid.identify_drive_gains`). No sign constraint: the sign of a gain is the sign
convention of the logged current, which the physics does not fix.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .base import MeasurementBlock

#: Name of the drive gain of joint j (1-based): "k1", "k2", ...
GAIN_NAME = "k"
#: The block's entry of result.json.
RECORD_KEY = "drive_gains"


@dataclass(frozen=True)
class DriveGains(MeasurementBlock):
    """Columns -diag(i): row j of a sample holds -i_j in the column of k_j."""

    key = RECORD_KEY
    n: int

    def names(self) -> list[str]:
        return [f"{GAIN_NAME}{j}" for j in range(1, self.n + 1)]

    def expressions(self) -> list[str]:
        return [f"drive gain of joint {j} (torque per unit current)" for j in range(1, self.n + 1)]

    def columns(self, measured: NDArray[np.float64]) -> NDArray[np.float64]:
        current = np.asarray(measured, dtype=float).reshape(-1, self.n)
        C = np.zeros((current.shape[0], self.n, self.n))
        C[:, np.arange(self.n), np.arange(self.n)] = -current
        return C

    def torque(
        self, measured: NDArray[np.float64], coefficients: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.asarray(measured, dtype=float) * np.asarray(coefficients, dtype=float)

    def note(self, gains: NDArray[np.float64]) -> str:
        """The note a log gets when its currents are converted to torques."""
        return "tau = k * current with the identified drive gains k = " + ", ".join(
            f"{k:.6g}" for k in gains
        )

    def record(self, report: Mapping[str, Any]) -> dict[str, Any]:
        return {RECORD_KEY: dict(report)}

    @classmethod
    def from_record(cls, data: Mapping[str, Any], n: int) -> dict[str, Any] | None:
        report = data.get(RECORD_KEY)
        if report is None:
            return None
        if not isinstance(report, Mapping):
            raise ValueError(f"{RECORD_KEY}: expected an object, got {type(report).__name__}")
        if "gains" not in report:
            raise ValueError(f"{RECORD_KEY}.gains: missing")
        try:
            values = np.ravel(np.asarray(report["gains"], dtype=object))
            if any(isinstance(k, bool) for k in values):
                raise TypeError
            gains = np.asarray(report["gains"], dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"{RECORD_KEY}.gains: expected numbers") from None
        if gains.shape != (n,) or not np.all(np.isfinite(gains)):
            raise ValueError(
                f"{RECORD_KEY}.gains: expected {n} finite gains, got {np.ravel(gains).tolist()}"
            )
        return dict(report)
