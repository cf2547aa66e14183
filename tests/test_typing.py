"""The installed package carries its types: py.typed, a _core.pyi stub that covers every name the
compiled module exports (so editors and mypy see the C++ signatures), text signatures on the C++
calls (so inspect.signature and help() show their parameters), and a literal __all__."""

from __future__ import annotations

import ast
import importlib.resources
import inspect

import pytest

import dynid
from dynid import _core


def _installed_file(name: str) -> str:
    return (importlib.resources.files("dynid") / name).read_text()


def _stub() -> ast.Module:
    return ast.parse(_installed_file("_core.pyi"))


def _public(names: list[str]) -> set[str]:
    return {n for n in names if not n.startswith("__")}


def test_py_typed_is_installed() -> None:
    assert _installed_file("py.typed") == ""


def test_stub_lists_every_module_level_name_of_core() -> None:
    module = _stub()
    stubbed = {
        node.name for node in module.body if isinstance(node, (ast.ClassDef, ast.FunctionDef))
    }
    compiled = {n for n in _public(dir(_core)) if callable(getattr(_core, n))}
    assert compiled == stubbed, "regenerate python/dynid/_core.pyi: python tools/generate_stubs.py"


def test_stub_lists_every_attribute_of_the_compiled_classes() -> None:
    module = _stub()
    classes = {node.name: node for node in module.body if isinstance(node, ast.ClassDef)}
    base = _public(dir(object)) | {"_pybind11_conduit_v1_"}
    for name, node in classes.items():
        stubbed = {item.name for item in node.body if isinstance(item, ast.FunctionDef)}
        compiled = set(vars(getattr(_core, name))) - base - {"__module__", "__doc__", "__dict__"}
        compiled = {n for n in compiled if not n.startswith("__") or n in stubbed}
        missing = compiled - stubbed
        assert not missing, (
            f"{name}: {sorted(missing)} not in _core.pyi; run tools/generate_stubs.py"
        )


def test_stub_arguments_match_the_binding_names() -> None:
    # pybind11 puts the py::arg names in the first docstring line; the stub must use the same
    # names so that keyword calls type-check.
    module = _stub()
    for node in ast.walk(module):
        if not isinstance(node, ast.ClassDef):
            continue
        cls = getattr(_core, node.name)
        for item in node.body:
            if not isinstance(item, ast.FunctionDef) or item.decorator_list:
                continue
            doc = inspect.getdoc(getattr(cls, item.name)) or ""
            first = doc.splitlines()[0] if doc else ""
            if not first.startswith(item.name + "("):
                continue  # e.g. __init__ (pybind11 writes "Overloaded function" or no line)
            for arg in item.args.args[1:] + item.args.kwonlyargs:
                assert f"{arg.arg}:" in first, (node.name, item.name, arg.arg, first)


def _bound_functions() -> list[tuple[str, object]]:
    found: list[tuple[str, object]] = []
    for name, value in vars(_core).items():
        if inspect.isbuiltin(value):
            found.append((name, value))
        elif isinstance(value, type) and value.__module__ == _core.__name__:
            found += [
                (f"{name}.{attr}", member)
                for attr, member in vars(value).items()
                if type(member).__name__ == "instancemethod"
            ]
    return found


def _docstring_parameters(doc: str) -> list[tuple[str, object]]:
    """(name, default) from pybind11's typed first docstring line, e.g. "f(self: M, q: object,
    rotor: object = False) -> numpy.ndarray"; `inspect.Parameter.empty` when there is none."""
    head = doc.splitlines()[0]
    inner = head[head.index("(") + 1 : head.rindex(") -> ")]
    tree = ast.parse(f"def f({inner}): pass").body[0]
    assert isinstance(tree, ast.FunctionDef)
    args = tree.args
    positional = args.posonlyargs + args.args  # pybind11 marks pickling methods with '/'
    defaults = [inspect.Parameter.empty] * (len(positional) - len(args.defaults)) + [
        ast.literal_eval(d) for d in args.defaults
    ]
    kw_defaults = [
        inspect.Parameter.empty if d is None else ast.literal_eval(d) for d in args.kw_defaults
    ]
    return [(a.arg, d) for a, d in zip(positional, defaults)] + [
        (a.arg, d) for a, d in zip(args.kwonlyargs, kw_defaults)
    ]


def test_inspect_signature_shows_the_parameters_of_the_cpp_calls() -> None:
    assert list(inspect.signature(dynid.Robot.rnea).parameters) == ["self", "q", "qd", "qdd", "out"]
    robot = dynid.models.planar_2r()
    assert list(inspect.signature(robot.rnea).parameters) == ["q", "qd", "qdd", "out"]
    signature = inspect.signature(robot.regressor)
    assert signature.parameters["rotor"].default is False
    assert list(inspect.signature(dynid.set_threads).parameters) == ["threads"]
    rls = inspect.signature(dynid.RecursiveLeastSquares)
    assert rls.parameters["theta0"].kind is inspect.Parameter.KEYWORD_ONLY
    # __doc__ keeps a typed signature line (what pybind11-stubgen and help() read); for the
    # Model's calls it is written from the call table, with the arguments' real types
    assert (dynid.Robot.rnea.__doc__ or "").startswith(
        "rnea(self: dynid._core.Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike"
    )


def test_every_text_signature_matches_the_pybind11_docstring() -> None:
    # Independent source: the typed signature line pybind11 writes itself, parsed with ast.
    functions = _bound_functions()
    assert len(functions) > 30
    for name, function in functions:
        doc = function.__doc__ or ""
        if not doc.startswith(name.split(".")[-1] + "(") or "Overloaded function" in doc:
            continue  # pybind11 internals (_pybind11_conduit_v1_) and overloads
        try:
            expected = _docstring_parameters(doc)
        except (SyntaxError, ValueError):  # a default that is no literal: no text signature
            with pytest.raises(ValueError, match="signature"):
                inspect.signature(function)
            continue
        got = [(p.name, p.default) for p in inspect.signature(function).parameters.values()]
        assert got == expected, name


def test_all_is_literal_and_lists_every_lazy_name() -> None:
    exported = set(dynid.__all__)
    assert len(dynid.__all__) == len(exported)
    assert set(dynid._LAZY) <= exported
    eager = exported - set(dynid._LAZY)
    # names not loaded lazily are imported by dynid/__init__.py itself
    assert eager <= set(vars(dynid)), sorted(eager - set(vars(dynid)))
    for name in dynid.__all__:
        assert getattr(dynid, name) is not None
