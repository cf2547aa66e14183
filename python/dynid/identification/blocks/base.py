"""The Block protocol: one named group of columns of the identification regressor.

An identified torque model is tau = Y theta with Y = [Y_base | Y_1 | Y_2 | ...]: the base
columns of the robot's regressor (lecture, "Least Squares (LS) identification", Robotics 2
pp. 26-28; :mod:`.rigid_body`) followed by the blocks asked for (asymmetric friction, torque
offsets, position torque, ...). A block owns everything about its columns: how they are built
from a run (``build``), their values at a state (``columns``), the names and expressions of
their coefficients, which coefficients the physically consistent fit constrains (``nonnegative``),
what the result file records about them (``record`` / ``from_record``) and the notes they add
to the training report. :class:`~.model.IdentificationModel` puts the blocks in order and gives
each its slice of theta, so no other code computes where a coefficient sits.

Adding a block (e.g. a friction model): one file with a subclass of :class:`Block` and one
``register(...)`` line in :mod:`.registry` (docs/identification.md, "Column blocks").

A block whose columns also depend on parameters that enter them nonlinearly (a friction law's
velocity scales) says so through :meth:`Block.nonlinear` (their names, values, bounds and
standard deviations) and gives :meth:`Block.with_parameters` and
:meth:`Block.torque_derivatives`; :func:`dynid.identify_log` then estimates them first by
separable least squares (:mod:`dynid.identification.separable`) and fits the linear
coefficients with them fixed.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ...model.robot import Robot


@dataclass(frozen=True)
class Nonlinear:
    """A block's parameters that enter its columns nonlinearly (e.g. velocity scales), in their
    units, each positive and within its bounds. ``std`` is inf until they are estimated (and
    where the data do not determine them)."""

    names: tuple[str, ...]
    values: tuple[float, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    std: tuple[float, ...]
    estimated: bool  #: whether ``values`` are an estimate on data (False: the starting values)
    #: starting values for the estimate (each like ``values``; the estimate tries them all)
    starts: tuple[tuple[float, ...], ...] = ()

    @property
    def size(self) -> int:
        return len(self.names)


@dataclass(frozen=True)
class Context:
    """What a block may depend on when :func:`dynid.identify_log` builds it: the robot and the
    options of the run (``friction`` is the friction model's name)."""

    robot: Robot
    rotor: bool
    friction: str
    offset: bool
    position_torque: bool


class Block(ABC):
    """A group of columns after the base parameters. Subclasses are frozen dataclasses (their
    fields are what the result file records, so equality of results compares them)."""

    #: Registry name of the block (:mod:`.registry`).
    key: ClassVar[str]
    #: The ``friction=`` value of :func:`dynid.identify_log` that selects this block, for a
    #: friction model; None for the other blocks.
    friction_model: ClassVar[str | None] = None
    #: The lowest result-file version that holds the block (:mod:`dynid.export.result_files`).
    version: ClassVar[int] = 2

    n: int  #: number of joints

    @classmethod
    @abstractmethod
    def build(cls, context: Context) -> Block | None:
        """The block for a run with these options, or None when they do not ask for it."""

    @classmethod
    @abstractmethod
    def from_record(cls, options: Mapping[str, Any], n: int) -> Block | None:
        """The block as :meth:`record` wrote it in ``options`` of result.json (None when the
        file has no such block). ValueError naming the option when malformed."""

    @abstractmethod
    def record(self) -> dict[str, Any]:
        """The entries of result.json's ``options`` that describe the block (JSON-ready)."""

    @abstractmethod
    def names(self) -> list[str]:
        """The names of the block's coefficients, in column order."""

    @abstractmethod
    def expressions(self) -> list[str]:
        """What each coefficient is, in words."""

    @abstractmethod
    def columns(self, q: NDArray[np.float64], qd: NDArray[np.float64]) -> NDArray[np.float64]:
        """(T, n, size) columns at the states (q, qd), both (T, n)."""

    @property
    def size(self) -> int:
        """Number of columns (coefficients)."""
        return len(self.names())

    def nonnegative(self) -> NDArray[np.bool_]:
        """(size,) the coefficients that the physically consistent fit keeps >= 0."""
        return np.zeros(self.size, dtype=bool)

    def notes(self) -> list[str]:
        """Notes for the training report (e.g. joints left out)."""
        return []

    def describe(self) -> str:
        """The block in the summary's list of coefficients, e.g. "7 offsets"."""
        return f"{self.size} {self.key.replace('_', ' ')} coefficients"

    # The optional nonlinear part (module docstring): blocks without one keep these defaults.

    def nonlinear(self) -> Nonlinear | None:
        """The parameters that enter the columns nonlinearly; None (the default) when the
        columns are functions of q and qd alone."""
        return None

    def with_parameters(self, values: NDArray[np.float64], std: NDArray[np.float64]) -> Block:
        """The same block with its nonlinear parameters set to ``values`` (estimated, with
        standard deviations ``std``), both in the order of ``nonlinear().names``."""
        raise NotImplementedError(f"block {self.key!r} has no nonlinear parameters")

    def torque_derivatives(
        self,
        q: NDArray[np.float64],
        qd: NDArray[np.float64],
        coefficients: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """(k, T, n) the derivatives of the block's torque ``columns(q, qd) @ coefficients``
        with respect to the logarithms of its k nonlinear parameters (v d/dv), at their
        current values (the Jacobian of the separable fit, :mod:`..separable`)."""
        raise NotImplementedError(f"block {self.key!r} has no nonlinear parameters")


class MeasurementBlock(ABC):
    """A group of columns that come from the measurement, not from the state: the log holds a
    signal s (e.g. motor currents) whose torque is ``torque(s, coefficients)``, linear in the
    coefficients, so that the torque model Y theta = tau reads Y theta - C(s) c = 0 with C(s)
    the block's ``columns``. Its coefficients are no part of the torque model's theta (the
    model predicts torques, the block converts the measurement); the result keeps them in a
    report of the block's own (``record``). Subclasses are frozen dataclasses."""

    #: Name of the block: its group of unknowns, and its entry of result.json.
    key: ClassVar[str]

    n: int  #: number of joints

    @abstractmethod
    def names(self) -> list[str]:
        """The names of the block's coefficients, in column order."""

    @abstractmethod
    def expressions(self) -> list[str]:
        """What each coefficient is, in words."""

    @abstractmethod
    def columns(self, measured: NDArray[np.float64]) -> NDArray[np.float64]:
        """(T, n, size) the columns C(s) of the measured signal s (T, n), with the sign they
        have on the model's side: Y theta + C(s) c = 0."""

    @abstractmethod
    def torque(
        self, measured: NDArray[np.float64], coefficients: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(T, n) the torque of the measured signal (T, n) with these coefficients (size,)."""

    @abstractmethod
    def record(self, report: Mapping[str, Any]) -> dict[str, Any]:
        """The entries of result.json that hold the block's ``report`` (JSON-ready)."""

    @classmethod
    @abstractmethod
    def from_record(cls, data: Mapping[str, Any], n: int) -> dict[str, Any] | None:
        """The block's report as :meth:`record` wrote it in result.json's ``data`` (None when
        the file has none). ValueError naming the entry when malformed."""

    @property
    def size(self) -> int:
        """Number of coefficients."""
        return len(self.names())
