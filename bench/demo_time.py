"""Wall time of ``dynid demo`` as a user runs it after ``pip install .`` (issue 13 item 5,
target < 2 s): the median of fresh processes of the installed ``dynid`` command, each writing
into a new folder, with the load average before and after (the machine is shared). The demo's
own "(x s)" figures leave out the interpreter's start and the imports; this does not. A
benchmark, not a test.

    python bench/demo_time.py [--runs 9]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=9)
    args = parser.parse_args()
    command = shutil.which("dynid")
    if command is None:
        raise SystemExit("demo_time: the dynid command is not installed (pip install .)")
    load_before = os.getloadavg()[0]
    walls = []
    with tempfile.TemporaryDirectory() as folder:
        for k in range(args.runs):
            start = time.perf_counter()
            subprocess.run(
                [command, "demo", "--output", str(Path(folder) / f"run{k}")],
                check=True,
                capture_output=True,
            )
            walls.append(time.perf_counter() - start)
    print(
        f"dynid demo wall time over {args.runs} runs: median {statistics.median(walls):.2f} s, "
        f"min {min(walls):.2f} s, max {max(walls):.2f} s "
        f"(load average {load_before:.1f} before, {os.getloadavg()[0]:.1f} after)"
    )


if __name__ == "__main__":
    main()
