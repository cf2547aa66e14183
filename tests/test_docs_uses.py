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
        exec(compile(code, str(DOC), "exec"), {"__name__": "__docs__"})  # noqa: S102 -- the doc's own code
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
    for text in ("k0 =    0.0707", "k1 =    4.3534", "k4 =    2.4231", "k6 =   55.9417",
                 "samples alone:    1.9346"):
        assert text in bounds, bounds
    payload = run(blocks("Payload estimation")[0])
    assert "m = 0.7995 +- 0.0004 kg" in payload
    static = run(blocks("Payload estimation")[1]).splitlines()
    masses = [float(x) for x in re.findall(r"[\d.]+", static[0])]
    assert len(masses) == 2 and all(abs(m - 0.25) < 0.0025 for m in masses)
    assert static[1].startswith("0.25")
