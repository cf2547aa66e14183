"""Building and running the small C++ test programs of tests/cpp/ (the zero-allocation proofs)
straight from the core's sources: one compiler search, one Eigen search, one build-and-run.

Without a C++ compiler the calling test is skipped, except in CI, where it fails: the proofs must
run on a clean machine (the `test` extra brings Eigen; the compiler comes with the machine)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def find_compiler() -> str | None:
    for candidate in (os.environ.get("CXX"), "g++", "c++", "clang++"):
        if candidate and shutil.which(candidate):
            return shutil.which(candidate)
    return None


def find_eigen() -> Path:
    """Eigen's include folder: the cmeel-eigen wheel (as in CMakeLists.txt), else the system."""
    for entry in map(Path, sys.path):
        candidate = entry / "cmeel.prefix" / "include" / "eigen3"
        if (candidate / "Eigen" / "Core").is_file():
            return candidate
    for candidate in (Path("/usr/include/eigen3"), Path("/usr/local/include/eigen3")):
        if (candidate / "Eigen" / "Core").is_file():
            return candidate
    pytest.fail("Eigen not found: pip install cmeel-eigen (or install the system's eigen3)")


def build_and_run(
    folder: Path,
    program: str,
    core_sources: Sequence[str] | None = None,
    optimisation: str = "-O2",
) -> str:
    """Compile ``tests/cpp/{program}.cpp`` with the named ``cpp/src`` files (default: all of
    them), ``-DNDEBUG``, into ``folder``, run it and return its output; the build and the run
    must succeed."""
    compiler = find_compiler()
    if compiler is None:
        assert not os.environ.get("CI"), "CI needs a C++ compiler (CXX, g++, c++, clang++)"
        pytest.skip("no C++ compiler found (CXX, g++, c++, clang++)")
    if core_sources is None:
        sources = sorted(str(p) for p in (REPO / "cpp" / "src").glob("*.cpp"))
    else:
        sources = [str(REPO / "cpp" / "src" / f"{name}.cpp") for name in core_sources]
    executable = folder / program
    build = subprocess.run(
        [
            compiler,
            optimisation,
            "-DNDEBUG",
            "-std=c++17",
            f"-I{REPO / 'cpp' / 'include'}",
            f"-I{REPO / 'cpp' / 'examples'}",  # allocation_counter.hpp
            f"-I{find_eigen()}",
            str(REPO / "tests" / "cpp" / f"{program}.cpp"),
            *sources,
            "-o",
            str(executable),
        ],
        check=False,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert build.returncode == 0, build.stderr
    run = subprocess.run(
        [str(executable)], check=False, capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stdout + run.stderr
    return run.stdout
