"""Value equality for the result dataclasses, whose fields hold NumPy arrays: the generated
``__eq__`` would compare arrays with ``==`` and raise ("truth value of an array is ambiguous")."""

from __future__ import annotations

from dataclasses import Field, fields
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np


def equal_values(a: Any, b: Any) -> bool:
    """Deep equality: arrays element by element (NaN equal to NaN), containers item by item."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            return False
        if a.dtype.kind in "fc" or b.dtype.kind in "fc":
            return bool(np.array_equal(a, b, equal_nan=True))
        return bool(np.array_equal(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(equal_values(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(equal_values(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b):
        return True
    return bool(a == b)


class ValueEquality:
    """Mixin for dataclasses (declared with ``eq=False``): ``==`` compares every field by value."""

    if TYPE_CHECKING:  # what @dataclass adds to the classes that use the mixin
        __dataclass_fields__: ClassVar[dict[str, Field[Any]]]

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(
            equal_values(getattr(self, f.name), getattr(other, f.name))
            for f in fields(self)
            if f.compare
        )

    # Unhashable (mutable contents); mypy objects to None in place of the inherited method.
    __hash__ = None  # type: ignore[assignment]
