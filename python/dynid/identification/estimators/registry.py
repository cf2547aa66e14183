"""The estimators of the log identification beyond "ols" and "wls": name -> function.

A new estimator is one file in this package with a function ``(Problem) -> EstimatorFit``
(:mod:`.base`) and one :func:`register` line in ``__init__.py``; ``identify_log(method=NAME)``
and ``dynid identify --method NAME`` then find it here.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import Estimator

#: Solved by identify_log itself from the triangular factors (dynid.identification.identify).
LEAST_SQUARES = ("ols", "wls")


@dataclass(frozen=True)
class Registered:
    """An estimator with its one-line description (the CLI's help) and its options' names."""

    function: Estimator
    summary: str
    options: tuple[str, ...] = ()
    #: why ``physical=True`` is refused with this estimator (empty: its row weights carry it)
    no_physical: str = ""


REGISTRY: dict[str, Registered] = {}


def register(
    name: str,
    function: Estimator,
    summary: str,
    options: tuple[str, ...] = (),
    no_physical: str = "",
) -> None:
    """Make ``function`` the estimator ``method=name``; ValueError when the name is taken.
    ``no_physical``: why the estimator has no physically consistent fit (identify_log then
    refuses ``physical=True`` with it), empty when its row weights give one."""
    if name in LEAST_SQUARES or (name in REGISTRY and REGISTRY[name].function is not function):
        raise ValueError(f"method: an estimator named {name!r} exists already")
    REGISTRY[name] = Registered(function, summary, tuple(options), no_physical)


def unregister(name: str) -> None:
    """Remove a registered estimator (tests that register a toy one clean up with it)."""
    REGISTRY.pop(name, None)


def methods() -> tuple[str, ...]:
    """Every ``method=`` of :func:`dynid.identify_log`: "ols", "wls", then the estimators."""
    return LEAST_SQUARES + tuple(REGISTRY)


def method_name(value: object) -> str:
    """``method`` checked against :func:`methods`; ValueError naming the choices otherwise."""
    if isinstance(value, str) and value in methods():
        return value
    raise ValueError(f"method: expected one of {', '.join(map(repr, methods()))}, got {value!r}")


def estimator(name: str) -> Registered:
    """The registered estimator ``name`` (not "ols"/"wls"); ValueError otherwise."""
    if name not in REGISTRY:
        raise ValueError(f"method: no estimator named {name!r}; registered: {list(REGISTRY)}")
    return REGISTRY[name]


def option_names() -> tuple[str, ...]:
    """Every option any registered estimator takes (identify_log checks the given ones)."""
    return tuple(dict.fromkeys(o for r in REGISTRY.values() for o in r.options))
