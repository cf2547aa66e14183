"""The C++ test programs of tests/cpp/ (the size-check probe, the zero-allocation proofs and the
real-time example), built ONCE per test session, the way a C++ user builds against dynid: the
standalone CMake project tests/cpp configured with ``find_package(dynid)`` against the INSTALLED
package, so every program links the very ``dynid::core`` the wheel ships (its SIMD lane
kernels, run-time dispatch and Eigen settings), compiled with AddressSanitizer and
UndefinedBehaviorSanitizer when the compiler supports them.

The session fixture ``cpp_tests`` (conftest.py) builds it once for the whole run: under
pytest-xdist the first worker that needs it builds it in a folder shared by the workers, under a
file lock, and the others wait for it and reuse it.
Without a C++ compiler or cmake the calling test is skipped, except in CI, where it fails: the
proofs must run on a clean machine (requirements/test.txt brings Eigen, CMake and Ninja; the
compiler comes with the machine)."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import pytest
from filelock import FileLock

REPO = Path(__file__).resolve().parents[1]
PROGRAMS = (
    "size_checks",
    "rls_no_allocation",
    "simulator_no_allocation",
    "elastic_no_allocation",
    "transmission_no_allocation",
    "uses_no_allocation",
    "batch",
    "model_file",
    "realtime_loop",
)


def find_compiler() -> str | None:
    for candidate in (os.environ.get("CXX"), "g++", "c++", "clang++"):
        if candidate and shutil.which(candidate):
            return shutil.which(candidate)
    return None


def find_tool(name: str) -> str | None:
    """A build tool on PATH, else next to this Python (a venv's bin/), else its PyPI package's."""
    found = shutil.which(name) or shutil.which(name, path=str(Path(sys.executable).parent))
    if found:
        return found
    try:  # the `cmake` and `ninja` wheels keep their binaries in the package
        module = __import__(name)
        folder = getattr(module, "CMAKE_BIN_DIR", None) or getattr(module, "BIN_DIR", None)
    except ImportError:
        return None
    return shutil.which(name, path=folder) if folder else None


def require_build_tools() -> tuple[str, str, str]:
    """(compiler, cmake, ctest), or skip (fail in CI) when one is missing."""
    compiler, cmake, ctest = find_compiler(), find_tool("cmake"), find_tool("ctest")
    if compiler is None or cmake is None or ctest is None:
        assert not os.environ.get("CI"), (
            f"CI needs a C++ compiler and cmake/ctest: compiler={compiler}, cmake={cmake}, "
            f"ctest={ctest}"
        )
        pytest.skip(
            "needs a C++ compiler (CXX, g++, c++, clang++) and cmake/ctest (PATH or "
            f"`pip install cmake`): compiler={compiler}, cmake={cmake}, ctest={ctest}"
        )
    return compiler, cmake, ctest


@dataclass(frozen=True)
class CppTests:
    """The built tests/cpp project: its folder, whether the sanitizers are on, the configure
    output and the tools that built it."""

    build: Path
    sanitized: bool
    configure_output: str
    ctest: str

    def run(self, program: str, *arguments: str) -> str:
        """Run one program of the build; it must exit 0 without a sanitizer report. Returns its
        standard output and error."""
        assert program in PROGRAMS, program
        command = [str(self.build / program), *arguments]
        output = run_tool(command, timeout=600, env={**os.environ, **SANITIZER_OPTIONS})
        assert not SANITIZER_REPORT.search(output), output
        return output


# The same settings as ctest's (tests/cpp/CMakeLists.txt): stop at the first report.
SANITIZER_OPTIONS = {
    "ASAN_OPTIONS": "halt_on_error=1:detect_leaks=1:strict_string_checks=1",
    "UBSAN_OPTIONS": "print_stacktrace=1:halt_on_error=1",
}
SANITIZER_REPORT = re.compile(
    r"AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|runtime error:"
)


def run_tool(command: list[str], timeout: float = 900, env: dict[str, str] | None = None) -> str:
    """Run a build or test tool (cmake, ctest, a program); it must exit 0. Its output."""
    done = subprocess.run(
        command, capture_output=True, text=True, timeout=timeout, check=False, env=env
    )
    output = done.stdout + done.stderr
    assert done.returncode == 0, f"{command}:\n{output}"
    return output


def cmake_configure(source: Path, build: Path, *options: str) -> str:
    """``cmake -S source -B build`` with this machine's compiler (Ninja when there is one),
    compile_commands.json written; returns CMake's output."""
    compiler, cmake, _ = require_build_tools()
    command = [cmake, "-S", str(source), "-B", str(build), f"-DCMAKE_CXX_COMPILER={compiler}"]
    command += ["-DCMAKE_EXPORT_COMPILE_COMMANDS=ON", *options]
    ninja = find_tool("ninja")
    if ninja:
        command += ["-G", "Ninja", f"-DCMAKE_MAKE_PROGRAM={ninja}"]
    return run_tool(command, timeout=300)


def cmake_build(build: Path) -> str:
    """Build every target of ``build`` on every core."""
    _, cmake, _ = require_build_tools()
    return run_tool([cmake, "--build", str(build), "--parallel", str(os.cpu_count() or 1)])


def compile_commands(build: Path) -> list[str]:
    """The compiler command of every file of a configured build."""
    entries = json.loads((build / "compile_commands.json").read_text())
    return [e.get("command") or " ".join(e["arguments"]) for e in entries]


def build_cpp_tests(folder: Path) -> CppTests:
    """Configure tests/cpp against the installed dynid in ``folder`` and build every program."""
    import dynid.cmake

    configured = cmake_configure(
        REPO / "tests" / "cpp", folder, f"-Ddynid_DIR={dynid.cmake.get_cmake_dir()}"
    )
    cmake_build(folder)
    return CppTests(folder, "sanitizers ON" in configured, configured, require_build_tools()[2])


def shared_build(folder: Path) -> CppTests:
    """The build in ``folder``, made by the first process that asks (a file lock keeps the
    pytest-xdist workers of one run from building it twice) and reused by the others."""
    record = folder / "cpp_tests.json"
    with FileLock(f"{folder}.lock"):
        if record.is_file():
            fields = json.loads(record.read_text())
            return CppTests(**{**fields, "build": Path(fields["build"])})
        built = build_cpp_tests(folder)
        record.write_text(json.dumps({**asdict(built), "build": str(built.build)}))
        return built
