"""The examples of docs/uses.md run as written (the sections on time scaling, bounds, payload).

Each ```python block of those sections is executed in a fresh namespace, in the documented order;
a block that raises, or whose `assert` fails, fails the test. The printed numbers quoted in the
comments are checked where they are stated as results.
"""

from __future__ import annotations

import contextlib
import functools
import io
import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[1] / "docs" / "uses.md"
SECTIONS = ("Uniform time scaling", "Bounds on the dynamic terms", "Payload estimation")


def blocks(section: str) -> list[str]:
    text = DOC.read_text(encoding="utf-8")
    parts = re.split(r"^## ", text, flags=re.MULTILINE)
    body = next(p for p in parts if p.startswith(section + "\n"))
    return re.findall(r"^```python\n(.*?)^```", body, flags=re.MULTILINE | re.DOTALL)


@functools.cache  # each example runs once per session
def run(code: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(DOC), "exec"), {"__name__": "__docs__"})
    return out.getvalue()


@pytest.mark.parametrize("section", SECTIONS)
def test_every_section_has_runnable_examples(section):
    codes = blocks(section)
    assert codes, f"no python example in section {section!r}"
    outputs = [run(code) for code in codes]
    assert all(outputs), "each example prints its result"


def test_the_quoted_numbers_are_what_the_examples_print():
    # The values quoted in the page's comments (rounded as printed).
    scaling = run(blocks("Uniform time scaling")[0])
    assert "k = 0.346" in scaling
    bounds = run(blocks("Bounds on the dynamic terms")[0])
    for text in (
        "k0 =    0.0707",
        "k1 =    4.3534",
        "k4 =    2.4231",
        "k6 =   55.9417",
        "samples alone:    1.9346",
    ):
        assert text in bounds, bounds
    payload = run(blocks("Payload estimation")[0])
    assert "m = 0.7995 +- 0.0004 kg" in payload
    paper = run(blocks("Payload estimation")[1]).splitlines()
    assert paper[0] == "eqs. (31), (32): [0.25001, 0.25]"
    assert paper[1].startswith("m = 0.25000 +- 5.5e-07 kg, c = [0.")
    assert paper[1].endswith("0.11] m")
    assert paper[2] == "I_C diagonal = [1.5e-04 1.5e-04 2.0e-05] kg m^2, std <= 1e-08"
    assert paper[3].startswith("m = 0.25000 kg at [0.")
