"""Writing a result folder so that results are never lost or mixed (issues 14 and 22).

Everything is written into a fresh temporary folder beside the target; only when every file is
complete is dynid's marker ``.dynid-output.json`` (the files written, the dynid version) added
and the folder moved into place with ``os.replace``. An existing, non-empty target is refused
unless ``overwrite`` is given, and then it is replaced as a whole (moved aside, the new folder
moved in, the old one deleted), so a folder never holds files of two runs, and a failure (a full
disk, a plot that cannot be drawn) leaves the previous folder as it was. ``overwrite`` replaces
only a folder that dynid wrote (it holds the marker), and never one that holds an input of the
run (the log, the model, the result being validated: the ``inputs``) or the current folder.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import stat
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Union

from .._version import dynid_version

PathLike = Union[str, Path]

#: The file that marks a folder as written by dynid: ``overwrite`` replaces no other folder.
MARKER = ".dynid-output.json"
MARKER_FORMAT = "dynid-output"


def check_output_path(
    folder: PathLike,
    overwrite: bool,
    name: str = "output",
    inputs: Iterable[PathLike | None] = (),
) -> Path:
    """The output folder as a Path; a ValueError naming ``name`` for an empty path, a path that
    is a file, a folder that holds the current folder, and an existing non-empty folder unless
    ``overwrite`` is True and it is a folder dynid wrote that holds none of ``inputs`` (paths of
    files and folders the run reads; None and what does not exist, e.g. a built-in model's name,
    are skipped)."""
    if not isinstance(overwrite, bool):
        raise ValueError(f"overwrite: expected True or False, got {overwrite!r}")
    if not isinstance(folder, (str, Path)) or str(folder).strip() == "":
        raise ValueError(f"{name}: expected a folder path, got {folder!r}")
    path = Path(folder)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{name}: {path} exists and is not a folder")
    if not path.is_dir():
        return path
    if _holds(path, os.getcwd()):
        # Replacing it would leave this process, and the shell that started it, in a deleted folder.
        raise ValueError(
            f"{name}: {path} is or holds the current folder; choose another (--output)"
        )
    if not any(path.iterdir()):
        return path
    if not overwrite:
        raise ValueError(
            f"{name}: {path} exists and is not empty; choose another folder or pass "
            "--overwrite (overwrite=True) to replace it"
        )
    for item in inputs:
        if item is not None and _holds(path, item):
            raise ValueError(
                f"{name}: {path} holds {item}, an input of this run, which --overwrite would "
                "delete; choose another folder (--output)"
            )
    if not _is_dynid_output(path):
        raise ValueError(
            f"{name}: {path} was not written by dynid (it has no {MARKER}); --overwrite "
            "(overwrite=True) replaces only dynid's result folders: choose another folder "
            "(--output) or empty this one yourself"
        )
    return path


@contextmanager
def output_folder(
    folder: PathLike,
    overwrite: bool = False,
    name: str = "output",
    inputs: Iterable[PathLike | None] = (),
) -> Iterator[Path]:
    """Yield a temporary folder to write into; on leaving the block without an error it becomes
    ``folder`` (see the module docstring; ``check_output_path`` for ``overwrite`` and
    ``inputs``); on an error it is removed and ``folder`` is untouched."""
    target = check_output_path(folder, overwrite, name, inputs)
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = _new_folder(target.parent, f".{target.name}.", ".partial")
    try:
        yield staging
        _write_marker(staging)
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


def _holds(folder: Path, item: PathLike) -> bool:
    """Whether the existing path ``item`` is ``folder`` or inside it: as written (a symbolic link
    inside), or with symbolic links resolved (a link to inside)."""
    if not os.path.lexists(item):
        return False
    return any(
        Path(resolve(item)).is_relative_to(resolve(folder))
        for resolve in (os.path.abspath, os.path.realpath)
    )


def _is_dynid_output(folder: Path) -> bool:
    try:
        marker = json.loads((folder / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(marker, dict) and marker.get("format") == MARKER_FORMAT


def _write_marker(staging: Path) -> None:
    files = sorted(p.relative_to(staging).as_posix() for p in staging.rglob("*") if p.is_file())
    marker = {"format": MARKER_FORMAT, "dynid_version": dynid_version(), "files": files}
    (staging / MARKER).write_text(json.dumps(marker, indent=1) + "\n", encoding="utf-8")


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
