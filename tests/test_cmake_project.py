"""The root CMake project as a C++ user without pip meets it (docs/building.md):

- `cmake -S . -B build` configures with no scikit-build-core and no pybind11 (the Python
  extension is off outside pip), taking the version from python/dynid/_version.py;
- `cmake --build` builds the same core as the wheel: the same source files (cpp/src/*.cpp and
  the lane kernels of every instruction set), and the same exported Eigen settings as the
  installed package's dynid::core;
- `ctest` passes: the seven programs of tests/cpp and examples_installed, which runs
  `cmake --install`, builds cpp/examples against the installed tree with find_package(dynid) and
  runs its 1 kHz loop.

Skipped only without a C++ compiler or cmake, and failed instead when CI is set.
"""

from __future__ import annotations

import json
import os
import platform
import re
import subprocess
from pathlib import Path

import dynid
import dynid.cmake
from cpp_programs import PROGRAMS, REPO, find_tool, require_build_tools


def test_root_project_builds_tests_and_installs_the_core(tmp_path: Path) -> None:
    compiler, cmake, ctest = require_build_tools()
    build = tmp_path / "build"
    configure = [
        cmake, "-S", str(REPO), "-B", str(build), f"-DCMAKE_CXX_COMPILER={compiler}",
        "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON",
    ]  # fmt: skip
    ninja = find_tool("ninja")
    if ninja:
        configure += ["-G", "Ninja", f"-DCMAKE_MAKE_PROGRAM={ninja}"]
    step = subprocess.run(configure, capture_output=True, text=True, timeout=300, check=False)
    assert step.returncode == 0, step.stdout + step.stderr
    cache = (build / "CMakeCache.txt").read_text()
    assert re.search(r"^CMAKE_PROJECT_VERSION:STATIC=(.*)$", cache, re.MULTILINE)[1] == (
        dynid.__version__
    )
    assert "DYNID_BUILD_PYTHON:BOOL=OFF" in cache

    step = subprocess.run(
        [cmake, "--build", str(build), "--parallel", str(os.cpu_count() or 1)],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert step.returncode == 0, step.stdout + step.stderr

    # The same core as the wheel: every source of cpp/src, the lane kernels included, and the
    # Eigen settings the installed package exports.
    commands = json.loads((build / "compile_commands.json").read_text())
    compiled = {Path(entry["file"]).resolve() for entry in commands}
    sources = set((REPO / "cpp" / "src").glob("*.cpp"))
    if platform.machine().lower() in ("x86_64", "amd64"):
        sources |= set((REPO / "cpp" / "src" / "batch").glob("lanes_*.cpp"))
    assert sources <= compiled, sorted(map(str, sources - compiled))
    installed = "".join(
        p.read_text() for p in Path(dynid.cmake.get_cmake_dir()).glob("dynidTargets*.cmake")
    )
    settings = re.search(r'INTERFACE_COMPILE_DEFINITIONS "([^"]*)"', installed)
    assert settings, installed
    rnea = next(e for e in commands if e["file"].endswith("src/rnea.cpp"))
    command = rnea.get("command") or " ".join(rnea["arguments"])
    for definition in settings[1].split(";"):
        assert definition.startswith("EIGEN_"), definition
        assert f"-D{definition}" in command, (definition, command)

    run = subprocess.run(
        [ctest, "--test-dir", str(build), "--output-on-failure"],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    output = run.stdout + run.stderr
    assert run.returncode == 0, output
    assert f"100% tests passed out of {len(PROGRAMS) + 1}" in output, output
    assert "examples_installed" in output, output
    installed_config = build / "tests" / "cpp" / "installed" / "lib" / "cmake" / "dynid"
    assert (installed_config / "dynidConfig.cmake").is_file()
