"""Short quotes of file contents for error messages.

A recording can have hundreds of columns and lines of kilobytes (a UR RTDE file: 80+ names on
one line); an error that quotes them whole buries the one fact it is about. These shorten what
they quote to a bounded length and say how much was left out.
"""

from __future__ import annotations

from collections.abc import Sequence

#: Characters of a quoted field or line kept in a message.
QUOTE_LIMIT = 60
#: Names listed in full; longer lists show their first and last ones.
NAMES_LIMIT = 12


def quote(text: str, limit: int = QUOTE_LIMIT) -> str:
    """``repr(text)``, or its first and last characters with the count of those left out."""
    if len(text) <= limit:
        return repr(text)
    keep = limit // 2
    return f"{text[:keep]!r} ... {text[-keep:]!r} ({len(text)} characters)"


def name_list(names: Sequence[str], limit: int = NAMES_LIMIT) -> str:
    """The names separated by commas; past ``limit`` the first and the last few, and the count."""
    if len(names) <= limit:
        return ", ".join(names)
    head, tail = names[: limit - 3], names[-2:]
    return f"{', '.join(head)}, ..., {', '.join(tail)} ({len(names)} in all)"
