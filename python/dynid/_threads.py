"""BLAS thread caps around small dense work.

OpenBLAS starts one thread per core for every call, which pays off for large matrices but makes
the many small factorisations of base_parameters, least squares, excitation optimisation and the
demo several times slower on a busy machine (threads waiting for cores that other processes
hold). Inside :func:`single_blas_thread` BLAS and LAPACK run on the calling thread; the previous
setting is restored on exit. The libraries are found once, on first use, by threadpoolctl.

    with single_blas_thread():
        ...                      # small dense work

    @blas_single_threaded
    def compute(...): ...
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

_controller: Any = None  # threadpoolctl.ThreadpoolController, made on first use


def _libraries() -> Any:
    global _controller
    if _controller is None:  # imported here: `import dynid` stays fast
        import scipy.linalg  # noqa: F401 -- SciPy's own OpenBLAS must be loaded to be found
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController()
    return _controller


def single_blas_thread() -> Any:
    """A context manager under which BLAS/LAPACK (NumPy's and SciPy's) use one thread."""
    return _libraries().limit(limits=1, user_api="blas")


def blas_single_threaded(function: F) -> F:
    """Decorator: ``function`` runs under :func:`single_blas_thread`."""

    @functools.wraps(function)
    def capped(*args: Any, **kwargs: Any) -> Any:
        with single_blas_thread():
            return function(*args, **kwargs)

    return capped  # type: ignore[return-value]
