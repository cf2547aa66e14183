"""The C++ tests (tests/cpp: the size-check probe, the zero-allocation proofs and the real-time
example) built with AddressSanitizer and UndefinedBehaviorSanitizer against the INSTALLED
package (tests/cpp_programs.py, built once per session), run by ctest.

- size_checks: every public algorithm, given each argument with a wrong size in turn, throws
  std::invalid_argument naming that argument, and with the right sizes agrees with
  independent routes (rnea = M qdd + S qd + g + friction, Y pi = rnea, ...) to 1e-9;
- the *_no_allocation programs and cpp/examples/realtime_loop: 0 heap allocations in their loops
  (counted through the sanitizer's allocation hook under ASan);
- any sanitizer report fails (ctest's FAIL_REGULAR_EXPRESSION, and checked here again). The
  program is instrumented while the installed core is not: this only works because the exported
  dynid::core carries Eigen's alignment settings (EIGEN_MALLOC_ALREADY_ALIGNED, ...), without
  which ASan reports a heap-buffer-overflow in Eigen's aligned free (docs/cpp.md).

Skipped only without a C++ compiler or cmake, and then failed instead when CI is set.
"""

from __future__ import annotations

import os
import re

import dynid.cmake
from cpp_programs import (
    PROGRAMS,
    REPO,
    SANITIZER_REPORT,
    CppTests,
    compile_commands,
    find_compiler,
    run_tool,
)


def test_cpp_tests_pass_under_address_and_undefined_sanitizers(
    cpp_tests: CppTests, record_property
):
    record_property("sanitizers", cpp_tests.sanitized)
    compiler = find_compiler() or ""
    if os.environ.get("CI") and compiler.endswith(("g++", "clang++")):
        assert cpp_tests.sanitized, cpp_tests.configure_output  # GCC and Clang support both

    # The programs were compiled against the installed headers with the sanitizers and with the
    # Eigen settings of the installed core, which come from the exported target.
    for command in compile_commands(cpp_tests.build):
        assert dynid.cmake.get_include() in command, command
        assert str(REPO / "cpp" / "include") not in command, command
        assert "-DEIGEN_MALLOC_ALREADY_ALIGNED=" in command, command
        assert "-DEIGEN_MAX_ALIGN_BYTES=" in command, command
        if cpp_tests.sanitized:
            assert "-fsanitize=address,undefined" in command, command

    output = run_tool(
        [cpp_tests.ctest, "--test-dir", str(cpp_tests.build), "--output-on-failure", "-V"]
    )
    assert not SANITIZER_REPORT.search(output), output
    assert f"100% tests passed out of {len(PROGRAMS)}" in output, output
    assert re.search(r"size checks: (\d+) probes, 0 failures", output), output
    assert "allocations_during_updates=0" in output, output
    assert re.search(r"allocations: 0 allocations in 1000 cycles", output), output


def test_dynid_hpp_includes_every_public_header_and_internals_are_in_detail():
    """docs/cpp.md, "What is API": dynid/dynid.hpp includes every public header; the headers under
    dynid/detail/ declare only namespace dynid::detail (compared against the files on disk)."""
    include = REPO / "cpp" / "include" / "dynid"
    umbrella = (include / "dynid.hpp").read_text()
    public = sorted(p.name for p in include.glob("*.hpp") if p.name != "dynid.hpp")
    missing = [name for name in public if f'#include "dynid/{name}"' not in umbrella]
    assert not missing, missing
    details = sorted((include / "detail").glob("*.hpp"))
    assert {p.name for p in details} >= {
        "joint_transform.hpp",
        "joint_geometry.hpp",
        "newton_euler.hpp",
        "workspace_buffers.hpp",
        "argument_checks.hpp",
    }
    for header in details:
        namespaces = set(re.findall(r"^namespace ([\w:]+) \{", header.read_text(), re.MULTILINE))
        assert namespaces == {"dynid::detail"}, (header.name, namespaces)
    # The internals left the public headers.
    for name in public:
        text = (include / name).read_text()
        for internal in (
            "propagate_motion",
            "accumulate_wrenches",
            "struct JointTransform",
            "struct LinkOffset",
            "struct JointGeometry",
            "update_joint_transforms",
        ):
            assert internal not in text, (name, internal)
