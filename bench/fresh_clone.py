#!/usr/bin/env python3
"""The README's times, measured as a new user meets them: a fresh clone, a fresh virtual
environment, then exactly the commands of the README's quickstart block, each timed.

    python bench/fresh_clone.py                    # clone HEAD of this repository
    python bench/fresh_clone.py --skip-tests       # install and demo only
    python bench/fresh_clone.py --json bench/results/fresh_clone.json

The quickstart block is read from README.md (the lines of its first ```bash block; each `&&`
part is one timed step), so the figures are those of the commands the README gives. pip's cache
is off (PIP_NO_CACHE_DIR), as on a new machine. The machine, its load and the commit are printed
and recorded with the times (docs/building.md quotes them).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from machine import describe_machine  # a sibling module: bench/ is sys.path[0] as a script

REPO = Path(__file__).resolve().parents[1]


def quickstart_steps(readme: str) -> list[str]:
    """The commands of the README's first ```bash block, split at `&&`."""
    block = re.search(r"^```bash\n(.*?)^```", readme, re.MULTILINE | re.DOTALL)
    if block is None:
        raise SystemExit("fresh_clone: README.md has no ```bash quickstart block")
    steps = []
    for line in block.group(1).splitlines():
        steps += [part.strip() for part in line.split("&&") if part.strip()]
    return steps


def timed(command: str, cwd: Path, env: dict[str, str], log: Path) -> tuple[float, str]:
    """Run ``command`` in a shell; (wall seconds, its output). Fails loudly on a non-zero exit."""
    start = time.perf_counter()
    done = subprocess.run(
        command, shell=True, cwd=cwd, env=env, capture_output=True, text=True, check=False
    )
    seconds = time.perf_counter() - start
    output = done.stdout + done.stderr
    log.write_text(output)
    if done.returncode != 0:
        tail = "\n".join(output.splitlines()[-30:])
        raise SystemExit(f"fresh_clone: `{command}` failed (exit {done.returncode}):\n{tail}")
    return seconds, output


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ref", default="HEAD", help="commit to clone (default: HEAD)")
    parser.add_argument("--skip-tests", action="store_true", help="stop after the first command")
    parser.add_argument("--json", type=Path, help="also write the figures to this file")
    args = parser.parse_args()

    commit = subprocess.run(
        ["git", "-C", str(REPO), "rev-parse", "--short", args.ref],
        capture_output=True, text=True, check=True,
    ).stdout.strip()  # fmt: skip
    machine = describe_machine()
    results: list[dict[str, object]] = []
    with tempfile.TemporaryDirectory(prefix="dynid-fresh-") as folder:
        clone = Path(folder) / "dynid"
        subprocess.run(["git", "clone", "-q", str(REPO), str(clone)], check=True)
        subprocess.run(["git", "-C", str(clone), "checkout", "-q", commit], check=True)
        venv = Path(folder) / "venv"
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        env = {**os.environ, "PIP_NO_CACHE_DIR": "1", "VIRTUAL_ENV": str(venv)}
        env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env['PATH']}"
        env.pop("PYTHONPATH", None)
        # As CI does (.ci/run), the venv's pip first brought up to date; not timed.
        timed("python -m pip install -q --upgrade pip", clone, env, Path(folder) / "pip.log")

        steps = quickstart_steps((clone / "README.md").read_text())
        if args.skip_tests:
            steps = steps[:2]
        for index, command in enumerate(steps):
            seconds, output = timed(command, clone, env, Path(folder) / f"step{index}.log")
            row: dict[str, object] = {"command": command, "wall_s": round(seconds, 1)}
            summary = re.search(r"^=*\s*(\d+) passed.* in ([0-9.]+)s", output, re.MULTILINE)
            if command.startswith("pytest") and summary:
                row["passed"] = int(summary.group(1))
                row["pytest_s"] = float(summary.group(2))
            results.append(row)
            print(f"{seconds:7.1f} s  {command}", flush=True)

    machine["load_average_end"] = [round(x, 2) for x in os.getloadavg()]
    print(f"commit {commit}; {machine['cpu']} ({machine['cpu_count']} cores); "
          f"load {machine['load_average']} -> {machine['load_average_end']}")  # fmt: skip
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        record = {"commit": commit, "machine": machine, "steps": results}
        args.json.write_text(json.dumps(record, indent=2) + "\n")


if __name__ == "__main__":
    main()
