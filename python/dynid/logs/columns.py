"""Reading foreign logs: which columns (CSV) or keys (NPZ) hold t, q, qd, qdd and tau, and the
unit of the time stamps.

A mapping names, per signal, a column/key or a glob pattern over them; a pattern's matches are
ordered by the numbers in their names (``pos_2`` before ``pos_10``), one per joint::

    load_log("ros.csv", columns={"t": "stamp", "q": "pos_*", "tau": "effort_*"}, time_unit="ns")
    dynid identify ros.csv --columns "t=stamp,q=pos_*,tau=effort_*" --time-unit ns
"""

from __future__ import annotations

import fnmatch
import re
from collections.abc import Mapping, Sequence

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


def matching(pattern: str, names: Sequence[str], signal: str) -> list[str]:
    """The names matching ``pattern`` in natural order; a ValueError naming the signal if none."""
    found = [name for name in names if fnmatch.fnmatchcase(name, pattern)]
    if not found:
        raise ValueError(
            f"columns: nothing matches {pattern!r} for {signal}; found {', '.join(names)}"
        )
    return sorted(found, key=_natural_key)


def _natural_key(name: str) -> list[object]:
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", name)]
