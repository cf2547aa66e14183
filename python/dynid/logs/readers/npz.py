"""NPZ (``numpy.savez``): dynid's keys ``t, q, tau[, qd, qdd]``, the FloBaRoID names of the
KUKA LWR4+ recordings (``times, positions, torques, ...``), or any keys mapped with ``columns``
(docs/data.md). The keyed arrays are shared with the MATLAB reader (:mod:`.matlab`)."""

from __future__ import annotations

import zipfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..._checks import positive
from ..columns import matching
from ..formats import LogFormat, ReadOptions
from ..log import Log
from ..messages import name_list
from ._build import finish

NAME = "NPZ"

#: Keys: the dynid name first, then the FloBaRoID name (measurements_*.npz of kjyv/FloBaRoID).
KEYS = {
    "t": ("t", "times"),
    "q": ("q", "positions"),
    "qd": ("qd", "velocities"),
    "qdd": ("qdd", "accelerations"),
    "tau": ("tau", "torques"),
}


def read(path: Path, options: ReadOptions) -> Log:
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:  # all: "not an npz"
        raise ValueError(f"not a readable NPZ file ({type(exc).__name__}: {exc})") from None
    with data:
        found = list(data.files)
        _check_members(path)
        notes = [str(s) for s in data["notes"]] if "notes" in found else []
        stored = str(data["format"]) if "format" in found else ""
        timeless = not ({"t", "times"} & set(found)) and not (options.columns or {}).get("t")
        if timeless and "sample_time" in found and options.sample_time is None:
            # the recording's own sample time (the Staubli TX40 data's key)
            own = positive(data["sample_time"][()], "key 'sample_time'")  # seconds
            options = replace(options, sample_time=own)
        arrays, how = keyed_arrays(
            found, data.__getitem__, options.columns, need_t=options.sample_time is None
        )
    note = f"loaded from {path.name} (NPZ, {how})"
    return finish(arrays, path, options, fmt=stored or NAME, note=note, notes=notes)


def keyed_arrays(
    found: Sequence[str],
    get: Callable[[str], Any],
    columns: Mapping[str, str] | None,
    *,
    need_t: bool = True,
) -> tuple[dict[str, NDArray], str]:
    """The signals of a file of named arrays (NPZ keys, MATLAB variables), and how they were
    found (for the load note): by ``columns``, else by dynid's or FloBaRoID's names. Without
    ``need_t`` (a sample time was given) a missing time vector is no error."""
    if columns:
        return mapped_arrays(found, lambda name: np.asarray(get(name)), columns), (
            f"columns {dict(columns)}"
        )
    arrays: dict[str, NDArray] = {}
    flobaroid = False
    for name, aliases in KEYS.items():
        present = [key for key in aliases if key in found]
        if len(present) > 1:
            raise ValueError(f"both keys {present[0]!r} and {present[1]!r} given for {name}")
        if present:
            try:
                arrays[name] = np.asarray(get(present[0]))
            except ValueError as exc:  # object arrays need pickle, refused on purpose
                raise ValueError(f"key {present[0]!r}: unreadable ({exc})") from None
            flobaroid |= present[0] != name
    for name in ("t", "q", "tau") if need_t else ("q", "tau"):
        if name not in arrays:
            alias = KEYS[name][1]
            raise ValueError(
                f"missing key {name!r} (or FloBaRoID {alias!r}); found keys: {name_list(found)}"
            )
    for name, arr in arrays.items():
        if arr.dtype.kind not in "iuf":
            raise ValueError(f"key for {name}: expected numbers, got dtype {arr.dtype}")
    how = "FloBaRoID key names" if flobaroid else "dynid key names"
    return arrays, f"{how}; {', '.join(arrays)}"


def mapped_arrays(
    names: Sequence[str],
    get: Callable[[str], NDArray],
    mapping: Mapping[str, str],
) -> dict[str, NDArray]:
    """The signals named by ``mapping`` (keys or patterns, :mod:`dynid.logs.columns`): one 2-D
    array, or several 1-D ones stacked as joints in natural order; ``t`` is one 1-D array."""
    for required in ("q", "tau"):
        if required not in mapping:
            raise ValueError(f"columns: {required!r} missing from the mapping {dict(mapping)}")
    # Without a time vector the Log is made from the sample time, or refused naming it.
    has_t = "t" in names or "times" in names
    spec = {**({"t": "t" if "t" in names else "times"} if has_t else {}), **mapping}
    arrays: dict[str, NDArray] = {}
    for signal, pattern in spec.items():
        found = matching(pattern, names, signal)
        parts = [np.asarray(get(name)) for name in found]
        if len(parts) == 1 and (signal == "t" or parts[0].ndim == 2):
            arrays[signal] = parts[0]
        elif signal != "t" and all(part.ndim == 1 for part in parts):
            arrays[signal] = np.column_stack(parts)
        else:
            expected = (
                "one time vector"
                if signal == "t"
                else "one (T, n) array or 1-D columns, one per joint"
            )
            raise ValueError(
                f"columns: {pattern!r} for {signal} matches {name_list(found)}; expected {expected}"
            )
    return arrays


def _check_members(path: Path) -> None:
    """Refuse a member whose .npy header asks for more bytes than the member holds (a corrupt or
    hostile header would otherwise make NumPy try to allocate it) or that is not .npy at all."""
    with zipfile.ZipFile(path) as archive:
        for info in archive.infolist():
            if not info.filename.endswith(".npy"):
                raise ValueError(f"member {info.filename!r} is not a .npy array")
            with archive.open(info) as member:
                try:
                    version = np.lib.format.read_magic(member)
                    read_header = (
                        np.lib.format.read_array_header_1_0
                        if version == (1, 0)
                        else np.lib.format.read_array_header_2_0
                    )
                    shape, _, dtype = read_header(member)
                except (ValueError, OSError, EOFError) as exc:
                    raise ValueError(
                        f"member {info.filename!r}: unreadable header ({exc})"
                    ) from None
            needed = dtype.itemsize * int(np.prod(shape, dtype=object))
            if needed > info.file_size:
                raise ValueError(
                    f"member {info.filename!r}: its header asks for shape {shape} "
                    f"({needed} bytes) but the member holds {info.file_size} bytes"
                )


def recognises(path: Path, head: str) -> bool:
    """Any .npz file (an unreadable one gets the reader's error)."""
    return True


FORMAT = LogFormat(NAME, (".npz",), recognises, read)
