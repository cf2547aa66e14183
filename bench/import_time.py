"""How long ``import dynid`` takes beyond ``import numpy`` (issue 14 item 15, target < 0.3 s in
all), and for comparison ``import pinocchio``: the median of fresh interpreters, one after the
other in the same run. A benchmark, not a test.

    python bench/import_time.py [--runs 21]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys

CODE = (
    "import time; t0 = time.perf_counter(); import numpy; t1 = time.perf_counter(); "
    "import {module}; t2 = time.perf_counter(); print(t1 - t0, t2 - t1)"
)


def measure(module: str, runs: int) -> tuple[float, float]:
    numpy_times, module_times = [], []
    for _ in range(runs):
        out = subprocess.run(
            [sys.executable, "-c", CODE.format(module=module)],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()
        numpy_times.append(float(out[0]))
        module_times.append(float(out[1]))
    return statistics.median(numpy_times), statistics.median(module_times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=21)
    args = parser.parse_args()
    print(f"{'module':<12}{'numpy [s]':>12}{'module beyond numpy [s]':>26}{'total [s]':>12}")
    for module in ("dynid", "pinocchio"):
        try:
            numpy_s, module_s = measure(module, args.runs)
        except subprocess.CalledProcessError:
            print(f"{module:<12}{'not installed':>12}")
            continue
        print(f"{module:<12}{numpy_s:>12.3f}{module_s:>26.3f}{numpy_s + module_s:>12.3f}")


if __name__ == "__main__":
    main()
