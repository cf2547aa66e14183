"""The Python level of the benchmark: what a user calling dynid or Pinocchio from Python gets.

Single calls: one state per call, both libraries called as a user would write it, over the
same precomputed NumPy states. Batch: dynid's ``robot.rnea(Q, Qd, Qdd)`` on T states against
a Python loop of ``pinocchio.rnea`` (Pinocchio has no batch API), storing into a (T, n) array
as the batch call does. Results are compared before anything is timed.
"""

from __future__ import annotations

import os
import statistics
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np
from numpy.typing import NDArray

TOLERANCE = 1e-9
Array = NDArray[np.float64]
State = tuple[Array, Array, Array]


def make_states(n: int, count: int, seed: int) -> tuple[Array, Array, Array]:
    """q in [-pi, pi], qd in [-2, 2] rad/s, qdd in [-5, 5] rad/s^2, as in the C++ program;
    float64 C-contiguous (T, n), dynid's fast path, whose rows are contiguous (n,) views."""
    rng = np.random.default_rng(seed)
    return (
        rng.uniform(-np.pi, np.pi, (count, n)),
        rng.uniform(-2.0, 2.0, (count, n)),
        rng.uniform(-5.0, 5.0, (count, n)),
    )


def time_interleaved(
    loops: Sequence[Callable[[], object]], runs: int, per_run: int
) -> list[dict[str, float]]:
    """Median and minimum over ``runs`` runs of each loop's time per call [us].

    The loops' runs alternate (a, b, a, b, ...) so that a change in the machine's load hits all
    alike; run -1 is an untimed warm-up. ``per_run`` is the number of calls one loop makes.
    """
    samples: list[list[float]] = [[] for _ in loops]
    for run in range(-1, runs):
        for j, loop in enumerate(loops):
            start = time.perf_counter_ns()
            loop()
            elapsed = time.perf_counter_ns() - start
            if run >= 0:
                samples[j].append(elapsed / 1e3 / per_run)
    return [{"median": statistics.median(s), "min": min(s)} for s in samples]


def _worst(a: Any, b: Any) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))))


def _full(M: Array) -> Array:
    # whether a binding returns Pinocchio's upper triangle or the symmetric M, this is M
    return np.triu(M) + np.triu(M, 1).T


def check_single(
    robot: Any, pin: Any, model: Any, data: Any, states: Sequence[State]
) -> dict[str, float]:
    """Largest |dynid - Pinocchio| of rnea, mass matrix and gravity over the states; exits if
    any exceeds the tolerance."""
    worst = {"rnea": 0.0, "mass_matrix": 0.0, "gravity": 0.0}
    for q, qd, qdd in states:
        worst["rnea"] = max(
            worst["rnea"], _worst(robot.rnea(q, qd, qdd), pin.rnea(model, data, q, qd, qdd))
        )
        worst["mass_matrix"] = max(
            worst["mass_matrix"], _worst(robot.mass_matrix(q), _full(pin.crba(model, data, q)))
        )
        worst["gravity"] = max(
            worst["gravity"],
            _worst(robot.gravity(q), pin.computeGeneralizedGravity(model, data, q)),
        )
    _require_agreement(worst, "Python single calls")
    return worst


def _require_agreement(worst: dict[str, float], where: str) -> None:
    bad = {k: v for k, v in worst.items() if not v <= TOLERANCE}
    if bad:
        detail = ", ".join(f"{k}: max |diff| = {v:.3g}" for k, v in bad.items())
        raise SystemExit(
            f"bench: dynid and Pinocchio disagree ({where}, > {TOLERANCE:g}): {detail}"
        )


def time_single(
    robot: Any, pin: Any | None, model: Any, data: Any, states: Sequence[State], runs: int
) -> dict[str, Any]:
    """Per function: dynid's and (with Pinocchio) Pinocchio's time per single call [us].

    Each loop is written as a user would write it, names looked up once, no wrapper around the
    call, so both sides pay the same Python loop overhead (reported as ``loop_overhead_us``).
    """
    qs = [s[0] for s in states]

    def empty_loop() -> None:
        for _q, _qd, _qdd in states:
            pass

    def dynid_rnea() -> None:
        rnea = robot.rnea
        for q, qd, qdd in states:
            rnea(q, qd, qdd)

    def dynid_mass_matrix() -> None:
        mass_matrix = robot.mass_matrix
        for q in qs:
            mass_matrix(q)

    def dynid_gravity() -> None:
        gravity = robot.gravity
        for q in qs:
            gravity(q)

    loops: dict[str, list[Callable[[], None]]] = {
        "rnea": [dynid_rnea], "mass_matrix": [dynid_mass_matrix], "gravity": [dynid_gravity],
    }  # fmt: skip
    if pin is not None:

        def pin_rnea() -> None:
            rnea = pin.rnea
            for q, qd, qdd in states:
                rnea(model, data, q, qd, qdd)

        def pin_crba() -> None:
            # the Python binding of crba returns the full symmetric M (checked in check_single)
            crba = pin.crba
            for q in qs:
                crba(model, data, q)

        def pin_gravity() -> None:
            gravity = pin.computeGeneralizedGravity
            for q in qs:
                gravity(model, data, q)

        loops["rnea"].append(pin_rnea)
        loops["mass_matrix"].append(pin_crba)
        loops["gravity"].append(pin_gravity)

    result: dict[str, Any] = {
        "loop_overhead_us": time_interleaved([empty_loop], runs, len(states))[0]["median"]
    }
    for name, pair in loops.items():
        stats = time_interleaved(pair, runs, len(states))
        result[name] = {"dynid": stats[0], "pinocchio": stats[1] if pin is not None else None}
    return result


def batch(
    robot: Any,
    pin: Any | None,
    model: Any,
    data: Any,
    Q: Array,
    Qd: Array,
    Qdd: Array,
    runs: int,
) -> dict[str, Any]:
    """Batch rnea on the T states in (Q, Qd, Qdd): time per state [us], after checking that
    dynid's batch equals Pinocchio's loop."""
    T, n = Q.shape

    def dynid_batch() -> None:
        robot.rnea(Q, Qd, Qdd)

    def pin_loop() -> Array:
        rnea = pin.rnea
        out = np.empty((T, n))
        for k, (q, qd, qdd) in enumerate(zip(Q, Qd, Qdd)):
            out[k] = rnea(model, data, q, qd, qdd)
        return out

    result: dict[str, Any] = {"states": T}
    loops: list[Callable[[], object]] = [dynid_batch]
    if pin is not None:
        result["max_abs_diff"] = _worst(robot.rnea(Q, Qd, Qdd), pin_loop())
        _require_agreement({"batch rnea": result["max_abs_diff"]}, "Python batch")
        loops.append(pin_loop)
    stats = time_interleaved(loops, runs, T)
    result["dynid"] = stats[0]
    result["pinocchio"] = stats[1] if pin is not None else None
    result["threads"] = None  # filled by batch_threaded (dynid.set_threads)
    return result


def batch_kernels(
    robot: Any,
    pin: Any | None,
    model: Any,
    data: Any,
    Q: Array,
    Qd: Array,
    Qdd: Array,
    runs: int,
) -> dict[str, Any]:
    """Batch gravity, mass matrix and (rigid-body) regressor on the T states, time per state
    [us], against Python loops of Pinocchio's computeGeneralizedGravity, crba and
    computeJointTorqueRegressor; and batch rnea on every SIMD path this CPU runs
    (dynid._core._set_batch_isa), checked against the scalar path."""
    from dynid import _core

    T, n = Q.shape
    calls: dict[str, tuple[Callable[[], object], Callable[[], object] | None]] = {
        "gravity": (lambda: robot.gravity(Q), None),
        "mass_matrix": (lambda: robot.mass_matrix(Q), None),
        "regressor": (lambda: robot.regressor(Q, Qd, Qdd), None),
        # the same into a preallocated array: no fresh pages to clear (T x n x 10n doubles)
        "regressor_out": (lambda: robot.regressor(Q, Qd, Qdd, out=regressor_out), None),
    }
    regressor_out = np.empty((T, n, 10 * n))
    if pin is not None:

        def pin_gravity() -> Array:
            out = np.empty((T, n))
            for k, q in enumerate(Q):
                out[k] = pin.computeGeneralizedGravity(model, data, q)
            return out

        def pin_crba() -> Array:
            out = np.empty((T, n, n))
            for k, q in enumerate(Q):
                out[k] = pin.crba(model, data, q)
            return out

        def pin_regressor() -> Array:
            out = np.empty((T, n, 10 * n))
            for k, (q, qd, qdd) in enumerate(zip(Q, Qd, Qdd)):
                out[k] = pin.computeJointTorqueRegressor(model, data, q, qd, qdd)
            return out

        calls = {
            name: (calls[name][0], fn)
            for name, fn in (
                ("gravity", pin_gravity),
                ("mass_matrix", pin_crba),
                ("regressor", pin_regressor),
                ("regressor_out", pin_regressor),
            )
        }
    result: dict[str, Any] = {"states": T, "isa": _core._batch_isa()}
    for name, (ours, theirs) in calls.items():
        stats = time_interleaved([ours] + ([theirs] if theirs else []), runs, T)
        result[name] = {"dynid": stats[0], "pinocchio": stats[1] if theirs else None}
    chosen = _core._batch_isa()
    paths: dict[str, Any] = {}
    try:
        _core._set_batch_isa("scalar")
        reference = robot.rnea(Q, Qd, Qdd)
        for isa in _core._supported_batch_isas():
            _core._set_batch_isa(isa)
            _require_agreement(
                {f"batch rnea {isa}": _worst(robot.rnea(Q, Qd, Qdd), reference)},
                f"{isa} lanes vs scalar",
            )
            paths[isa] = time_interleaved([lambda: robot.rnea(Q, Qd, Qdd)], runs, T)[0]
    finally:
        _core._set_batch_isa(chosen)
    result["rnea_per_path"] = paths
    return result


def batch_threaded(
    robot: Any, Q: Array, Qd: Array, Qdd: Array, runs: int, threads: int
) -> dict[str, Any] | None:
    """dynid's batch rnea on ``threads`` threads (``dynid.set_threads``), time per state [us],
    checked against the single-thread call; None when this dynid has no thread setting."""
    import dynid

    if not hasattr(dynid, "set_threads"):
        return None
    previous = dynid.get_threads()
    try:
        dynid.set_threads(1)
        single = robot.rnea(Q, Qd, Qdd)
        dynid.set_threads(threads)
        _require_agreement(
            {"threaded batch rnea": _worst(robot.rnea(Q, Qd, Qdd), single)},
            "dynid threaded vs single-thread batch",
        )
        stat = time_interleaved([lambda: robot.rnea(Q, Qd, Qdd)], runs, len(Q))[0]
    finally:
        dynid.set_threads(previous)
    return {"count": threads, "dynid": stat}


@contextmanager
def pinned_to(cpu: int | None) -> Iterator[int | None]:
    """Run the block on one CPU (as the C++ program under taskset), then restore the affinity.
    Yields the CPU, or None when pinning is not possible here."""
    if cpu is None or not hasattr(os, "sched_setaffinity") or cpu not in os.sched_getaffinity(0):
        yield None
        return
    before = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {cpu})
    try:
        yield cpu
    finally:
        os.sched_setaffinity(0, before)
