"""Rewrite references to the old product specification as references to dynid's own docs.

Early code cited a specification that never lived in this repository ("SPEC §2", "SPEC
section 8", "SPEC 6", "SPEC order", ...). Its contracts are now in docs/ (issue 19, item 6); this
script maps each citation to the docs page and heading that hold the contract and rewrites it in
place.

    python tools/spec_references.py PATH...            # list what would change, change nothing
    python tools/spec_references.py --write PATH...    # rewrite the files

PATH is a file or a folder (searched recursively for text files). The exit status is 1 when a
citation is left that the script cannot map (listed on stderr, with the reason), else 0. Running
it twice changes nothing the second time: the replacements hold no citation.

How a citation is mapped: the section number picks a page (``SECTIONS``); keywords on the
citation's line and the line before pick a heading of that page when exactly one heading's
keywords match (several or none: the page as a whole). Markdown files get a relative Markdown
link (``[uses.md](uses.md#analytic-rnea-derivatives)``), other files the path and the start of
the heading, the form the code already used (``docs/uses.md, "Analytic RNEA derivatives"``).
Lines that the rewrite makes longer than the formatters' 100 characters are listed for
rewrapping by hand.
"""

from __future__ import annotations

import argparse
import io
import os
import re
import sys
import tokenize
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: Files the script reads; everything else (data, images, build output) is skipped.
TEXT_SUFFIXES = {".py", ".pyi", ".md", ".hpp", ".cpp", ".h", ".txt", ".toml", ".cfg", ".cmake"}
TEXT_SUFFIXES |= {".sh", ".yaml", ".yml", ".json", ".in"}
TEXT_NAMES = {"CMakeLists.txt", "run"}
SKIPPED_FOLDERS = {".git", "build", "__pycache__", ".mypy_cache", ".ruff_cache", ".pytest_cache"}
#: This file states the patterns; tests/test_docs.py builds them from pieces instead.
SELF = Path(__file__).resolve()

# The word itself, split so that a search of the repository for it finds no false hit here.
WORD = "SP" + "EC"


@dataclass(frozen=True)
class Section:
    """One section of the old specification: the docs page that now holds its contract, the
    heading for a citation that no keyword narrows down (``""``: the page), and keyword rules
    (regular expression, page, heading) tried on the citation's context. A heading is named by
    its start, e.g. "Collision residual" for "Collision residual: the generalized-momentum
    observer (De Luca & Mattone 2005)"."""

    page: str
    heading: str = ""
    rules: tuple[tuple[str, str, str], ...] = ()


CONVENTIONS = "docs/conventions.md"
USES = "docs/uses.md"
CPP = "docs/cpp.md"
BASE = "docs/base_parameters.md"

SECTIONS: dict[int, Section] = {
    # 1. Layout
    1: Section("docs/architecture.md", "The layers"),
    # 2. Conventions: frames, parameters, torque model, shapes, bad input
    2: Section(
        CONVENTIONS,
        rules=(
            (
                r"ValueError|bad input|wrong type|naming the argument|names the argument|"
                r"what was expected|rotor=\"no\"|crash",
                CONVENTIONS,
                "Bad input",
            ),
            (r"\bshapes?\b|one sample|\(T, n\)", CONVENTIONS, "Shapes"),
            (
                r"\bDH\b|Rz\(|Rx\(|\{a, alpha|homogeneous transform|convention|\"modified\"",
                CONVENTIONS,
                "DH tables",
            ),
            (
                r"inertial|Steiner|\[m, mx|frame origin|frame's origin|origin of (DH )?frame|"
                r"standard parameters|I_O|\borigin\b|parameter vector|regressor's columns|"
                r"\border\b",
                CONVENTIONS,
                "Inertial parameters",
            ),
            (
                r"sign\(|drive terms|friction|torque|\btau\b|\bIa\b",
                CONVENTIONS,
                "Drive terms and the torque model",
            ),
        ),
    ),
    # 3. Python API, base parameters, models, identification in Python
    3: Section(
        "docs/api.md",
        rules=(
            (
                r"structural|counts?\b|base.parameter|vertical plane|parameter values",
                BASE,
                "Base parameters",
            ),
            (r"finite values", CONVENTIONS, "Inertial parameters"),
            (r"d1 = 0\.4|d2 = 0\.39|Table I\b", "docs/models.md", ""),
        ),
    ),
    # 4. Command line
    4: Section("docs/cli.md"),
    # 5. Real-time C++ use
    5: Section(CPP),
    # 6. URDF in and out
    6: Section("docs/urdf.md"),
    # 7. Physically consistent identification
    7: Section("docs/identification.md", "Physically consistent identification"),
    # 8. Uses of the model (its last bullet: elastic joints)
    8: Section(
        USES,
        rules=(
            (r"uses of", USES, ""),
            (r"rnea_derivatives|RNEA derivatives|dtau_dq", USES, "Analytic RNEA derivatives"),
            (r"lineari[sz]", USES, "Linearization"),
            (
                r"jacobian_dot|Jacobian's|cartesian|operational",
                USES,
                "Cartesian (operational-space) dynamics",
            ),
            (
                r"observer|residual|De Luca|collision",
                USES,
                "Collision residual",
            ),
            (
                r"[Ss]imulat",
                USES,
                "Closed-loop simulation",
            ),
            (r"[Ee]lastic", "docs/elastic.md", ""),
        ),
    ),
    # 9. The C++ contract: argument checks, what is API
    9: Section(
        CPP,
        "Argument checks",
        rules=(
            (r"public header|headers under", CPP, "What is API"),
            (r"argument sizes|size checks", CPP, "Argument checks"),
            (r"ValueError|naming the argument", CONVENTIONS, "Bad input"),
        ),
    ),
}

# A citation: the word, then a section number (with "§" or "section", possibly after a line
# break inside a comment), or one of the forms that name no number.
CITATION = re.compile(
    r"\b"
    + WORD
    + r"""
    (?:
        (?P<gap>[ \t]*(?:\n[ \t]*(?://+|\#+|\*)?[ \t]*)?)
        (?:§[ \t]*|section[ \t]+)?(?P<number>[1-9])\b
        (?P<bullet>,[ \t]*last[ \t]+bullet)?
      | (?P<order>[ \t]+order)\b
      | (?P<dh_row>[ \t]+DH[ \t]+row)\b
      | (?P<colon>):
    )""",
    re.VERBOSE,
)
ANY = re.compile(r"\b" + WORD + r"\b")
# A second reference to a docs page right after the citation, e.g. "(SPEC 6; docs/urdf.md)".
FOLLOWING = re.compile(
    r"[;,][ \t]*(?P<ref>docs/[\w-]+\.md(?:#[\w-]+|(?P<title>, \"[^\"\n]+\"))?"
    r"|\[[^\]\n]*\]\([^)\n]*\))"
)
#: The line length of ruff (pyproject.toml) and clang-format (.clang-format).
LINE_LIMIT = 100
LIMITED_SUFFIXES = {".py", ".pyi", ".hpp", ".cpp", ".h"}


@dataclass(frozen=True)
class Target:
    page: str  # relative to the repository root
    heading: str  # the start of one of its headings; "" for the page as a whole


def headings(page: Path) -> list[str]:
    """The Markdown headings of ``page`` (outside code blocks), in order."""
    found: list[str] = []
    fenced = False
    for line in page.read_text(encoding="utf-8").splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
        elif not fenced and re.match(r"#{1,6} ", line):
            found.append(line.lstrip("#").strip())
    return found


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchor(target: Target) -> str:
    """The anchor of the first heading of the target's page that starts with its heading."""
    if not target.heading:
        return ""
    for heading in headings(ROOT / target.page):
        if heading.lower().startswith(target.heading.lower()):
            return slug(heading)
    raise LookupError(f"{target.page}: no heading starts with {target.heading!r}")


def _contexts(text: str, start: int, end: int) -> tuple[str, str]:
    """Where a citation's subject is named: its own line(s); failing that, with the lines
    before and after."""
    line_start = text.rfind("\n", 0, start) + 1
    line_end = text.find("\n", end)
    line_end = len(text) if line_end < 0 else line_end
    before = text.rfind("\n", 0, line_start - 1) + 1 if line_start > 1 else 0
    after = text.find("\n", line_end + 1)
    after = len(text) if after < 0 else after
    return text[line_start:line_end], text[before:after]


def _narrow(section: Section, contexts: tuple[str, str]) -> Target:
    for context in contexts:
        hits = {
            (page, head) for pattern, page, head in section.rules if re.search(pattern, context)
        }
        if len(hits) == 1:
            page, head = hits.pop()
            return Target(page, head)
        if len(hits) > 1:
            pages = {page for page, _ in hits}
            return Target(pages.pop() if len(pages) == 1 else section.page, "")
    return Target(section.page, section.heading)


def target_of(match: re.Match[str], text: str) -> Target | None:
    """The docs page and heading a citation stands for, or None when it cannot be told."""
    contexts = _contexts(text, match.start(), match.end())
    if match.group("order") or match.group("dh_row"):
        return Target(CONVENTIONS, "")  # "standard order (docs/conventions.md)"
    if match.group("colon") is not None:
        # No number: only a subject that the conventions' keywords recognise.
        target = _narrow(SECTIONS[2], contexts)
        return target if target.heading else None
    number = int(match.group("number"))
    if match.group("bullet"):
        return Target("docs/elastic.md", "")
    section = SECTIONS[number]
    if text[match.end() : match.end() + 2] in (' "', "'s"):
        # quoted headings follow, or a possessive that a quoted heading would make unreadable
        return Target(section.page, "")
    return _narrow(section, contexts)


def _quote(text: str, offset: int, path: Path) -> str:
    """The quote for a heading's name at ``offset``: double, or single inside a one-line Python
    string delimited by double quotes."""
    if path.suffix not in (".py", ".pyi"):
        return '"'
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (tokenize.TokenError, SyntaxError):
        return '"'
    line = text.count("\n", 0, offset) + 1
    column = offset - (text.rfind("\n", 0, offset) + 1)
    for token in tokens:
        if token.type == tokenize.STRING and token.start <= (line, column) < token.end:
            body = token.string.lstrip("rRbBuUfF")
            if body.startswith('"') and not body.startswith('"""'):
                return "'"
    return '"'


def _link(target: Target, path: Path, text: str, offset: int) -> str:
    """The citation's replacement as written in ``path``: a relative Markdown link in Markdown,
    ``docs/<page>.md, "<heading>"`` elsewhere."""
    if path.suffix != ".md":
        if not target.heading:
            return target.page
        quote = _quote(text, offset, path)
        return f"{target.page}, {quote}{target.heading}{quote}"
    fragment = f"#{anchor(target)}" if target.heading else ""
    if (ROOT / target.page).resolve() == (ROOT / path).resolve():
        return f"[this page]({fragment})" if fragment else "this page"
    page = Path(os.path.relpath(ROOT / target.page, (ROOT / path).parent)).as_posix()
    return f"[{page}]({page}{fragment})"


def _replacement(match: re.Match[str], target: Target, path: Path, text: str) -> str:
    link = _link(target, path, text, match.start())
    if match.group("order"):
        return f"standard order ({link})"
    if match.group("dh_row"):
        return f"DH row ({link})"
    if match.group("colon") is not None:
        return link + ":"
    return link


def _page_of(reference: str) -> str:
    inner = re.search(r"\(([^)#]*)", reference) if reference.startswith("[") else None
    return Path((inner.group(1) if inner else reference).split("#")[0].split(",")[0]).name


def rewrite(text: str, path: Path) -> tuple[str, list[tuple[int, str, str]], list[tuple[int, str]]]:
    """``text`` with every citation it can map rewritten; the changes (line, old, new) and what
    is left to do by hand (line, reason): citations it cannot map, lines made too long."""
    out: list[str] = []
    changes: list[tuple[int, str, str]] = []
    position = 0
    for match in CITATION.finditer(text):
        target = target_of(match, text)
        if target is None:
            continue
        new = _replacement(match, target, path, text)
        end = match.end()
        following = FOLLOWING.match(text, end)
        if following and _page_of(following.group("ref")) == Path(target.page).name:
            if not target.heading and ("#" in following.group("ref") or following.group("title")):
                new = ""  # the page reference that follows is the more precise one
                end = following.start("ref")
            else:
                end = following.end()
        out.append(text[position : match.start()])
        out.append(new)
        line = text.count("\n", 0, match.start()) + 1
        changes.append((line, text[match.start() : end], new))
        position = end
    out.append(text[position:])
    result = "".join(out)
    left = [
        (result.count("\n", 0, m.start()) + 1, _reason(result, m)) for m in ANY.finditer(result)
    ]
    if path.suffix in LIMITED_SUFFIXES and changes:
        result, too_long = rewrap(result, path, {line for line, _, _ in changes})
        left += [(n, f"longer than {LINE_LIMIT} characters: rewrap it by hand") for n in too_long]
    return result, changes, left


# Prefixes of comment lines that may be rewrapped: C++ and Python comments.
_COMMENT = re.compile(r"^(\s*(?://+|#:?)\s?)(?=\S)")
# Lines that start something new and must not receive the words pushed down from above.
_NEW_ITEM = re.compile(r"^(?:[-*+] |\d+[.)] |[A-Za-z_][\w ,]*\n|\.\. |>>> |```|\"\"\"|$)")


def _docstring_lines(text: str) -> set[int]:
    """Numbers of the lines inside a triple-quoted Python string (including its first line)."""
    lines: set[int] = set()
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (tokenize.TokenError, SyntaxError):
        return lines
    for token in tokens:
        body = token.string.lstrip("rRbBuUfF")
        if token.type == tokenize.STRING and body[:3] in ('"""', "'''"):
            lines.update(range(token.start[0], token.end[0] + 1))
    return lines


def _prefix(line: str, in_docstring: bool) -> str | None:
    comment = _COMMENT.match(line)
    if comment:
        return comment.group(1)
    if in_docstring:
        indent = re.match(r"\s*", line)
        return indent.group(0) if indent else ""
    return None


def _cut(line: str, start: int) -> int:
    """The last space within LINE_LIMIT after ``start`` that is not inside double quotes (a
    heading's name stays on one line, where a search finds it) nor inside ``literal``; or
    failing that any space within LINE_LIMIT; or -1."""
    cut = line.rfind(" ", start + 1, LINE_LIMIT + 1)
    first = cut
    quotes = line.replace('"""', "").count('"') % 2 == 0  # else one opens on another line
    while cut > 0 and (
        (quotes and line[:cut].replace('"""', "").count('"') % 2) or line[:cut].count("``") % 2
    ):
        cut = line.rfind(" ", start + 1, cut)
    return cut if cut > 0 else first


def rewrap(text: str, path: Path, changed: set[int]) -> tuple[str, list[int]]:
    """Push the words beyond LINE_LIMIT of each changed comment or docstring line down into the
    next line of the same paragraph (or a new line), line after line until everything fits.
    Returns the text and the numbers of long lines that are not comments or docstrings."""
    lines = text.split("\n")
    docstrings = _docstring_lines(text) if path.suffix in (".py", ".pyi") else set()
    too_long: list[int] = []
    todo = sorted(n for n in changed if 1 <= n <= len(lines))
    i = 0
    while i < len(todo):
        number = todo[i]
        i += 1
        line = lines[number - 1]
        if len(line) <= LINE_LIMIT:
            continue
        rule = re.search(r" -{4,}$", line)  # a "# ---- title ----" rule: shorten its dashes
        if rule and rule.start() + 5 <= LINE_LIMIT:
            lines[number - 1] = line[: rule.start() + 1] + "-" * (LINE_LIMIT - rule.start() - 1)
            continue
        prefix = _prefix(line, number in docstrings)
        cut = _cut(line, len(prefix or ""))
        if prefix is None or cut < 0:
            too_long.append(number)
            continue
        head, tail = line[:cut].rstrip(), line[cut + 1 :].lstrip()
        following = lines[number] if number < len(lines) else None
        next_prefix = (
            _prefix(following, number + 1 in docstrings) if following is not None else None
        )
        if number in docstrings and next_prefix is not None and len(next_prefix) > len(prefix):
            prefix = next_prefix  # a docstring's list item continues at its deeper indent
        continues = (
            following is not None
            and next_prefix == prefix
            and not _NEW_ITEM.match(following[len(prefix) :])
        )
        lines[number - 1] = head
        if continues:
            lines[number] = prefix + tail + " " + following[len(prefix) :]
        else:
            lines.insert(number, prefix + tail)
            docstrings = {n + 1 if n > number else n for n in docstrings}
            if number in docstrings:
                docstrings.add(number + 1)
            todo = [n + 1 if n > number else n for n in todo]
        todo.insert(i, number + 1)
    return "\n".join(lines), too_long


def _reason(text: str, match: re.Match[str]) -> str:
    start = text.rfind("\n", 0, match.start()) + 1
    finish = text.find("\n", match.end())
    line = text[start : finish if finish >= 0 else len(text)].strip()
    return f"no section or subject to map: {line}"


def text_files(paths: list[Path]) -> list[Path]:
    files: list[Path] = []
    for path in paths:
        if path.is_file():
            files.append(path)
            continue
        for item in sorted(path.rglob("*")):
            if any(part in SKIPPED_FOLDERS for part in item.parts) or not item.is_file():
                continue
            if item.suffix in TEXT_SUFFIXES or item.name in TEXT_NAMES:
                files.append(item)
    return [f for f in files if f.resolve() != SELF]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("paths", nargs="+", type=Path, help="files or folders")
    parser.add_argument("--write", action="store_true", help="rewrite the files in place")
    args = parser.parse_args(argv)
    unmapped = 0
    for path in text_files(args.paths):
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        relative = path.resolve().relative_to(ROOT) if path.resolve().is_relative_to(ROOT) else path
        new, changes, left = rewrite(text, relative)
        for line, old, replacement in changes:
            old_text = old.replace("\n", "\\n")
            print(f"{relative}:{line}: {old_text!r} -> {replacement!r}")
        for line, reason in left:
            print(f"{relative}:{line}: NOT MAPPED, {reason}", file=sys.stderr)
        unmapped += len(left)
        if args.write and new != text:
            path.write_text(new, encoding="utf-8")
    return 1 if unmapped else 0


if __name__ == "__main__":
    sys.exit(main())
