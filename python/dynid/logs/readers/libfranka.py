"""libfranka's ``franka::logToCSV`` (the log of a ``ControlException``, or any
``std::vector<franka::Record>``): ``time, success_rate, state.q[0] .. state.q[6], state.q_d[..],
state.dq[..], state.dq_d[..], state.tau_J[..], state.tau_ext_hat_filtered[..], cmd.q_d[..], ...``
(libfranka's src/log.cpp: the names of a group separated by ", "; src/logging/
robot_state_log.cpp of newer releases: by ","; both are read). docs/data.md, "libfranka
logToCSV".

``time`` is the robot's time in milliseconds (``Duration::toMSec``); q from ``state.q``, qd from
``state.dq``, the joint torques from ``state.tau_J`` (the measured link-side torques). libfranka
writes doubles with the stream's default 6 significant digits.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..formats import LogFormat, ReadOptions
from ..log import Log
from ._build import table_log
from ._table import header_fields, read_table

NAME = "libfranka logToCSV"


def _joint(field: str) -> re.Pattern[str]:
    return re.compile(rf"state\.{field}\[\d+\]\Z")


def read(path: Path, options: ReadOptions) -> Log:
    if options.current:
        raise ValueError(
            "current: a libfranka log has no motor currents (state.tau_J are joint torques)"
        )
    spec: dict[str, str | re.Pattern[str]] = {
        "t": "time",
        "q": _joint("q"),
        "qd": _joint("dq"),
        "tau": _joint("tau_J"),
    }
    return table_log(path, read_table(path), options, spec, fmt=NAME, unit="ms")


def recognises(path: Path, head: str) -> bool:
    """A header with ``time`` and ``state.q[0]``."""
    names = header_fields(head)
    return "time" in names and "state.q[0]" in names


FORMAT = LogFormat(NAME, (".csv",), recognises, read)
