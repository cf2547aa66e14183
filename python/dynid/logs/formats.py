"""What a log format is, and the registry of them.

Each format is a :class:`LogFormat` (its name, the file name suffixes it reads, a test on the
file's first bytes, and its reader), registered once in :mod:`dynid.logs.readers` with
:func:`register`. Which format a file is: :mod:`dynid.logs.detection` (it imports the readers;
this module does not, so that the readers can import it without a circle).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .log import Log


@dataclass(frozen=True)
class ReadOptions:
    """What the caller of ``load_log`` said about the file (docs/data.md).

    ``columns``: signal -> column/key pattern (:mod:`dynid.logs.columns`), overriding a format's
    own mapping; ``time_unit``: the time stamps' unit, None for the format's own (seconds unless
    the format says otherwise); ``current``: read motor currents instead of joint torques where
    the format records both (UR RTDE); ``topic``, ``joint_names``: for the ROS bag reader;
    ``drop_nonfinite``: drop rows with a NaN or inf instead of refusing the file;
    ``sample_time``: seconds between samples of a log without a time vector (t = 0, dt, ...).
    """

    columns: Mapping[str, str] | None = None
    time_unit: str | None = None
    current: bool = False
    topic: str | None = None
    joint_names: tuple[str, ...] | None = None
    drop_nonfinite: bool = False
    sample_time: float | None = None


@dataclass(frozen=True)
class LogFormat:
    """One file format: ``recognises(path, head)`` gets the first HEAD_BYTES of the file as text
    ("" for a binary file); ``read(path, options)`` returns the checked Log."""

    name: str  #: shown in the output and in result.json, e.g. "UR RTDE CSV"
    #: lower case, with the dot: (".csv",); DIRECTORY for a format stored as a folder (a ROS 2
    #: bag: metadata.yaml beside its .db3 or .mcap files)
    suffixes: tuple[str, ...]
    recognises: Callable[[Path, str], bool]
    read: Callable[[Path, ReadOptions], Log]
    #: Whether the format holds several streams chosen by ``ReadOptions.topic`` (ROS bags); a
    #: topic given for another format is an error, not ignored.
    topics: bool = False


#: The "suffix" of a folder given as the log (``recognises`` then gets "" as the head).
DIRECTORY = "/"

_SPECIFIC: list[LogFormat] = []
_GENERIC: list[LogFormat] = []


def register(fmt: LogFormat, *, generic: bool = False) -> LogFormat:
    """Add a format. Generic formats (that accept any file of their suffix) are tried after all
    specific ones, whatever the order of registration."""
    if not isinstance(fmt, LogFormat):
        raise ValueError(f"fmt: expected a LogFormat, got {type(fmt).__name__}")
    if any(known.name == fmt.name for known in (*_SPECIFIC, *_GENERIC)):
        raise ValueError(f"fmt: a format named {fmt.name!r} is registered already")
    (_GENERIC if generic else _SPECIFIC).append(fmt)
    return fmt


def registered() -> list[LogFormat]:
    """The formats registered so far, in the order ``detect`` tries them (specific, then generic);
    :func:`dynid.logs.detection.formats` registers dynid's own first."""
    return [*_SPECIFIC, *_GENERIC]
