"""The BLAS thread cap (dynid._threads) around small dense work: inside it every BLAS library
NumPy and SciPy loaded reports one thread (threadpoolctl's own view), and the previous setting
comes back on exit; the capped entry points run under it."""

from __future__ import annotations

import numpy as np
from threadpoolctl import threadpool_info, threadpool_limits

import dynid
from dynid._threads import blas_single_threaded, single_blas_thread


def blas_threads() -> list[int]:
    return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]


def test_cap_and_restore() -> None:
    with threadpool_limits(limits=2, user_api="blas"):
        assert blas_threads() and set(blas_threads()) == {2}
        with single_blas_thread():
            assert set(blas_threads()) == {1}
        assert set(blas_threads()) == {2}


def test_decorated_function_runs_capped_and_returns_its_value() -> None:
    seen: list[list[int]] = []

    @blas_single_threaded
    def work(x: np.ndarray) -> float:
        seen.append(blas_threads())
        return float(np.linalg.norm(x))

    with threadpool_limits(limits=2, user_api="blas"):
        assert work(np.array([3.0, 4.0])) == 5.0
        assert set(blas_threads()) == {2}
    assert set(seen[0]) == {1}


def test_entry_points_are_capped(monkeypatch) -> None:
    # base_parameters, least_squares and the streaming solver see one BLAS thread inside.
    import dynid.identification._qr as qr

    seen: list[set[int]] = []
    original = qr.upper_triangle

    def spy(block):
        seen.append(set(blas_threads()))
        return original(block)

    monkeypatch.setattr(qr, "upper_triangle", spy)
    robot = dynid.models.kuka_lwr4()
    with threadpool_limits(limits=2, user_api="blas"):
        base = dynid.base_parameters(robot.copy(), "gravity")
        Y = robot.gravity_regressor(robot.random_configurations(50))[..., base.independent]
        dynid.least_squares(Y, robot.gravity(robot.random_configurations(50)))
        acc = dynid.LeastSquaresAccumulator(7, base.independent.size)
        acc.add(Y, np.zeros((50, 7)))
    assert seen and all(s == {1} for s in seen)
