"""The warnings of a command's run, for its report (``report.html``), shown as before."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def recorded_warnings() -> Iterator[list[str]]:
    """Yield a list that collects, as "Category: message", every warning shown in the block;
    each is still shown by the handler in place (``dynid``'s one line on stderr, cli/main.py),
    and the filters are left as they are: which warnings are shown does not change."""
    with warnings.catch_warnings():  # restores the handler on leaving
        shown = warnings.showwarning
        seen: list[str] = []

        def show(message: Any, category: Any, *args: Any, **kwargs: Any) -> None:
            seen.append(f"{getattr(category, '__name__', 'Warning')}: {message}")
            shown(message, category, *args, **kwargs)

        warnings.showwarning = show
        yield seen
