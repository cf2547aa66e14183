"""Writing a result folder so that results are never lost or mixed, not even by a second run on
the same folder, a run that is killed or a power cut (issues 14 and 22).

A command writes its files into a hidden staging folder beside the target,
``.NAME.XXXXXXXX.partial``. When all are complete, dynid's marker ``.dynid-output.json`` (the
files written, the dynid version) is added, every file and folder is fsync'ed, the staging folder
is renamed into place, and the parent folder is fsync'ed: after a crash the target is the old
folder or the whole new one (a rename may reach the disk before the data it names, hence the
syncs before it).

- Without ``overwrite`` the target must be absent or an empty folder. That is checked when the
  command starts, before its work, and again by the rename itself: rename(2) replaces an empty
  folder but fails on a non-empty one, atomically, so of two runs racing for one target the
  second to finish fails and the first one's result stays.
- ``overwrite`` replaces only a folder that dynid wrote (it holds the marker), and never one that
  holds an input of the run (the log, the model, the result being validated: the ``inputs``) or
  the current folder. The new folder takes the old one's place in one step (Linux renameat2
  RENAME_EXCHANGE), then the old one is deleted. Where the system lacks that, two renames; a
  crash between them leaves the old folder, whole, as ``.NAME.XXXXXXXX.old``.
- A run holds a lock (flock) on its staging folder as long as it exists. The next run on the same
  target removes the staging folders it can lock, the debris of killed runs, and nothing else:
  not the staging folder of a run still writing, nor any other file or folder.
"""

from __future__ import annotations

import ctypes
import errno
import fcntl
import functools
import json
import os
import re
import secrets
import shutil
import stat
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Union

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
    """Yield a staging folder to write into; on leaving the block without an error it becomes
    ``folder`` (see the module docstring; ``check_output_path`` for ``overwrite`` and
    ``inputs``). On an error, and when another run wrote ``folder`` meanwhile (a ValueError
    unless ``overwrite``), the staging folder is removed and ``folder`` is left as it is."""
    inputs = list(inputs)
    given = check_output_path(folder, overwrite, name, inputs)
    # A symbolic link's folder is the one replaced, "." has a name: the real path from here on.
    target = Path(os.path.realpath(given))
    target.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale_staging(target)
    staging, lock = _new_staging(target)
    try:
        yield staging
        _write_marker(staging)
        _sync_tree(staging)
        _move_into_place(staging, target, given, overwrite, name, inputs)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    finally:
        os.close(lock)


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


def _move_into_place(
    staging: Path,
    target: Path,
    given: Path,
    overwrite: bool,
    name: str,
    inputs: list[PathLike | None],
) -> None:
    # A few rounds: with overwrite, another run may remove the target between two steps here.
    for _ in range(10):
        try:
            os.rename(staging, target)  # fails on a non-empty folder, atomically
            break
        except OSError as error:
            if error.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                raise
        if not overwrite:
            raise ValueError(
                f"{name}: {given} was written by another run meanwhile; its files are kept and "
                "this run's are not written: choose another folder or pass --overwrite "
                "(overwrite=True) to replace it"
            )
        check_output_path(given, overwrite, name, inputs)  # what is there now may be replaced
        if _replace(staging, target):
            break
    else:
        raise OSError(errno.EBUSY, f"{name}: {given} kept changing; this run's result not written")
    _fsync(target.parent)


def _replace(staging: Path, target: Path) -> bool:
    """Put the folder ``staging`` in the place of the folder ``target`` and delete the old one;
    False when ``target`` is gone."""
    try:
        _rename_exchange(staging, target)
        old = staging  # the exchange left the old folder there
    except FileNotFoundError:
        return False
    except OSError as error:
        if error.errno not in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP, errno.EOPNOTSUPP):
            raise
        old = staging.with_suffix(".old")
        try:
            os.rename(target, old)
        except FileNotFoundError:
            return False
        os.rename(staging, target)
    shutil.rmtree(old, ignore_errors=True)
    return True


@functools.cache
def _libc() -> Any:
    return ctypes.CDLL(None, use_errno=True)


def _rename_exchange(a: Path, b: Path) -> None:
    """Swap the paths ``a`` and ``b`` in one step: renameat2(2) with RENAME_EXCHANGE (Linux 3.15,
    glibc 2.28); an OSError ENOSYS where the C library lacks it, EINVAL where the file system
    does."""
    renameat2 = getattr(_libc(), "renameat2", None)
    if renameat2 is None:
        raise OSError(errno.ENOSYS, "renameat2: not in this C library")
    at_fdcwd, rename_exchange = -100, 2  # <fcntl.h>, <linux/fs.h>
    renameat2.argtypes = [
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_uint,
    ]
    renameat2.restype = ctypes.c_int
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) != 0:
        code = ctypes.get_errno()
        raise OSError(code, os.strerror(code), str(a), None, str(b))


def _new_staging(target: Path) -> tuple[Path, int]:
    """A new staging folder for ``target`` and the open descriptor by which this run holds its
    lock. The folder is locked just after it is made: if another run's clean-up
    (``_remove_stale_staging``) takes it in that instant, it is removed and a new one made."""
    while True:
        path = _new_folder(target.parent, f".{target.name}.", ".partial")
        try:
            handle = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
        except FileNotFoundError:
            continue
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(handle)
            continue
        except OSError:
            pass  # no locks on this file system: no other run can lock, hence remove, it either
        if _same_folder(handle, path):
            return path, handle
        os.close(handle)


def _remove_stale_staging(target: Path) -> None:
    """Remove the staging folders of ``target`` (``.NAME.`` 8 hex digits ``.partial``) that no
    run holds locked: those of runs that were killed."""
    pattern = re.compile(re.escape(f".{target.name}.") + "[0-9a-f]{8}" + re.escape(".partial"))
    with os.scandir(target.parent) as entries:
        found = [
            e.path for e in entries if pattern.fullmatch(e.name) and e.is_dir(follow_symlinks=False)
        ]
    for path in found:
        try:
            handle = os.open(path, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
        except OSError:
            continue
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:  # a run is writing into it (or no locks here: then left alone)
            os.close(handle)
            continue
        try:
            if _same_folder(handle, path):
                shutil.rmtree(path, ignore_errors=True)
        finally:
            os.close(handle)


def _same_folder(handle: int, path: PathLike) -> bool:
    """Whether ``path`` is still the folder open as ``handle``."""
    try:
        now = os.stat(path, follow_symlinks=False)
    except FileNotFoundError:
        return False
    opened = os.fstat(handle)
    return (now.st_dev, now.st_ino) == (opened.st_dev, opened.st_ino)


def _sync_tree(folder: Path) -> None:
    """fsync every file and folder under ``folder``, and ``folder``: data and names on disk."""
    for parent, _, files in os.walk(folder, topdown=False):
        for file in files:
            _fsync(os.path.join(parent, file))
        _fsync(parent)


def _fsync(path: PathLike) -> None:
    handle = os.open(path, os.O_RDONLY)
    try:
        os.fsync(handle)
    except OSError as error:
        # Some file systems cannot sync a folder (EINVAL); its entries then reach the disk as
        # that file system allows, which is all that can be done there.
        if not (
            stat.S_ISDIR(os.fstat(handle).st_mode) and error.errno in (errno.EINVAL, errno.ENOTSUP)
        ):
            raise
    finally:
        os.close(handle)


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
