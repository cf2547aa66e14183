"""Delimited text tables as robots' tools write them: comments, a header row or none, the
delimiter found from the lines themselves, text columns that are never converted.

A UR RTDE recording separates its fields by blanks, libfranka and pyfri by commas (libfranka's
older header by ", "), spreadsheets by ";" or tabs: the delimiter is the first of ",", ";", tab
and runs of blanks that splits the header and the first data lines into the same number (> 1)
of fields (``csv.Sniffer`` was tried and guesses wrong on all-numeric lines). Only the columns a
reader uses are converted to numbers, so a text column (a ROS export's ``name0 =
panda_joint1``) is ignored unless it is asked for.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..messages import quote

#: Delimiters tried in this order; None is a run of blanks (spaces or tabs).
DELIMITERS: tuple[str | None, ...] = (",", ";", "\t", None)
#: Lines (the header and the first data lines) that must agree on the delimiter.
SNIFF_LINES = 6


@dataclass
class Table:
    """The text of a table: ``names`` are the header's column names, or "0", "1", ... when the
    file has no header (``has_header`` False)."""

    names: list[str]
    has_header: bool
    rows: list[str]  #: the data lines, stripped
    lines: list[int]  #: the line number (1-based) of each data line
    delimiter: str | None
    header_line: int = 0
    notes: list[str] = field(default_factory=list)  #: "# note:" comments (dynid's own files)
    format: str | None = None  #: a "# format:" comment (dynid's own files)

    def column(self, name: str) -> int:
        return self.names.index(name)


def split(line: str, delimiter: str | None) -> list[str]:
    """The fields of one line, stripped (quoted fields as the csv module reads them)."""
    if delimiter is None:
        return line.split()
    return [f.strip() for f in next(csv.reader([line], delimiter=delimiter))]


def content_lines(text: str) -> list[str]:
    """The lines of ``text`` that are neither blank nor comments, stripped."""
    kept = (line.strip() for line in text.splitlines())
    return [line for line in kept if line and not line.startswith("#")]


def sniff(lines: list[str]) -> str | None:
    """The delimiter that splits every one of ``lines`` into the same number (> 1) of fields;
    "," when none does (the errors then name the line that disagrees)."""
    sample = lines[:SNIFF_LINES]
    for delimiter in DELIMITERS:
        counts = {len(split(line, delimiter)) for line in sample}
        if len(counts) == 1 and counts.pop() > 1:
            return delimiter
    return ","


def header_fields(head: str) -> list[str]:
    """The first line's fields of a file whose start is ``head`` (for ``recognises``)."""
    lines = content_lines(head)
    # The last line of the head may be cut: leave it out of the sniffing unless it is the only one.
    sample = lines[:-1] if len(lines) > 1 else lines
    return split(lines[0], sniff(sample)) if lines else []


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_table(path: Path) -> Table:
    """The table of ``path``: a first line of numbers is data (no header), anything else the
    header."""
    notes: list[str] = []
    stored_format: str | None = None
    rows: list[str] = []
    lines: list[int] = []
    with path.open(newline="", encoding="utf-8", errors="replace") as handle:
        for number, line in enumerate(handle, start=1):
            text = line.strip()
            if text.startswith("# note:"):
                notes.append(text[len("# note:") :].strip())
            elif text.startswith("# format:"):
                stored_format = text[len("# format:") :].strip()
            if not text or text.startswith("#"):
                continue
            rows.append(text)
            lines.append(number)
    if not rows:
        raise ValueError("no header row (expected columns t, q1..qn, tau1..taun)")
    delimiter = sniff(rows)
    first = split(rows[0], delimiter)
    if all(_is_number(f) for f in first):
        names = [str(c) for c in range(len(first))]
        return Table(names, False, rows, lines, delimiter, 0, notes, stored_format)
    return Table(first, True, rows[1:], lines[1:], delimiter, lines[0], notes, stored_format)


def numbers(table: Table, columns: list[int]) -> NDArray[np.float64]:
    """The given columns of every data row as numbers, (rows, len(columns)). A row with another
    number of fields than the header, or text in a used column, is an error naming its line."""
    width = len(table.names)
    if not table.rows:
        return np.empty((0, len(columns)))
    try:  # fast path (NumPy's C parser); on failure the loop below finds and names the bad line
        if table.delimiter is not None and '"' not in table.rows[0]:
            counts = {row.count(table.delimiter) for row in table.rows}
            uniform = counts == {width - 1}
        else:
            uniform = {len(row.split()) for row in table.rows} == {width}
        if uniform:
            values = np.loadtxt(
                table.rows, delimiter=table.delimiter, usecols=columns, ndmin=2, dtype=float
            )
            if values.shape == (len(table.rows), len(columns)):
                return values
    except ValueError:
        pass
    values = np.empty((len(table.rows), len(columns)))
    for r, row in enumerate(table.rows):
        fields = split(row, table.delimiter)
        if len(fields) != width:
            what = (
                f"the header (line {table.header_line}) has"
                if table.has_header
                else f"the first line ({table.lines[0]}) has"
            )
            raise ValueError(
                f"line {table.lines[r]}: {len(fields)} fields, but {what} {width} columns"
            )
        for k, c in enumerate(columns):
            try:
                values[r, k] = float(fields[c])
            except ValueError:
                raise ValueError(
                    f"line {table.lines[r]}, column {quote(table.names[c])}: "
                    f"cannot read {quote(fields[c])} as a number"
                ) from None
    return values
