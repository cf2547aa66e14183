"""What an estimator of the log identification sees and returns.

:func:`dynid.identify_log` builds the columns (base parameters, then the column blocks) and folds
the rows into the triangular factors of least squares; "ols" and "wls" are solved there. Any
other ``method`` is a registered estimator (:mod:`.registry`): it receives the whole problem --
the stacked regressor, the torques, the rows kept, the prepared logs, the model that evaluates
the regressor at other states, and the WLS fit as a starting point -- and returns its estimate
with standard deviations, optional per-row weights (the physically consistent fit of the same
method uses them) and a JSON-ready report that result.json keeps under ``estimator``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from ..identify import LeastSquaresResult

if TYPE_CHECKING:
    from ...logs.log_files import Log
    from ...model.robot import Robot
    from ..blocks.model import IdentificationModel


@dataclass(frozen=True, eq=False)
class Problem:
    """The identification problem of the training logs, as :func:`dynid.identify_log` built it.

    The arrays stack every training log's samples in the order given (log k's samples are
    ``slice(starts[k], starts[k + 1])``); rows left out (``--min-velocity``) are zero in ``Y``
    and ``tau`` and False in ``keep``; the joints in ``excluded`` take no part in the fit.
    """

    Y: NDArray[np.float64]  #: (T, n, p) the regressor of theta: base columns, then the blocks'
    tau: NDArray[np.float64]  #: (T, n) the measured joint torques
    keep: NDArray[np.bool_]  #: (T, n) the rows that take part (False: left out)
    excluded: tuple[int, ...]  #: joints (0-based) left out of the fit
    names: list[str]  #: the p coefficients' names
    runs: tuple[Log, ...]  #: the prepared training logs (q, qd, qdd, tau, t)
    starts: NDArray[np.int64]  #: (logs + 1,) where each log's samples start in the stacked arrays
    robot: Robot  #: the robot whose base parameters are identified (its DH table, gravity...)
    model: IdentificationModel  #: ``model.regressor(q, qd, qdd)`` at any other states
    start: LeastSquaresResult  #: the WLS fit on these rows: rank, noise levels, a first estimate
    #: the estimator's own options (``identify_log(estimator_options=...)``, the CLI's flags)
    options: Mapping[str, Any] = field(default_factory=dict)

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.tau.shape[1])

    @property
    def p(self) -> int:
        """Number of coefficients."""
        return int(self.Y.shape[2])

    @property
    def joints(self) -> tuple[int, ...]:
        """The joints that take part in the fit (0-based)."""
        return tuple(j for j in range(self.n) if j not in self.excluded)


@dataclass(frozen=True, eq=False)
class EstimatorFit:
    """An estimator's answer: the estimate (same fields as least squares: theta, std,
    covariance, noise variance per joint, rank, condition number), the weight it gave each row
    in the end (None: the per-joint weights of WLS), and what it did, JSON-ready."""

    result: LeastSquaresResult
    row_weights: NDArray[np.float64] | None = None  #: (T, n) >= 0, or None
    report: dict[str, Any] = field(default_factory=dict)  #: e.g. iterations, loss, outliers
    notes: tuple[str, ...] = ()  #: warnings in words, also printed by the CLI


class Estimator(Protocol):
    """A registered estimator: the problem in, its fit out. Bad options: ValueError naming the
    option; data that cannot support the estimate: a RuntimeWarning, or a ValueError."""

    def __call__(self, problem: Problem) -> EstimatorFit: ...
