"""Reading foreign logs: which columns (CSV) or keys (NPZ) hold t, q, qd, qdd and tau, and the
unit of the time stamps.

A mapping names, per signal, a column/key or a pattern over them; a pattern's matches are
ordered by the numbers in their names (``pos_2`` before ``pos_10``), one per joint::

    load_log("ros.csv", columns={"t": "stamp", "q": "pos_*", "tau": "effort_*"}, time_unit="ns")
    dynid identify ros.csv --columns "t=stamp,q=pos_*,tau=effort_*" --time-unit ns

In a pattern ``*`` stands for any characters and ``?`` for one; everything else, brackets
included, is literal, so that libfranka's ``state.q[*]`` means what it says (fnmatch would read
``[...]`` as a character class). A file without a header is mapped by 0-based column index:
``t=0,q=1:8,tau=15:22``, ranges half-open as Python's slices.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

from .messages import name_list

#: Signals a mapping may name.
MAPPABLE = ("t", "q", "qd", "qdd", "tau")

#: Seconds per unit of the time stamps.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}


def parse_columns(text: str) -> dict[str, str]:
    """``"q=pos_*,tau=effort_*"`` as a mapping (the CLI's ``--columns``)."""
    if not isinstance(text, str) or not text.strip():
        raise ValueError(f"columns: expected SIGNAL=PATTERN[,SIGNAL=PATTERN...], got {text!r}")
    mapping: dict[str, str] = {}
    for item in text.split(","):
        signal, sep, pattern = item.partition("=")
        if not sep or not pattern.strip():
            raise ValueError(f"columns: expected SIGNAL=PATTERN, got {item!r} in {text!r}")
        mapping[signal.strip()] = pattern.strip()
    return check_columns(mapping)


def check_columns(columns: Mapping[str, str]) -> dict[str, str]:
    """The mapping checked: known signals, non-empty string patterns."""
    if not isinstance(columns, Mapping):
        raise ValueError(f"columns: expected a mapping signal -> column pattern, got {columns!r}")
    checked: dict[str, str] = {}
    for signal, pattern in columns.items():
        if signal not in MAPPABLE:
            raise ValueError(f"columns: unknown signal {signal!r}; expected one of {MAPPABLE}")
        if not isinstance(pattern, str) or not pattern:
            raise ValueError(
                f"columns: the pattern for {signal!r} must be a non-empty string, got {pattern!r}"
            )
        checked[signal] = pattern
    return checked


def time_scale(unit: str) -> float:
    """Seconds per unit (``time_unit`` of :func:`dynid.load_log`)."""
    if not isinstance(unit, str) or unit not in TIME_UNITS:
        raise ValueError(f"time_unit: expected one of {tuple(TIME_UNITS)}, got {unit!r}")
    return TIME_UNITS[unit]


#: A column index ``7`` or a half-open range ``1:8`` (files without a header).
INDEX_PATTERN = re.compile(r"^(\d+)(?::(\d+))?$")


def pattern_regex(pattern: str) -> re.Pattern[str]:
    """``pattern`` as a regular expression: ``*`` any characters, ``?`` one, the rest literal."""
    parts = [".*" if c == "*" else "." if c == "?" else re.escape(c) for c in pattern]
    return re.compile("".join(parts) + r"\Z", re.DOTALL)


def index_names(pattern: str, width: int, signal: str) -> list[str]:
    """The columns (as the strings "0", "1", ...) that an index pattern ``7`` or ``1:8`` names in
    a table of ``width`` columns without a header."""
    match = INDEX_PATTERN.match(pattern.strip())
    if match is None:
        raise ValueError(
            f"columns: the file has no header, so {signal} needs a 0-based column index or a "
            f"range like 1:8, got {pattern!r}"
        )
    start = int(match.group(1))
    stop = start + 1 if match.group(2) is None else int(match.group(2))
    if not start < stop <= width:
        raise ValueError(
            f"columns: {pattern!r} for {signal} is outside the file's {width} columns "
            f"(0 to {width - 1}; ranges are half-open, start:stop)"
        )
    return [str(c) for c in range(start, stop)]


def matching(pattern: str | re.Pattern[str], names: Sequence[str], signal: str) -> list[str]:
    """The names matching ``pattern`` (a pattern as in this module's docstring, or a compiled
    regular expression) in natural order; a ValueError naming the signal if none."""
    regex = pattern if isinstance(pattern, re.Pattern) else pattern_regex(pattern)
    found = [name for name in names if regex.match(name)]
    if not found:
        pattern = readable(pattern) if isinstance(pattern, re.Pattern) else pattern
        raise ValueError(
            f"columns: nothing matches {pattern!r} for {signal}; found {name_list(names)}"
        )
    return sorted(found, key=_natural_key)


def readable(regex: re.Pattern[str]) -> str:
    """A format's column expression as a name for messages: ``state\\.q\\[\\d+\\]\\Z`` ->
    ``state.q[N]``."""
    text = regex.pattern.replace(r"\d+", "N").replace(r"\Z", "")
    return re.sub(r"\\(.)", r"\1", text)


def _natural_key(name: str) -> list[object]:
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", name)]
