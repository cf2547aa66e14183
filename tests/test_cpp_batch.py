"""The public C++ batch API (dynid/batch.hpp), as a C++ user builds it against the installed
package (tests/cpp/test_batch.cpp, built once per session by tests/cpp_programs.py, with the
sanitizers when the compiler has them): every dynid::batch call equals the per-sample call on
random states to 1e-12 on every batch path the CPU runs, two threads give the one-thread results
bit for bit, wrong sizes are std::invalid_argument naming the argument, and a reused
BatchWorkspace on one thread allocates nothing."""

from __future__ import annotations

import re

from cpp_programs import CppTests
from dynid import _core


def test_cpp_batch_api_equals_single_calls_and_allocates_nothing(cpp_tests: CppTests) -> None:
    output = cpp_tests.run("batch")
    paths = re.search(r"paths checked: (.*)", output)
    assert paths is not None, output
    # The program checks the paths of the CPU it runs on: those the Python batches use too.
    assert paths.group(1).split() == list(_core._supported_batch_isas()), output
    for path in paths.group(1).split():
        assert f"{path}: allocations_during_batches=0" in output, output
