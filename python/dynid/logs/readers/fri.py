"""KUKA LBR FRI recordings of pyfri (``ClientApplication.collect_data``, lbr-stack/pyfri):
``index,time,record_time_nsec,tsec,tnsec,mp1..mp7,ip1..ip7,mt1..mt7,et1..et7,dt``
(docs/data.md, "KUKA FRI CSV (pyfri)").

The time is the controller's, ``tsec + 1e-9 tnsec``, taken relative to the first whole second
(``tsec - tsec[0]``: a Unix time in seconds in float64 would keep only ~0.2 us, and pyfri's own
``time`` column is the sum of the nominal sample times, written with 6 significant digits). q
from the measured positions ``mp``, the joint torques from the measured torques ``mt`` (the
joint torque sensors); the file has no velocities.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..formats import LogFormat, ReadOptions
from ..log import Log
from ._build import table_log
from ._table import header_fields, read_table

NAME = "KUKA FRI CSV (pyfri)"


def _time(tsec: NDArray[np.float64], tnsec: NDArray[np.float64]) -> NDArray[np.float64]:
    return (tsec - tsec[0]) + 1e-9 * tnsec if tsec.size else tsec


def read(path: Path, options: ReadOptions) -> Log:
    if options.current:
        raise ValueError("current: a pyfri FRI log has no motor currents (mt are joint torques)")
    spec = {"q": re.compile(r"mp\d+\Z"), "tau": re.compile(r"mt\d+\Z")}
    return table_log(
        path, read_table(path), options, spec, fmt=NAME, time_from=(("tsec", "tnsec"), _time)
    )


def recognises(path: Path, head: str) -> bool:
    """A header with ``tsec``, ``tnsec`` and ``mp1`` (a missing ``mt`` is then named)."""
    names = set(header_fields(head))
    return {"tsec", "tnsec", "mp1"} <= names


FORMAT = LogFormat(NAME, (".csv",), recognises, read)
