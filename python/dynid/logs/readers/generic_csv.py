"""Any CSV: dynid's own layout (``t, q1..qn, tau1..taun[, qd.., qdd..]``, docs/data.md), or
any other table mapped with ``columns`` (by name or pattern; a file without a header by 0-based
column index). The delimiter is found from the lines; columns that are not used are never read
as numbers, so text columns are ignored."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from ..formats import LogFormat, ReadOptions
from ..log import Log
from ..messages import name_list
from ._build import finish, table_log
from ._table import Table, numbers, read_table

NAME = "CSV"
_COLUMN = re.compile(r"^(q|qd|qdd|tau)(\d+)$")


def read(path: Path, options: ReadOptions) -> Log:
    table = read_table(path)
    if options.columns or not table.has_header:
        return table_log(path, table, options, {}, fmt=NAME)
    return _dynid_layout(path, table, options)


def _dynid_layout(path: Path, table: Table, options: ReadOptions) -> Log:
    header = table.names
    duplicates = sorted({c for c in header if header.count(c) > 1})
    if duplicates:
        raise ValueError(f"duplicate columns in the header: {', '.join(duplicates)}")
    index = {name: c for c, name in enumerate(header)}
    if "t" not in index and options.sample_time is None:
        raise ValueError(
            f"missing column 't'; found columns: {name_list(header)} (a log without a time "
            "column needs its sample time: sample_time / --sample-time)"
        )
    groups: dict[str, dict[int, int]] = {"q": {}, "qd": {}, "qdd": {}, "tau": {}}
    for name, c in index.items():
        match = _COLUMN.match(name)
        if match:
            groups[match.group(1)][int(match.group(2))] = c
    if not groups["q"]:
        raise ValueError(f"missing columns q1..qn; found columns: {name_list(header)}")
    n = max(groups["q"])
    wanted = range(1, n + 1)
    columns: dict[str, list[int]] = {"t": [index["t"]]} if "t" in index else {}
    for name, found in groups.items():
        if not found:
            if name == "tau":
                raise ValueError(
                    f"missing columns tau1..tau{n}; found columns: {name_list(header)}"
                )
            continue
        missing = [f"{name}{j}" for j in wanted if j not in found]
        extra = [f"{name}{j}" for j in sorted(found) if j not in wanted]
        if missing or extra:
            problem = f"missing {', '.join(missing)}" if missing else f"extra {', '.join(extra)}"
            raise ValueError(
                f"inconsistent joint columns: expected {name}1..{name}{n} (n = {n} from column "
                f"q{n}), {problem}; found columns: {name_list(header)}"
            )
        columns[name] = [found[j] for j in wanted]
    used = [c for cols in columns.values() for c in cols]
    values = numbers(table, used)
    arrays: dict[str, Any] = {}
    start = 0
    for name, cols in columns.items():
        block = values[:, start : start + len(cols)]
        arrays[name] = block[:, 0] if name == "t" else block
        start += len(cols)
    ignored = [c for c in header if c != "t" and not _COLUMN.match(c)]
    note = f"loaded from {path.name} (CSV, {', '.join(arrays)})"
    if ignored:
        note += f"; ignored columns {', '.join(ignored)}"
    return finish(
        arrays,
        path,
        options,
        fmt=table.format or NAME,
        note=note,
        notes=table.notes,
        lines=np.asarray(table.lines),
    )


def recognises(path: Path, head: str) -> bool:
    """Any text file: the generic reader, tried after the formats recognised by their header."""
    return True


FORMAT = LogFormat(NAME, (".csv",), recognises, read)
