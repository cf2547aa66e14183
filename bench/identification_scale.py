"""Identification at scale: a 100k-sample, 7-joint log with the 62 base parameters (rotor and
friction columns) of the LWR-IV, solved by dynid.least_squares (from the (T, 7, 62) regressor in
memory) and by dynid.least_squares_streaming (regressor computed chunk by chunk), OLS and WLS;
wall and CPU time and peak resident memory of each in a fresh process. A benchmark, not a test.

    python bench/identification_scale.py [--samples 100000] [--chunk 8192] [--modes streaming]

"peak MB" is the process's peak resident memory (inputs included), "inputs MB" the peak before
the timed part (the simulated log q, qd, qdd, tau and the imports).
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time


def run(mode: str, method: str, samples: int, chunk: int) -> dict:
    import numpy as np
    from threadpoolctl import threadpool_limits

    import dynid

    threadpool_limits(1)
    rng = np.random.default_rng(0)
    robot = dynid.models.kuka_lwr4()
    base = dynid.base_parameters(robot, "torque", rotor=True, friction=True)
    t = np.arange(samples) / 1000.0
    w = rng.uniform(0.2, 1.0, 7)
    q = np.sin(np.outer(t, w) + rng.uniform(0, 6, 7)) * 2
    qd = np.cos(np.outer(t, w)) * w * 2
    qdd = -np.sin(np.outer(t, w)) * w**2 * 2
    tau = robot.rnea(q, qd, qdd) + rng.normal(size=(samples, 7)) * 0.1
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.perf_counter()
    cpu_start = time.process_time()
    if mode == "in-memory":
        Y = robot.regressor(q, qd, qdd, rotor=True, friction=True, columns=base.independent)
        fit = dynid.least_squares(Y, tau, method=method)
    else:
        chunks = (
            (q[k : k + chunk], qd[k : k + chunk], qdd[k : k + chunk], tau[k : k + chunk])
            for k in range(0, samples, chunk)
        )
        fit = dynid.least_squares_streaming(
            robot, chunks, rotor=True, friction=True, columns=base.independent, method=method
        )
    elapsed = time.perf_counter() - start
    cpu = time.process_time() - cpu_start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return {
        "mode": mode,
        "method": method,
        "samples": samples,
        "p": int(fit.theta.size),
        "seconds": elapsed,
        "cpu_seconds": cpu,
        "peak_rss_mb": peak / 1024,
        "input_rss_mb": before / 1024,
        "theta0": float(fit.theta[0]),
        "std0": float(fit.std[0]),
    }


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--chunk", type=int, default=8192)
    parser.add_argument(
        "--modes",
        default="in-memory,streaming",
        help="comma-separated: in-memory (the (T, 7, 62) regressor, then "
        "least_squares) and/or streaming (least_squares_streaming)",
    )
    parser.add_argument("--child", nargs=2)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(run(*args.child, args.samples, args.chunk)))
        return
    print(
        f"{'mode':<10} {'method':<6} {'samples':>8} {'p':>3} {'wall s':>7} {'cpu s':>6} "
        f"{'peak MB':>8} {'inputs MB':>9}"
    )
    for mode in args.modes.split(","):
        for method in ("ols", "wls"):
            out = subprocess.run(
                [
                    sys.executable,
                    __file__,
                    "--samples",
                    str(args.samples),
                    "--chunk",
                    str(args.chunk),
                    "--child",
                    mode,
                    method,
                ],
                capture_output=True,
                text=True,
                check=True,
            )
            r = json.loads(out.stdout)
            print(
                f"{r['mode']:<10} {r['method']:<6} {r['samples']:>8} {r['p']:>3} "
                f"{r['seconds']:>7.3f} {r['cpu_seconds']:>6.3f} {r['peak_rss_mb']:>8.0f} "
                f"{r['input_rss_mb']:>9.0f}"
            )


if __name__ == "__main__":
    main()
