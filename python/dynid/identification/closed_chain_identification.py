"""Identification of a closed-chain robot's base parameters from a log (lecture pp. 26-28 on the
closed chain's regressor G^T Y_tree, :mod:`dynid.model.closed_chain`).

The log holds the independent (actuated) joints only, as a closed-chain robot's controller
records them: q, tau (and qd, qdd when it has them) of the n motors. The log goes through the same
:func:`dynid.prepare_log` as a serial robot's; the base columns of the closed chain's regressor
(one batch over the samples) and the torques are solved by :func:`dynid.least_squares`.
"""

from __future__ import annotations

import dataclasses
import inspect
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._equality import ValueEquality
from ..logs.log_files import Log
from ..logs.preparation import prepare_log
from ..model.base_parameters import BaseParameters
from ..model.closed_chain import ClosedChain
from .identify import VARIANCE_FLOOR, LeastSquaresResult, least_squares, relative_std
from .log_identification import _with_derivatives
from .serial_correlation import correlation_note, correlation_robust_covariance


@dataclass(frozen=True, eq=False)
class ClosedChainIdentification(ValueEquality):
    """The identified base parameters of a closed chain: ``fit.theta`` estimates
    ``base.values(chain)`` (names ``base.names``, expressions ``base.expressions``)."""

    base: BaseParameters
    fit: LeastSquaresResult
    notes: list[str]  #: what was done to the log (``Log.notes`` of the prepared log)

    @property
    def theta(self) -> NDArray[np.float64]:
        return self.fit.theta

    @property
    def std(self) -> NDArray[np.float64]:
        return self.fit.std

    def predict(self, chain: ClosedChain, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> Any:
        """Torques of the identified model at the given states of ``chain``'s independent joints."""
        Y = chain.regressor(
            q,
            qd,
            qdd,
            rotor=self.base.rotor,
            friction=self.base.friction,
            columns=self.base.independent,
        )
        return Y @ self.fit.theta


def identify_closed_chain(
    log: Log,
    chain: ClosedChain,
    *,
    rotor: bool = False,
    friction: bool = False,
    method: str = "wls",
    on_rank_deficient: str = "raise",
    **preparation: Any,
) -> ClosedChainIdentification:
    """Least-squares estimate of ``chain``'s base parameters (with Ia, Fv, Fs of the independent
    joints when ``rotor``, ``friction``) from ``log``.

    ``preparation`` goes to :func:`dynid.prepare_log` (``cutoff``, ``decimate``, ``trim_edges``,
    ...); qd and qdd are differentiated from q when the log lacks them. ``method`` and
    ``on_rank_deficient`` as for :func:`dynid.least_squares`; the regressor's rank must be the
    base parameters' count, or the log does not excite the chain enough (RankDeficientError).
    """
    if not isinstance(chain, ClosedChain):
        raise ValueError(f"chain: expected a dynid.ClosedChain, got {type(chain).__name__}")
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    known = [name for name in inspect.signature(prepare_log).parameters if name != "log"]
    unknown = [name for name in preparation if name not in known]
    if unknown:
        raise ValueError(
            f"{unknown[0]}: not an option of identify_closed_chain or dynid.prepare_log "
            f"(those are: {', '.join(known)})"
        )
    prepared = _with_derivatives(
        prepare_log(log, **preparation) if preparation else log, chain.n, chain.name
    )
    assert prepared.qd is not None and prepared.qdd is not None  # _with_derivatives made them
    base = chain.base_parameters("torque", rotor=rotor, friction=friction)
    Y = chain.regressor(
        prepared.q,
        prepared.qd,
        prepared.qdd,
        rotor=rotor,
        friction=friction,
        columns=base.independent,
    )
    Y = Y.reshape(-1, chain.n, base.count)
    fit = least_squares(
        Y, prepared.tau, method=method, names=base.names, on_rank_deficient=on_rank_deficient
    )
    notes = list(prepared.notes)
    fit, note = _correlation_robust(fit, Y, prepared.tau)
    return ClosedChainIdentification(base=base, fit=fit, notes=notes + note)


def _correlation_robust(
    fit: LeastSquaresResult, Y: NDArray[np.float64], tau: NDArray[np.float64]
) -> tuple[LeastSquaresResult, list[str]]:
    """The fit with the correlation-robust covariance when its residuals are correlated in time
    (a filtered log: :mod:`dynid.identification.serial_correlation`, as ``identify_log``)."""
    if fit.rank < fit.theta.size or not np.all(np.isfinite(fit.covariance)):
        return fit, []
    weights = np.ones(tau.shape[1])
    if fit.method == "wls":
        variance = np.asarray(fit.noise_variance, dtype=float)
        largest = variance.max()
        weights = 1.0 / np.maximum(variance, VARIANCE_FLOOR * largest) if largest > 0 else weights
    robust = correlation_robust_covariance(Y, tau - Y @ fit.theta, weights)
    if robust is None:
        return fit, []
    covariance, correlation_time, width = robust
    std = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    ratio = std / np.where(fit.std > 0, fit.std, np.inf)
    note = correlation_note(correlation_time, width, ratio)
    robust_fit = dataclasses.replace(
        fit, covariance=covariance, std=std, relative_std=relative_std(fit.theta, std)
    )
    return robust_fit, [note]
