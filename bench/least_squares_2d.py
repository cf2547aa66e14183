"""dynid.least_squares on a stacked system Y (N, p), tau (N,) against numpy.linalg.lstsq on the
same arrays: 100k samples of the LWR-IV's 62 base columns (rotor and friction) stacked by joint,
700k x 62 (issue 22: the target is at most half lstsq's time). Both run on one BLAS thread
(least_squares always does; lstsq is capped here, so the ratio compares the algorithms), in
alternation, and each figure is the median of the runs. A measurement, not a test.

    python bench/least_squares_2d.py [--samples 100000] [--runs 5]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable

import numpy as np
from threadpoolctl import threadpool_limits

import dynid
from dynid.identification.identify import stack_by_joint


def stacked_system(samples: int) -> tuple[np.ndarray, np.ndarray]:
    """A (7 samples, 62) and b (7 samples,): the LWR-IV's base regressor, torques with noise."""
    rng = np.random.default_rng(0)
    robot = dynid.models.kuka_lwr4()
    base = dynid.base_parameters(robot, "torque", rotor=True, friction=True)
    q, qd, qdd = (rng.uniform(-2.0, 2.0, (samples, robot.n)) for _ in range(3))
    Y = robot.regressor(q, qd, qdd, rotor=True, friction=True, columns=base.independent)
    tau = robot.rnea(q, qd, qdd) + rng.normal(scale=0.1, size=(samples, robot.n))
    A, b, _ = stack_by_joint(Y, tau)
    return A, b


def seconds(call: Callable[[], object]) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    A, b = stacked_system(args.samples)
    load_before = os.getloadavg()
    calls = {
        "dynid.least_squares": lambda: dynid.least_squares(A, b),
        "numpy.linalg.lstsq": lambda: np.linalg.lstsq(A, b, rcond=None),
    }
    times: dict[str, list[float]] = {name: [] for name in calls}
    with threadpool_limits(1, user_api="blas"):
        for _ in range(args.runs):  # alternating: both see the same machine load
            for name, call in calls.items():
                times[name].append(seconds(call))
        theta = dynid.least_squares(A, b).theta
        reference = np.linalg.lstsq(A, b, rcond=None)[0]
    load_after = os.getloadavg()
    median = {name: statistics.median(values) for name, values in times.items()}
    print(f"stacked system {A.shape[0]} x {A.shape[1]}, {args.runs} runs, one BLAS thread")
    for name, value in median.items():
        print(f"  {name:<20} median {value:7.3f} s  (min {min(times[name]):.3f} s)")
    ratio = median["dynid.least_squares"] / median["numpy.linalg.lstsq"]
    print(f"  ratio least_squares / lstsq: {ratio:.2f} (target <= 0.5)")
    difference = np.linalg.norm(theta - reference) / np.linalg.norm(reference)
    print(f"  |theta - theta_lstsq| / |theta_lstsq| = {difference:.1e}")
    print(
        "  load average (1, 5, 15 min) before "
        f"{', '.join(f'{x:.2f}' for x in load_before)}, after "
        f"{', '.join(f'{x:.2f}' for x in load_after)}"
    )


if __name__ == "__main__":
    main()
