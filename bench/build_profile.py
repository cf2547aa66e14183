#!/usr/bin/env python3
"""Where the build's CPU time goes: every translation unit of the wheel's build, timed.

Configures the root CMake project as pip does (the core and the extension, Release, Ninja) in a
new folder and builds it twice: once with one job, so that each file's time from Ninja's log is
its own (the CPU-seconds a build costs), once with every core, for the wall time a user waits.
Prints the files from slowest, the total, and both wall times; --json writes them.

    python bench/build_profile.py                # needs cmake, ninja, pybind11, cmeel-eigen
    python bench/build_profile.py --json bench/results/build_profile.json

Run it on an idle machine; the numbers quoted in docs/building.md come from it.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from machine import describe_machine  # a sibling module: bench/ is sys.path[0] as a script

REPO = Path(__file__).resolve().parents[1]


def configure(build: Path) -> None:
    import pybind11

    command = [
        "cmake", "-S", str(REPO), "-B", str(build), "-G", "Ninja",
        "-DSKBUILD=2", "-DCMAKE_BUILD_TYPE=Release", f"-Dpybind11_DIR={pybind11.get_cmake_dir()}",
        "-DSKBUILD_PROJECT_VERSION=0", f"-DPython_EXECUTABLE={sys.executable}",
    ]  # fmt: skip
    subprocess.run(command, check=True, capture_output=True, text=True)


def build(build: Path, jobs: int) -> float:
    """Build from clean with ``jobs`` jobs; returns the wall time in seconds."""
    subprocess.run(["ninja", "-C", str(build), "clean"], check=True, capture_output=True)
    log = build / ".ninja_log"
    log.unlink(missing_ok=True)
    start = time.perf_counter()
    subprocess.run(["ninja", "-C", str(build), f"-j{jobs}"], check=True, capture_output=True)
    return time.perf_counter() - start


def unit_times(build: Path) -> dict[str, float]:
    """Seconds per output of the last build, from Ninja's log (start and end in ms)."""
    times: dict[str, float] = {}
    for line in (build / ".ninja_log").read_text().splitlines()[1:]:
        start, end, _, output, _ = line.split("\t")
        times[output] = (int(end) - int(start)) / 1000.0
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="also write the figures to this file")
    parser.add_argument("--top", type=int, default=15, help="files listed (default: 15)")
    args = parser.parse_args()
    for tool in ("cmake", "ninja"):
        if shutil.which(tool) is None:
            raise SystemExit(f"build_profile: {tool} not found (pip install {tool})")

    with tempfile.TemporaryDirectory(prefix="dynid-build-") as folder:
        build_dir = Path(folder)
        configure(build_dir)
        serial_wall = build(build_dir, 1)
        units = unit_times(build_dir)
        jobs = os.cpu_count() or 1
        parallel_wall = build(build_dir, jobs)

    total = sum(units.values())
    print(f"{'seconds':>8}  output (one job)")
    for output, seconds in sorted(units.items(), key=lambda item: -item[1])[: args.top]:
        print(f"{seconds:8.1f}  {output}")
    print(f"{total:8.1f}  total over {len(units)} outputs (serial wall {serial_wall:.1f} s)")
    print(f"{parallel_wall:8.1f}  wall with {jobs} jobs")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        record = {
            "machine": describe_machine(),
            "units_s": units,
            "total_cpu_s": total,
            "serial_wall_s": serial_wall,
            "parallel_wall_s": parallel_wall,
            "jobs": jobs,
        }
        args.json.write_text(json.dumps(record, indent=2) + "\n")


if __name__ == "__main__":
    main()
