"""Universal Robots RTDE recordings: the RTDE client library's ``record.py`` (fields separated
by spaces) and ur_rtde's ``startFileRecording`` (commas), one header line of the recorded
fields with one column per joint: ``timestamp actual_q_0 .. actual_q_5 actual_qd_0 ..
target_moment_0 .. actual_current_0 ..`` (docs/data.md, "UR RTDE CSV").

The joint torques are ``target_moment_i``, the controller's torques from its own model (UR has
no joint torque sensors); with ``current`` (``--current``) the motor currents
``actual_current_i`` are read instead, for the drive gains (docs/drive_gains.md). ``timestamp``
is the controller's time in seconds.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..formats import LogFormat, ReadOptions
from ..log import Log
from ._build import table_log
from ._table import header_fields, read_table

NAME = "UR RTDE CSV"


def _joint(field: str) -> re.Pattern[str]:
    # Digits only: RTDE also has e.g. actual_current_window_0, which is no joint current.
    return re.compile(rf"{field}_\d+\Z")


def read(path: Path, options: ReadOptions) -> Log:
    spec: dict[str, str | re.Pattern[str]] = {
        "t": "timestamp",
        "q": _joint("actual_q"),
        "qd": _joint("actual_qd"),
        "tau": _joint("actual_current" if options.current else "target_moment"),
    }
    table = read_table(path)
    if not any(_joint("actual_qd").match(name) for name in table.names):
        del spec["qd"]
    return table_log(path, table, options, spec, fmt=NAME)


def recognises(path: Path, head: str) -> bool:
    """A header with ``timestamp`` and ``actual_q_0``."""
    names = header_fields(head)
    return "timestamp" in names and "actual_q_0" in names


FORMAT = LogFormat(NAME, (".csv",), recognises, read)
