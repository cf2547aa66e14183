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
import platform
import re
from pathlib import Path

import dynid
import dynid.cmake
from cpp_programs import (
    PROGRAMS,
    REPO,
    cmake_build,
    cmake_configure,
    compile_commands,
    require_build_tools,
    run_tool,
)


def test_root_project_builds_tests_and_installs_the_core(tmp_path: Path) -> None:
    build = tmp_path / "build"
    cmake_configure(REPO, build)
    cache = (build / "CMakeCache.txt").read_text()
    assert re.search(r"^CMAKE_PROJECT_VERSION:STATIC=(.*)$", cache, re.MULTILINE)[1] == (
        dynid.__version__
    )
    assert "DYNID_BUILD_PYTHON:BOOL=OFF" in cache

    cmake_build(build)

    # The same core as the wheel: every source of cpp/src, the lane kernels included, and the
    # Eigen settings the installed package exports.
    entries = json.loads((build / "compile_commands.json").read_text())
    compiled = {Path(entry["file"]).resolve() for entry in entries}
    sources = set((REPO / "cpp" / "src").glob("*.cpp"))
    if platform.machine().lower() in ("x86_64", "amd64"):
        sources |= set((REPO / "cpp" / "src" / "batch").glob("lanes_*.cpp"))
    assert sources <= compiled, sorted(map(str, sources - compiled))
    installed = "".join(
        p.read_text() for p in Path(dynid.cmake.get_cmake_dir()).glob("dynidTargets*.cmake")
    )
    settings = re.search(r'INTERFACE_COMPILE_DEFINITIONS "([^"]*)"', installed)
    assert settings, installed
    command = next(c for c in compile_commands(build) if "src/rnea.cpp" in c)
    for definition in settings[1].split(";"):
        assert definition.startswith("EIGEN_"), definition
        assert f"-D{definition}" in command, (definition, command)

    output = run_tool([require_build_tools()[2], "--test-dir", str(build), "--output-on-failure"])
    assert f"100% tests passed out of {len(PROGRAMS) + 1}" in output, output
    assert "examples_installed" in output, output
    installed_config = build / "tests" / "cpp" / "installed" / "lib" / "cmake" / "dynid"
    assert (installed_config / "dynidConfig.cmake").is_file()
