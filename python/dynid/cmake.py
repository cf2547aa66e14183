"""Where the installed package keeps its C++ side, for C++ projects that use dynid without Python.

The wheel ships the public headers, the static core library and a CMake package config
(docs/cpp.md)::

    <site-packages>/dynid/include/dynid/*.hpp
    <site-packages>/dynid/lib/libdynid_core.a
    <site-packages>/dynid/lib/cmake/dynid/dynidConfig.cmake   (+ version and targets files)

A CMake project then finds it with ``find_package(dynid CONFIG REQUIRED)`` and links
``dynid::core``, given the folder of the config::

    cmake -S . -B build -Ddynid_DIR="$(python -m dynid.cmake --cmakedir)"

The paths are those of this installed package (not of a source tree or an editable install).
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["get_cmake_dir", "get_include"]

_PACKAGE = Path(__file__).resolve().parent


def get_cmake_dir() -> str:
    """The folder holding ``dynidConfig.cmake``: pass it as ``-Ddynid_DIR=...`` to CMake.

    Raises ``FileNotFoundError`` when the package was installed without its C++ files
    (e.g. run from a source tree).
    """
    folder = _PACKAGE / "lib" / "cmake" / "dynid"
    if not (folder / "dynidConfig.cmake").is_file():
        raise FileNotFoundError(
            f"dynidConfig.cmake not found in {folder}: dynid's C++ package is installed with the "
            "wheel (pip install dynid); a source tree does not contain it"
        )
    return str(folder)


def get_include() -> str:
    """The include folder: ``#include "dynid/dynid.hpp"`` compiles with ``-I<this folder>``
    (plus Eigen's include folder and C++17; link ``<package>/lib/libdynid_core.a``).

    Raises ``FileNotFoundError`` when the headers are not installed.
    """
    folder = _PACKAGE / "include"
    if not (folder / "dynid" / "dynid.hpp").is_file():
        raise FileNotFoundError(
            f"dynid/dynid.hpp not found in {folder}: dynid's C++ headers are installed with the "
            "wheel (pip install dynid); a source tree keeps them in cpp/include"
        )
    return str(folder)


def main(argv: list[str] | None = None) -> None:
    """``python -m dynid.cmake --cmakedir | --includedir``: print one of the folders."""
    parser = argparse.ArgumentParser(
        prog="python -m dynid.cmake", description="Folders of dynid's installed C++ package."
    )
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--cmakedir", action="store_true", help="the folder of dynidConfig.cmake")
    group.add_argument("--includedir", action="store_true", help="the C++ include folder")
    args = parser.parse_args(argv)
    print(get_cmake_dir() if args.cmakedir else get_include())


if __name__ == "__main__":
    main()
