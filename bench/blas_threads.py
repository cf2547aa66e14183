"""Small dense work with OpenBLAS's default threads against the one-thread cap of dynid._threads,
in the same run (alternating, median of runs): base_parameters of the LWR-IV (torque, rotor and
friction columns) and a 20k-sample least squares. Run WITHOUT OPENBLAS_NUM_THREADS set. A
benchmark, not a test.

    python bench/blas_threads.py [--runs 15]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np
from threadpoolctl import threadpool_info

import dynid


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=15)
    args = parser.parse_args()
    bp = sys.modules["dynid.model.base_parameters"]
    robot = dynid.models.kuka_lwr4()
    base = dynid.base_parameters(robot, "torque", rotor=True, friction=True)
    rng = np.random.default_rng(0)
    q, qd, qdd = (rng.normal(size=(20_000, 7)) for _ in range(3))
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True, columns=base.independent)
    tau = robot.rnea(q, qd, qdd) + rng.normal(size=q.shape)
    import dynid.identification.identify as identify

    cases = {
        "base_parameters": (
            lambda: bp._compute.__wrapped__(robot, "torque", True, True),
            lambda: bp._compute(robot, "torque", True, True),
        ),
        "least_squares 20k x 62": (
            lambda: identify.least_squares.__wrapped__(Y, tau, method="wls"),
            lambda: identify.least_squares(Y, tau, method="wls"),
        ),
    }
    threads = {lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"}
    print(
        f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}, default BLAS threads "
        f"{threads}, load average {os.getloadavg()[0]:.1f}"
    )
    print(f"{'case':<24} {'default ms':>10} {'capped ms':>10} {'ratio':>6}")
    for name, (free, capped) in cases.items():
        times: dict[str, list[float]] = {"free": [], "capped": []}
        for _ in range(args.runs):
            for key, fn in (("free", free), ("capped", capped)):
                start = time.perf_counter()
                fn()
                times[key].append(time.perf_counter() - start)
        f, c = statistics.median(times["free"]) * 1e3, statistics.median(times["capped"]) * 1e3
        print(f"{name:<24} {f:>10.1f} {c:>10.1f} {c / f:>6.2f}")


if __name__ == "__main__":
    main()
