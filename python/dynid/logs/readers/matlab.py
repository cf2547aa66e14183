"""MATLAB ``.mat`` files, v5 and v7 (``scipy.io.loadmat``): variables named as the NPZ keys
(``t, q, tau[, qd, qdd]`` or FloBaRoID's names) or mapped with ``columns``. A v7.3 file is HDF5,
which SciPy does not read: an error says so and how to save the file instead.

MATLAB has no 1-D arrays: a time vector comes as (1, T) or (T, 1) and is flattened; a signal
saved one joint per row, (n, T), is transposed to dynid's (T, n) when the time's length says
which axis is time (noted)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..formats import LogFormat, ReadOptions
from ..log import Log
from ._build import finish
from .npz import keyed_arrays

NAME = "MATLAB .mat"

#: The version bytes (offset 126 of the 128-byte header) of a v7.3 (HDF5) MAT-file, read as
#: little-endian: 0x0200. v5/v7 files have 0x0100 there (MATLAB's "MAT-File Format", p. 1-7).
_HDF5_VERSION = 0x0200


def read(path: Path, options: ReadOptions) -> Log:
    from scipy.io import loadmat  # SciPy only when a .mat file is read

    if _is_v73(path):
        raise ValueError(
            "a MATLAB v7.3 (HDF5) file, which scipy.io cannot read: save it in MATLAB with "
            "save(file, ..., '-v7'), or as CSV or NPZ (docs/data.md)"
        )
    try:
        contents = loadmat(path, squeeze_me=False, struct_as_record=True)
    except (ValueError, OSError, NotImplementedError, TypeError) as exc:
        # loadmat's errors on a file that is no MAT file, or one of a version it does not read
        # (NotImplementedError), reported as the log's ValueError
        raise ValueError(f"not a readable MATLAB file ({type(exc).__name__}: {exc})") from None
    variables = {k: v for k, v in contents.items() if not k.startswith("__")}
    arrays, how = keyed_arrays(
        list(variables), variables.__getitem__, options.columns, need_t=options.sample_time is None
    )
    arrays, turned = _orient(arrays)
    note = f"loaded from {path.name} (MATLAB, {how})"
    if turned:
        note += f"; {', '.join(turned)} saved one joint per row, transposed"
    return finish(arrays, path, options, fmt=NAME, note=note)


def _orient(arrays: dict[str, NDArray]) -> tuple[dict[str, NDArray], list[str]]:
    t = np.asarray(arrays["t"])
    if t.ndim == 2 and 1 in t.shape:
        t = t.ravel()
    oriented: dict[str, NDArray] = {"t": t}
    turned: list[str] = []
    for name, value in arrays.items():
        if name == "t":
            continue
        value = np.asarray(value)
        if value.ndim == 2 and value.shape[0] != t.size and value.shape[1] == t.size:
            value = value.T
            turned.append(name)
        oriented[name] = value
    return oriented, turned


def _is_v73(path: Path) -> bool:
    with path.open("rb") as handle:
        header = handle.read(128)
    if len(header) < 128:
        return False
    little = header[126:128] == b"IM"
    version = int.from_bytes(header[124:126], "little" if little else "big")
    return version == _HDF5_VERSION


def recognises(path: Path, head: str) -> bool:
    """Any .mat file (v4 and unreadable files get the reader's error)."""
    return True


FORMAT = LogFormat(NAME, (".mat",), recognises, read)
