"""The C++ level of the benchmark: write the arm, configure the root project with the benchmark
(bench/CMakeLists.txt, DYNID_BUILD_BENCH) and build it, run.

The C++ program (cpp/bench_dynamics.cpp) does its own agreement check and timing and prints one
JSON line; this module only prepares its input, builds it with CMake and reads its answer.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

BENCH_DIR = Path(__file__).resolve().parent
EXECUTABLE = "bench_dynamics"


def cmeel_prefixes() -> list[Path]:
    """Every ``cmeel.prefix`` on ``sys.path``: where the cmeel-eigen and pin wheels put their
    headers and CMake configs (Eigen3Config.cmake, pinocchio/...)."""
    found: list[Path] = []
    for entry in sys.path:
        prefix = Path(entry or ".") / "cmeel.prefix"
        if prefix.is_dir() and prefix.resolve() not in found:
            found.append(prefix.resolve())
    return found


def pinocchio_include_dir(prefixes: list[Path]) -> Path | None:
    """The include directory of the pin wheel's C++ headers, or None when it is not installed."""
    for prefix in prefixes:
        if (prefix / "include" / "pinocchio" / "multibody.hpp").is_file():
            return prefix / "include"
    return None


def write_model_file(robot: Any, path: Path) -> None:
    """The arm in the plain format of cpp/bench_inputs.hpp; repr() keeps every digit."""

    def numbers(values: Any) -> str:
        return " ".join(repr(float(x)) for x in np.ravel(values))

    lines = [
        "# written by bench/run.py from dynid: " + str(getattr(robot, "name", "robot")),
        f"convention {robot.convention}",
        f"gravity {numbers(robot.gravity_vector)}",
        f"base {numbers(robot.base)}",
    ]
    lines += [f"joint {t} {numbers(row)}" for t, row in zip(robot.joint_types, robot.dh)]
    lines += [f"params {numbers(row)}" for row in robot.params]
    lines += [f"Ia {numbers(robot.Ia)}", f"Fv {numbers(robot.Fv)}", f"Fs {numbers(robot.Fs)}"]
    path.write_text("\n".join(lines) + "\n")


def _run_logged(command: list[str], log: Path, what: str, hint: str = "") -> None:
    with log.open("w") as out:
        done = subprocess.run(command, stdout=out, stderr=subprocess.STDOUT, check=False)
    if done.returncode != 0:
        tail = "\n".join(log.read_text().splitlines()[-40:])
        raise SystemExit(f"bench: {what} failed (full log: {log}):\n{tail}\n{hint}".rstrip())


def build(build_dir: Path, *, native: bool, with_pinocchio: bool) -> Path:
    """Configure (when needed) and build the benchmark out of source; returns the executable."""
    cmake = shutil.which("cmake")
    if cmake is None:
        raise SystemExit("bench: cmake not found (pip install cmake, or install it system-wide)")
    prefixes = cmeel_prefixes()
    options = {
        "CMAKE_BUILD_TYPE": "Release",
        "CMAKE_PREFIX_PATH": ";".join(str(p) for p in prefixes),
        "DYNID_BUILD_BENCH": "ON",
        "DYNID_BUILD_TESTS": "OFF",
        "DYNID_NATIVE": "ON" if native else "OFF",
        "BENCH_WITH_PINOCCHIO": "ON" if with_pinocchio else "OFF",
    }
    build_dir.mkdir(parents=True, exist_ok=True)
    # find_path results are cached: a build directory configured from another interpreter (other
    # cmeel.prefix) or with other options starts again from an empty cache.
    stamp = build_dir / "run_py_options.json"
    cache = build_dir / "CMakeCache.txt"
    if cache.exists() and (not stamp.exists() or json.loads(stamp.read_text()) != options):
        cache.unlink()
    command = [cmake, "-S", str(BENCH_DIR.parent), "-B", str(build_dir)]
    if not cache.exists() and shutil.which("ninja"):
        command += ["-G", "Ninja"]
    command += [f"-D{key}={value}" for key, value in options.items()]
    hint = "bench: Eigen comes from the cmeel-eigen wheel (pip install cmeel-eigen) or the system"
    if any((p / "share" / "eigen3").is_dir() for p in prefixes):
        hint = ""
    _run_logged(command, build_dir / "configure.log", "CMake configuration", hint)
    stamp.write_text(json.dumps(options))

    if (
        with_pinocchio
        and pinocchio_include_dir(prefixes)
        and not any(build_dir.rglob("pinocchio_side.cpp.o"))
    ):
        print(
            "bench: compiling Pinocchio's headers (first build only: several minutes)", flush=True
        )
    command = [cmake, "--build", str(build_dir), "--parallel", str(os.cpu_count() or 1)]
    command += ["--target", EXECUTABLE]
    hint = "bench: --skip-cpp times the Python level alone"
    _run_logged(command, build_dir / "build.log", "C++ build", hint)
    return build_dir / "bench" / EXECUTABLE


def pinning_command(cpu: int | None) -> list[str]:
    """``taskset -c CPU`` when taskset exists and the CPU is ours: fewer migrations, steadier
    timings on a shared machine. Empty otherwise."""
    if cpu is None or shutil.which("taskset") is None:
        return []
    if not hasattr(os, "sched_getaffinity") or cpu not in os.sched_getaffinity(0):
        return []
    return ["taskset", "-c", str(cpu)]


def run(
    executable: Path, model_file: Path, *, runs: int, calls: int, states: int, cpu: int | None
) -> dict[str, Any]:
    """Run the C++ benchmark; its JSON answer plus the command used."""
    command = [
        *pinning_command(cpu), str(executable), str(model_file),
        "--runs", str(runs), "--calls", str(calls), "--states", str(states),
    ]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode == 2:
        raise SystemExit(
            "bench: dynid and Pinocchio disagree at the C++ level, nothing was timed:\n"
            + done.stderr
        )
    if done.returncode != 0:
        raise SystemExit(f"bench: {' '.join(command)} failed:\n{done.stderr}")
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    result["command"] = " ".join(command)
    result["pinned_cpu"] = cpu if pinning_command(cpu) else None
    return result
