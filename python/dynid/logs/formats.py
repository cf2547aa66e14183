"""Which log formats exist, and which one a file is: the one home of the readers.

Each format is a :class:`LogFormat` (its name, the file name suffixes it reads, a test on the
file's first bytes, and its reader), registered once in :mod:`dynid.logs.readers`. ``detect``
picks the first format whose suffix matches and which recognises the file, trying the specific
formats (a robot's own recorder, recognised by its header) before the generic ones (any CSV,
NPZ, MATLAB), so that a UR RTDE file is read as one and not as some CSV.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .log_files import Log

#: Bytes of a file handed to ``recognises`` (a header of 80+ RTDE names fits).
HEAD_BYTES = 4096


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


def formats() -> list[LogFormat]:
    """The registered formats in the order ``detect`` tries them."""
    from . import readers  # noqa: F401  (registers the formats on first use)

    return [*_SPECIFIC, *_GENERIC]


def suffixes() -> list[str]:
    """Every suffix some format reads, in the order of ``formats()`` (no repeats)."""
    return list(dict.fromkeys(s for fmt in formats() for s in fmt.suffixes))


def detect(path: str | Path) -> LogFormat:
    """The format of the file ``path``: by suffix, then by its first bytes."""
    path = Path(path)
    suffix = DIRECTORY if path.is_dir() else path.suffix.lower()
    candidates = [fmt for fmt in formats() if suffix in fmt.suffixes]
    if not candidates and suffix == DIRECTORY:
        raise ValueError(f"path: {path} is a folder; no log format reads a folder")
    if not candidates:
        known = [s for s in suffixes() if s != DIRECTORY]
        own = [s for s in (".npz", ".csv") if s in known]
        others = [s for s in known if s not in own]
        raise ValueError(
            f"path: unknown extension {path.suffix!r} of {path}; expected {' or '.join(own)}"
            + (f", or {', '.join(others)}" if others else "")
        )
    head = "" if suffix == DIRECTORY else _head(path)
    for fmt in candidates:
        if fmt.recognises(path, head):
            return fmt
    names = ", ".join(fmt.name for fmt in candidates)
    raise ValueError(f"{path}: not recognised as any of the {suffix} formats ({names})")


def _head(path: Path) -> str:
    """The file's first bytes as text, or "" when they are binary (a NUL byte, not UTF-8)."""
    with path.open("rb") as handle:
        raw = handle.read(HEAD_BYTES)
    if b"\0" in raw:
        return ""
    # A multi-byte character may be cut at the end of the block: ignore that, not the file.
    return raw.decode("utf-8", errors="ignore")
