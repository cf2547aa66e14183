"""Which format a log file is: ``detect`` picks the first registered format whose suffix matches
and which recognises the file, trying the specific formats (a robot's own recorder, recognised
by its header) before the generic ones (any CSV, NPZ, MATLAB), so that a UR RTDE file is read as
one and not as some CSV. Importing this module registers dynid's readers
(:mod:`dynid.logs.readers`).
"""

from __future__ import annotations

from pathlib import Path

from . import readers  # noqa: F401  (registers dynid's formats)
from .formats import DIRECTORY, LogFormat, registered

#: Bytes of a file handed to ``recognises`` (a header of 80+ RTDE names fits).
HEAD_BYTES = 4096


def formats() -> list[LogFormat]:
    """The registered formats in the order ``detect`` tries them."""
    return registered()


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
