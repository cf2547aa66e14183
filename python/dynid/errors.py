"""Exceptions of dynid beyond ``ValueError`` (bad input), in a module of their own so that the
command line can catch them without importing the modules that raise them (and their SciPy and
cvxpy imports)."""

from __future__ import annotations


class PhysicalIdentificationError(RuntimeError):
    """The semidefinite programme was not solved to optimality (``status`` says how it ended:
    e.g. "infeasible" when the mass bounds contradict the total mass)."""

    def __init__(self, message: str, status: str) -> None:
        super().__init__(message)
        self.status = status
