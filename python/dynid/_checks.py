"""Input checks shared by the Python modules (docs/conventions.md, "Bad input": bad input raises
``ValueError`` whose message starts with the argument's name and says what was expected and what was
given).

One conversion for every array argument, :func:`real_array`: NumPy's own ``float`` cast would
silently drop the imaginary part of complex numbers (a ComplexWarning at most), turn booleans
into 0/1 and accept objects or strings that happen to convert, so the dtype is checked before
the cast.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: dtype kinds accepted as real numbers: signed and unsigned integers, floats.
REAL_KINDS = "iuf"

#: The most joints a robot read from a file may have: the DH rows of a model file, the movable
#: joints of a URDF chain (docs/cli.md). Checked before any work on them: a 12 KB model file with
#: 300 DH rows, or a 100 KB URDF with 300 joints, kept `dynid info` computing base parameters
#: for many minutes (the URDF's ended in std::bad_alloc).
MAX_JOINTS = 64

# NumPy < 1.24 warns (and makes an object array) where later versions raise for ragged input.
_RAGGED_WARNING = getattr(np, "exceptions", np).VisibleDeprecationWarning

_KIND_NAMES = {
    "b": "booleans",
    "c": "complex numbers",
    "O": "Python objects",
    "U": "strings",
    "S": "bytes",
    "V": "structured values",
    "M": "datetimes",
    "m": "timedeltas",
}


def real_array(
    value: ArrayLike, name: str, *, ndim: int | None = None, finite: bool = True
) -> NDArray[np.float64]:
    """``value`` as a float64 array of real numbers, checked.

    Raises ``ValueError`` naming ``name`` when ``value`` is ragged (nested sequences of unequal
    lengths), is not made of real numbers (``dtype.kind`` outside "iuf": complex, bool, object,
    strings, ...), has not ``ndim`` dimensions (when given) or, with ``finite`` (default), holds
    NaN or inf. The result is not copied when ``value`` already is a float64 array; pass
    ``finite=False`` only when the caller reports non-finite values itself, in more detail.
    """
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", _RAGGED_WARNING)
            array = np.asarray(value)
    except (ValueError, _RAGGED_WARNING) as exc:
        text = str(exc)
        if "inhomogeneous" in text or "ragged" in text:
            raise ValueError(
                f"{name}: expected a rectangular array of real numbers, got ragged nested "
                f"sequences (rows of different lengths): {text}"
            ) from None
        raise ValueError(
            f"{name}: expected an array of real numbers, got {type(value).__name__} ({text})"
        ) from None
    except TypeError as exc:
        raise ValueError(
            f"{name}: expected an array of real numbers, got {type(value).__name__} ({exc})"
        ) from None
    if array.dtype.kind not in REAL_KINDS:
        what = _KIND_NAMES.get(array.dtype.kind, "non-real values")
        raise ValueError(
            f"{name}: expected real numbers (integer or float), got {what} "
            f"(dtype {array.dtype}) from {type(value).__name__}"
        )
    array = array.astype(np.float64, copy=False)
    if ndim is not None and array.ndim != ndim:
        raise ValueError(f"{name}: expected a {ndim}-dimensional array, got shape {array.shape}")
    if finite:
        check_finite(array, name)
    return array


def check_finite(array: NDArray[np.float64], name: str) -> None:
    """Raise ``ValueError`` naming ``name`` and the first NaN or inf and its index."""
    bad = ~np.isfinite(array)
    if bad.any():
        if array.ndim == 0:
            raise ValueError(f"{name}: expected a finite number, got {array}")
        where = tuple(int(i[0]) for i in np.nonzero(bad))
        raise ValueError(f"{name}: non-finite value {array[where]} at index {where}")


def positive(value: Any, name: str) -> float:
    """A positive finite number (bool refused), as a float."""
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected a positive number, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a positive number, got {value!r}") from None
    if not np.isfinite(v) or v <= 0.0:
        raise ValueError(f"{name}: expected a positive finite number, got {value!r}")
    return v


def positive_int(value: Any, name: str) -> int:
    """An integer >= 1 (bool refused), as an int."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name}: expected a positive integer, got {value!r}")
    return int(value)


def count(value: Any, name: str, minimum: int, why: str = "") -> int:
    """An integer >= ``minimum`` (bool refused); ``why`` explains the minimum in the message."""
    integral = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
    if not integral or value < minimum:
        reason = f" ({why})" if why else ""
        raise ValueError(f"{name}: expected an integer >= {minimum}{reason}, got {value!r}")
    return int(value)


def is_integer(value: Any) -> bool:
    """True for Python and NumPy integers, False for booleans (which are integers to Python)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def index(value: Any, name: str, size: int) -> int:
    """An integer index in [0, size) (bool refused), as an int."""
    if not is_integer(value) or not 0 <= value < size:
        raise ValueError(f"{name}: expected an integer index in [0, {size}), got {value!r}")
    return int(value)


def indices(value: Any, name: str, size: int) -> tuple[int, ...]:
    """A sequence of distinct integer indices in [0, size), as a tuple (None is refused)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise ValueError(f"{name}: expected a sequence of indices in [0, {size}), got {value!r}")
    items = list(value)
    for item in items:
        index(item, name, size)
    if len(set(items)) != len(items):
        raise ValueError(f"{name}: repeated index in {items!r}")
    return tuple(int(i) for i in items)


def flag(value: Any, name: str) -> bool:
    """True or False exactly (docs/conventions.md, "Bad input": ``rotor="no"`` must not read as
    True)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise ValueError(f"{name}: expected True or False, got {value!r}")


def text(value: Any, name: str, expected: str) -> str:
    """A string; anything else is a ValueError saying what was ``expected``."""
    if isinstance(value, str):
        return value
    raise ValueError(f"{name}: expected {expected}, got {value!r}")


def names(value: Any, name: str, size: int) -> list[str]:
    """A list of ``size`` strings (a tuple or other sequence is accepted)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise ValueError(f"{name}: expected a sequence of {size} strings, got {value!r}")
    items = list(value)
    if len(items) != size or not all(isinstance(item, str) for item in items):
        raise ValueError(f"{name}: expected a sequence of {size} strings, got {value!r}")
    return items


def robot(value: Any, name: str = "robot") -> Any:
    """A dynid robot model (a ``dynid.Robot`` or the C++ model it wraps)."""
    from ._core import Model  # the compiled module; imported here to keep this module pure

    if not isinstance(value, Model):
        raise ValueError(f"{name}: expected a dynid.Robot, got {type(value).__name__}")
    return value
