"""The documentation is self-contained and every reference into it resolves.

- No file cites the product specification that early code referred to and that never lived in
  this repository, nor a file outside the repository (the shared folder beside it): the
  contracts are in docs/.
- Every docs page that a file names exists (``docs/cli.md``), with the heading it names: an
  anchor (``docs/cpp.md#argument-checks``), or the start of a heading or of a paragraph's bold
  title in quotes (``docs/uses.md, "Collision residual"``, the form the code uses).
- Every relative Markdown link of a ``.md`` file points to a file that exists, and to a heading
  of it when it has an anchor.
- ``tools/spec_references.py`` (the script that rewrote the citations) maps hand-written
  examples to the expected text, maps every section to a page and heading that exist, and
  changes nothing on a second run.

Anchors are computed here independently of the script, by GitHub's rule: the heading in lower
case, punctuation other than ``-`` and ``_`` dropped, each space a hyphen, ``-1``, ``-2`` ... on
repeats. Headings inside code blocks do not count.
"""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from functools import cache
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
#: The word of the citations, in two pieces so that this file does not cite it.
WORD = "SP" + "EC"
#: This file and the script that rewrote the citations quote the forms they look for.
QUOTING = ("tests/test_docs.py", "tools/spec_references.py")
TEXT = re.compile(r"\.(py|pyi|md|hpp|cpp|h|txt|toml|cfg|cmake|sh|ya?ml|json|in)$")


@cache
def text_files() -> tuple[Path, ...]:
    """The repository's tracked text files (untracked ones too when git is not there)."""
    try:
        listed = subprocess.run(
            ["git", "ls-files", "--cached", "--others", "--exclude-standard"],
            cwd=REPO,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split("\n")
        paths = [REPO / name for name in listed if name]
    except (OSError, subprocess.CalledProcessError):
        paths = [p for p in REPO.rglob("*") if "build" not in p.parts and ".git" not in p.parts]
    return tuple(
        p
        for p in sorted(paths)
        if p.is_file() and (TEXT.search(p.name) or p.name in ("CMakeLists.txt", "run"))
    )


def read(path: Path) -> str:
    return path.read_text(encoding="utf-8", errors="replace")


def relative(path: Path) -> str:
    return path.relative_to(REPO).as_posix()


@cache
def headings(page: Path) -> tuple[str, ...]:
    found, fenced = [], False
    for line in read(page).splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
        elif not fenced and re.match(r"#{1,6} ", line):
            found.append(line.lstrip("#").strip())
    return tuple(found)


@cache
def titles(page: Path) -> tuple[str, ...]:
    """Headings and the bold titles that open paragraphs (``**Units.** The fit ...``)."""
    bold = re.findall(r"^\*\*([^*\n]+?)\.?\*\*", read(page), flags=re.MULTILINE)
    return headings(page) + tuple(bold)


def github_anchor(heading: str) -> str:
    text = heading.strip().lower()
    kept = "".join(c for c in text if c.isalnum() or c in "-_ ")
    return kept.replace(" ", "-")


@cache
def anchors(page: Path) -> frozenset[str]:
    seen: dict[str, int] = {}
    result = set()
    for heading in headings(page):
        base = github_anchor(heading)
        count = seen.get(base, 0)
        seen[base] = count + 1
        result.add(base if count == 0 else f"{base}-{count}")
    return frozenset(result)


def test_the_anchor_rule_on_headings_of_these_docs():
    # Anchors taken from links that the docs had before this test (docs/uses.md, docs/building.md)
    assert github_anchor("Linearization (notes p. 44–47)") == "linearization-notes-p-4447"
    assert (
        github_anchor(
            "Collision residual: the generalized-momentum observer (De Luca & Mattone 2005)"
        )
        == "collision-residual-the-generalized-momentum-observer-de-luca--mattone-2005"
    )
    assert (
        github_anchor("C++ tests and sanitizers: `tests/cpp`") == "c-tests-and-sanitizers-testscpp"
    )
    assert github_anchor("`result.json`") == "resultjson"


def test_no_file_cites_the_missing_specification_or_files_outside_the_repository():
    citation = re.compile(r"\b" + WORD + r"\b")
    outside = re.compile(r"\.\./shared/|/work/" + "shared")
    found = []
    for path in text_files():
        name = relative(path)
        if name in QUOTING:
            continue
        for number, line in enumerate(read(path).splitlines(), 1):
            if citation.search(line) or outside.search(line):
                found.append(f"{name}:{number}: {line.strip()}")
    assert not found, "cites a document that is not in the repository:\n" + "\n".join(found)


# docs/<page>.md, optionally #anchor or , "Heading start" (the quote may follow a line break and a
# comment leader, as rewrapped comments have it).
CITED = re.compile(
    r"\bdocs/(?P<page>[\w-]+)\.md"
    r"(?:#(?P<anchor>[\w-]+)"
    r"|,\s*(?:(?://+|#:?|\*)\s*)?(?P<quote>[\"'])(?P<title>[^\"'\n]+)(?P=quote))?"
)


def test_every_cited_docs_page_and_heading_exists():
    problems = []
    for path in text_files():
        if relative(path) in QUOTING:
            continue
        text = read(path)
        for match in CITED.finditer(text):
            where = f"{relative(path)}:{text.count(chr(10), 0, match.start()) + 1}"
            page = REPO / "docs" / f"{match.group('page')}.md"
            if not page.is_file():
                problems.append(f"{where}: no page {relative(page)}")
            elif match.group("anchor") and match.group("anchor") not in anchors(page):
                problems.append(f"{where}: no heading #{match.group('anchor')} in {page.name}")
            elif match.group("title") and not any(
                h.lower().startswith(match.group("title").lower()) for h in titles(page)
            ):
                problems.append(f"{where}: no heading starting {match.group('title')!r}")
    assert not problems, "\n".join(problems)


LINK = re.compile(r"\]\((?P<target>[^)\s]+)\)")


def test_every_relative_markdown_link_resolves():
    problems = []
    for path in text_files():
        if path.suffix != ".md":
            continue
        text = read(path)
        # code blocks and inline code hold no links
        prose = re.sub(r"```.*?```|`[^`\n]*`", "", text, flags=re.DOTALL)
        for match in LINK.finditer(prose):
            target = match.group("target")
            if re.match(r"[a-z]+:", target):  # https:, mailto:
                continue
            file_part, _, fragment = target.partition("#")
            linked = (path.parent / file_part).resolve() if file_part else path
            where = f"{relative(path)}: ({target})"
            if not linked.exists():
                problems.append(f"{where}: no such file")
            elif fragment and linked.suffix == ".md" and fragment not in anchors(linked):
                problems.append(f"{where}: no such heading")
    assert not problems, "\n".join(problems)


# ---- tools/spec_references.py --------------------------------------------------------------


@pytest.fixture(scope="module")
def tool():
    path = REPO / "tools" / "spec_references.py"
    spec = importlib.util.spec_from_file_location("spec_references", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        del sys.modules[spec.name]


def test_every_section_maps_to_an_existing_page_and_heading(tool):
    for number, section in tool.SECTIONS.items():
        targets = [(section.page, section.heading)] + [(p, h) for _, p, h in section.rules]
        for page, heading in targets:
            assert (REPO / page).is_file(), (number, page)
            if heading:
                assert any(h.lower().startswith(heading.lower()) for h in headings(REPO / page)), (
                    number,
                    page,
                    heading,
                )


# (file the text is in, text, expected rewrite); written by hand from the docs' headings.
EXAMPLES = [
    (
        "python/dynid/a.py",
        f"# Steiner ({WORD} §2): about the frame origin\n",
        '# Steiner (docs/conventions.md, "Inertial parameters"): about the frame origin\n',
    ),
    (
        "python/dynid/a.py",
        f'"""Checks ({WORD} 2: a ValueError naming the argument)."""\n',
        '"""Checks (docs/conventions.md, "Bad input": a ValueError naming the argument)."""\n',
    ),
    (
        "cpp/src/a.cpp",
        f"// the exact sign(qd) of {WORD} section 2.\n",
        '// the exact sign(qd) of docs/conventions.md, "Drive terms and the torque model".\n',
    ),
    (
        "python/dynid/a.py",
        f"# URDF in and out ({WORD} 6; docs/urdf.md)\n",
        "# URDF in and out (docs/urdf.md)\n",
    ),
    (
        "tests/test_a.py",
        f'"""The observer ({WORD} §8; De Luca & Mattone 2005)."""\n',
        '"""The observer (docs/uses.md, "Collision residual"; De Luca & Mattone 2005)."""\n',
    ),
    (
        "cpp/a.hpp",
        f"// elastic joints ({WORD} section 8, last bullet)\n",
        "// elastic joints (docs/elastic.md)\n",
    ),
    (
        "cpp/a.hpp",
        f"// columns in {WORD} order\n",
        "// columns in standard order (docs/conventions.md)\n",
    ),
    ("tests/a.py", f"# {WORD} §2's tau\n", "# docs/conventions.md's tau\n"),
    (
        "docs/a.md",
        f"the torque of {WORD} §2, with friction\n",
        "the torque of [conventions.md](conventions.md#drive-terms-and-the-torque-model), with "
        "friction\n",
    ),
    (
        "CHANGELOG.md",
        f"- C++ safety ({WORD} 9): every public algorithm checks all argument sizes\n",
        "- C++ safety ([docs/cpp.md](docs/cpp.md#argument-checks)): every public algorithm checks "
        "all argument sizes\n",
    ),
    # a citation split over two comment lines
    (
        "cpp/a.hpp",
        f"// the size checks every algorithm runs first ({WORD}\n// section 9), like Pinocchio's\n",
        '// the size checks every algorithm runs first (docs/cpp.md, "Argument checks"), like '
        "Pinocchio's\n",
    ),
]


@pytest.mark.parametrize(("name", "text", "expected"), EXAMPLES)
def test_the_tool_rewrites_citations_as_written_by_hand(tool, name, text, expected):
    rewritten, changes, left = tool.rewrite(text, Path(name))
    assert rewritten == expected
    assert len(changes) == 1 and not left
    again, changes, left = tool.rewrite(rewritten, Path(name))
    assert again == rewritten and not changes and not left


def test_the_tool_rewraps_a_comment_it_made_too_long(tool):
    text = "# " + "word " * 18 + f"({WORD} section 2: a ValueError) and more\n# words here.\n"
    rewritten, _, left = tool.rewrite(text, Path("python/dynid/a.py"))
    assert not left
    assert all(len(line) <= 100 for line in rewritten.splitlines())
    assert " ".join(rewritten.replace("# ", " ").split()) == " ".join(
        (
            "word " * 18 + '(docs/conventions.md, "Bad input": a ValueError) and more words here.'
        ).split()
    )


def test_the_tool_reports_what_it_cannot_map(tool):
    text = f"The {WORD} says so.\n"
    rewritten, changes, left = tool.rewrite(text, Path("python/dynid/a.py"))
    assert rewritten == text and not changes
    assert [line for line, _ in left] == [1]
