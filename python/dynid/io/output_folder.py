"""Writing a result folder so that results are never lost or mixed (issue: no silent overwrite,
no half-written file).

Everything is written into a fresh temporary folder beside the target; only when every file is
complete is it moved into place with ``os.replace``. An existing, non-empty target is refused
unless ``overwrite`` is given, and then it is replaced as a whole (moved aside, the new folder
moved in, the old one deleted), so a folder never holds files of two runs, and a failure (a full
disk, a plot that cannot be drawn) leaves the previous folder as it was.
"""

from __future__ import annotations

import os
import secrets
import shutil
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Union

PathLike = Union[str, Path]


def check_output_path(folder: PathLike, overwrite: bool, name: str = "output") -> Path:
    """The output folder as a Path; a ValueError naming ``name`` for an empty path, a path that
    is a file, or an existing non-empty folder when ``overwrite`` is False."""
    if not isinstance(overwrite, bool):
        raise ValueError(f"overwrite: expected True or False, got {overwrite!r}")
    if not isinstance(folder, (str, Path)) or str(folder).strip() == "":
        raise ValueError(f"{name}: expected a folder path, got {folder!r}")
    path = Path(folder)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{name}: {path} exists and is not a folder")
    if path.is_dir() and any(path.iterdir()) and not overwrite:
        raise ValueError(
            f"{name}: {path} exists and is not empty; choose another folder or pass "
            "--overwrite (overwrite=True) to replace it"
        )
    return path


@contextmanager
def output_folder(
    folder: PathLike, overwrite: bool = False, name: str = "output"
) -> Iterator[Path]:
    """Yield a temporary folder to write into; on leaving the block without an error it becomes
    ``folder`` (see the module docstring); on an error it is removed and ``folder`` is untouched."""
    target = check_output_path(folder, overwrite, name)
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = _new_folder(target.parent, f".{target.name}.", ".partial")
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    old = None
    if target.exists():
        old = target.parent / f".{target.name}.{staging.name.split('.')[-2]}.old"
        os.replace(target, old)
    os.replace(staging, target)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _new_folder(parent: Path, prefix: str, suffix: str) -> Path:
    """A new, uniquely named folder in ``parent`` with the permissions of any new folder
    (0o777 less the umask, applied by the kernel: tempfile.mkdtemp's would be 0o700)."""
    while True:
        path = parent / f"{prefix}{secrets.token_hex(4)}{suffix}"
        try:
            path.mkdir()
        except FileExistsError:
            continue
        return path


def _new_file(parent: Path, prefix: str) -> tuple[int, Path]:
    """A new, uniquely named file in ``parent``, open for writing, with the permissions of any new
    file (0o666 less the umask, applied by the kernel: tempfile.mkstemp's would be 0o600)."""
    while True:
        path = parent / f"{prefix}{secrets.token_hex(4)}.partial"
        try:
            return os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666), path
        except FileExistsError:
            continue


def write_text_atomic(path: PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` through a temporary file in the same folder and a rename, so
    that ``path`` is either the old file or the complete new one, never a truncated mix. A file
    that is replaced keeps its permissions; a new one gets those of any new file."""
    target = Path(path)
    handle, temporary = _new_file(target.parent, f".{target.name}.")
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
        if target.exists():
            os.chmod(temporary, stat.S_IMODE(target.stat().st_mode))
        os.replace(temporary, target)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return target
