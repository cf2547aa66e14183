"""The HTML pieces of ``report.html`` (:mod:`dynid.export.report`): every text through
``html.escape``, every number printed to a stated precision with its exact value beside it.

A number cell is ``<td class="num" data-value="REPR">PRINTED</td>``: ``PRINTED`` is for people
(``digits`` significant digits), ``data-value`` is ``repr`` of the float (exact, for a program
reading the page); a missing, infinite or NaN value is a dash with ``data-value="null"``, as
result.json writes it (null).
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

#: Printed for a number that is absent, infinite or NaN (result.json's null).
DASH = "–"


def text(value: Any) -> str:
    """``value`` as HTML text (escaped, quotes included)."""
    return html.escape(str(value), quote=True)


def number(value: Any, digits: int = 6) -> str:
    """``value`` with ``digits`` significant digits (``%g``), or a dash when it is not a finite
    number."""
    finite = _finite(value)
    return DASH if finite is None else f"{finite:.{digits}g}"


@dataclass(frozen=True)
class Num:
    """A number cell of :func:`table`: printed with ``digits`` significant digits and a
    ``suffix`` (e.g. " %"), its exact value in ``data-value``."""

    value: Any
    digits: int = 6
    suffix: str = ""

    def html(self, tag: str = "td") -> str:
        """The element ``tag`` (a table cell, or e.g. "dd") holding the number."""
        finite = _finite(self.value)
        exact = "null" if finite is None else repr(finite)
        shown = number(finite, self.digits) + (self.suffix if finite is not None else "")
        return f'<{tag} class="num" data-value="{exact}">{text(shown)}</{tag}>'


def table(
    headers: Sequence[str], rows: Iterable[Sequence[Any]], table_id: str, caption: str = ""
) -> str:
    """A table with ``id`` ``table_id``: a header row, then one ``<tr>`` per row; cells are
    :class:`Num` or anything else as escaped text."""
    head = "".join(f"<th>{text(h)}</th>" for h in headers)
    body = "\n".join(
        "<tr>"
        + "".join(
            cell.html() if isinstance(cell, Num) else f"<td>{text(cell)}</td>" for cell in row
        )
        + "</tr>"
        for row in rows
    )
    title = f"<caption>{text(caption)}</caption>" if caption else ""
    return (
        f'<table id="{text(table_id)}">{title}<thead><tr>{head}</tr></thead>'
        f"<tbody>\n{body}\n</tbody></table>"
    )


def facts(items: Iterable[tuple[str, Any]], list_id: str) -> str:
    """A definition list (``<dl>``) of (label, value) pairs; a value that is a :class:`Num` is
    printed as one, with its exact value in ``data-value``."""
    lines = []
    for label, value in items:
        shown = value.html("dd") if isinstance(value, Num) else f"<dd>{text(value)}</dd>"
        lines.append(f"<dt>{text(label)}</dt>{shown}")
    return f'<dl id="{text(list_id)}">' + "\n".join(lines) + "</dl>"


def bullet_list(items: Iterable[str], list_id: str, empty: str = "none") -> str:
    """An unordered list of texts (``empty`` as its one item when there are none)."""
    entries = [text(item) for item in items] or [f"<em>{text(empty)}</em>"]
    return f'<ul id="{text(list_id)}">' + "".join(f"<li>{e}</li>" for e in entries) + "</ul>"


def figure(svg: str, figure_id: str, caption: str) -> str:
    """An inline SVG with a caption (the SVG is matplotlib's, its texts escaped by it)."""
    return f'<figure id="{text(figure_id)}">{svg}<figcaption>{text(caption)}</figcaption></figure>'


@dataclass(frozen=True)
class Section:
    """One section of the page: ``key`` is its HTML id (and the link to it), ``body`` HTML whose
    texts are escaped already (the functions here)."""

    key: str
    title: str
    body: str


def _finite(value: Any) -> float | None:
    if value is None or isinstance(value, bool):
        return None
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None
