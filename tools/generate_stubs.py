#!/usr/bin/env python3
"""Generate ``python/dynid/_core.pyi``, the type stub of the compiled module ``dynid._core``.

Usage (from the repository root, with dynid installed and the ``dev`` extra)::

    python tools/generate_stubs.py            # (re)write python/dynid/_core.pyi
    python tools/generate_stubs.py --check    # exit 1 if the committed stub is out of date

pybind11-stubgen reads the signatures pybind11 writes into the docstrings. The Model's dynamics
calls arrive typed: their signature line is written from the call table
(``cpp/bindings/call_table.hpp``, ``typed_signature`` in ``calls.cpp``), so their stubs follow the
table. The other bindings take ``py::handle`` arguments (they convert and check them in C++ to
name the argument in errors), so those arrive as ``typing.Any``; the tables below give each such
argument its real type by name,
and every returned ``numpy.ndarray`` becomes ``NDArray[numpy.float64]`` (the core only returns
float64 arrays). An argument or return value of a new binding that is not in the tables stays
``typing.Any`` and is reported: add it to the tables and rerun (``--strict`` makes that an
error). The result is formatted with ruff, so the stub passes the project's lint as generated.
"""

from __future__ import annotations

import argparse
import difflib
import inspect
import re
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
STUB = ROOT / "python" / "dynid" / "_core.pyi"
MODULE = "dynid._core"

ARRAY = "numpy.typing.NDArray[numpy.float64]"
ARRAY_LIKE = "numpy.typing.ArrayLike"

# Arguments the bindings take as py::handle, by name; (class, function, name) or (function, name)
# entries override the plain name.
ARGUMENT_TYPES: dict[str | tuple[str, ...], str] = {
    # samples: one (n,) or T of them (T, n)
    "q": ARRAY_LIKE,
    "qd": ARRAY_LIKE,
    "qdd": ARRAY_LIKE,
    "qddd": ARRAY_LIKE,
    "qdddd": ARRAY_LIKE,
    "tau": ARRAY_LIKE,
    # batch outputs: a preallocated result array, the regressor's selected columns
    "out": f"{ARRAY} | None",
    "columns": f"{ARRAY_LIKE} | None",
    ("_sincos", "x"): ARRAY_LIKE,
    # second-order-section filter (dynid._iir checks and passes these)
    ("_sos_filter", "sections"): ARRAY_LIKE,
    ("_sos_filter", "x"): ARRAY_LIKE,
    ("_sos_filter", "state"): ARRAY_LIKE,
    # model geometry and bodies
    "dh": ARRAY_LIKE,
    "gravity": ARRAY_LIKE,
    "base": ARRAY_LIKE,
    "tool": ARRAY_LIKE,
    "com": ARRAY_LIKE,
    "inertia_com": ARRAY_LIKE,
    "params": ARRAY_LIKE,
    # flags and counts
    "rotor": "bool",
    "friction": "bool",
    "history": "bool",
    "threads": "int",
    "p": "int",
    # recursive least squares
    "Y_k": ARRAY_LIKE,
    "tau_k": ARRAY_LIKE,
    "Y": ARRAY_LIKE,
    "theta0": ARRAY_LIKE,
    "initial_covariance": f"float | {ARRAY_LIKE}",
    "forgetting": "float",
    "max_variance": "float",
    "memo": "dict[int, typing.Any]",
    # momentum observer
    ("MomentumObserver", "__init__", "gain"): f"float | {ARRAY_LIKE}",
    ("MomentumObserver", "__init__", "dt"): "float",
    # closed-loop simulation (dynid.sim.simulate checks and passes these)
    "q0": ARRAY_LIKE,
    "qd0": ARRAY_LIKE,
    ("_simulate", "model"): "Model | None",
    ("_simulate", "kp"): f"{ARRAY_LIKE} | None",
    ("_simulate", "kd"): f"{ARRAY_LIKE} | None",
    ("_simulate", "q_d"): f"{ARRAY_LIKE} | None",
    ("_simulate", "qd_d"): f"{ARRAY_LIKE} | None",
    ("_simulate", "qdd_d"): f"{ARRAY_LIKE} | None",
    ("_simulate", "function"): (f"typing.Callable[[float, {ARRAY}, {ARRAY}], {ARRAY_LIKE}] | None"),
    # elastic-joint simulation (dynid.sim.simulate_elastic checks and passes these)
    "stiffness": ARRAY_LIKE,
    "motor_inertia": ARRAY_LIKE,
    "motor_viscous": ARRAY_LIKE,
    "motor_coulomb": ARRAY_LIKE,
    "thetad0": ARRAY_LIKE,
    ("_simulate_elastic", "theta0"): ARRAY_LIKE,
    ("_simulate_elastic", "kp"): ARRAY_LIKE,
    ("_simulate_elastic", "kd"): ARRAY_LIKE,
    ("_simulate_elastic", "q_d"): ARRAY_LIKE,
    ("_simulate_elastic", "function"): (
        f"typing.Callable[[float, {ARRAY}, {ARRAY}, {ARRAY}, {ARRAY}, {ARRAY}], "
        f"{ARRAY_LIKE}] | None"
    ),
    ("_simulate_elastic_kuka", "theta0"): ARRAY_LIKE,
    ("_simulate_elastic_kuka", "model_stiffness"): ARRAY_LIKE,
    ("_simulate_elastic_kuka", "kp"): ARRAY_LIKE,
    ("_simulate_elastic_kuka", "kd"): ARRAY_LIKE,
    ("_simulate_elastic_kuka", "torque_gain"): ARRAY_LIKE,
    ("_simulate_elastic_kuka", "torque_damping"): ARRAY_LIKE,
    ("_simulate_elastic_kuka", "q_d"): ARRAY_LIKE,
    ("_simulate_elastic_kuka", "qd_d"): ARRAY_LIKE,
    ("_simulate_elastic_kuka", "tau_user"): f"{ARRAY_LIKE} | None",
    # the laws' core functions (cpp/bindings/laws.cpp)
    "coulomb_band": "float",
    "thetad": ARRAY_LIKE,
    "thetadd": ARRAY_LIKE,
    "tau_J": ARRAY_LIKE,
    ("_asymmetric_friction_columns", "offset"): "bool",
}

# Property setters (their single argument is unnamed in pybind11), by property name.
SETTER_TYPES: dict[str, str] = {
    "gravity_vector": ARRAY_LIKE,
    "base": ARRAY_LIKE,
    "tool": ARRAY_LIKE,
    "params": ARRAY_LIKE,
    "Ia": ARRAY_LIKE,
    "Fv": ARRAY_LIKE,
    "Fs": ARRAY_LIKE,
    "transmission": f"{ARRAY_LIKE} | None",
    "gear_ratios": ARRAY_LIKE,
    "joint_offsets": ARRAY_LIKE,
    "name": "str",
    "joint_names": "typing.Sequence[str]",
    "link_names": "typing.Sequence[str]",
    "qlim": ARRAY_LIKE,
    "velocity_limits": ARRAY_LIKE,
    "effort_limits": ARRAY_LIKE,
    "forgetting": "float",
    "max_variance": "float | None",
}

# Functions returning py::object: a number for one sample, an array for a batch.
RETURN_TYPES: dict[str | tuple[str, ...], str] = {
    "kinetic_energy": f"float | {ARRAY}",
    "potential_energy": f"float | {ARRAY}",
}

# Functions whose pybind11 return annotation contains typing.Any (a py::object element).
RETURN_REPLACEMENTS: dict[str, tuple[str, str]] = {
    # q, qd, qdd, tau and the measured q (None unless recorded)
    "_simulate": ("typing.Any]", f"{ARRAY} | None]"),
    # a py::tuple of n strings
    "joint_names": ("tuple", "tuple[str, ...]"),
    "link_names": ("tuple", "tuple[str, ...]"),
}

DEF = re.compile(
    r"^(?P<indent>\s*)def (?P<name>\w+)\((?P<params>.*)\) -> (?P<ret>.+):(?P<rest>.*)$"
)
CLASS = re.compile(r"^class (?P<name>\w+)\b")
SETTER = re.compile(r"^\s*@(?P<name>\w+)\.setter\s*$")
HEADER = (
    "# Generated by tools/generate_stubs.py from the compiled module (pybind11-stubgen, then\n"
    "# typed by argument name); rerun it after changing cpp/bindings/ instead of editing this\n"
    "# file.\n"
)


def split_top_level(text: str) -> list[str]:
    """Split a parameter list at the commas outside brackets and quotes."""
    parts: list[str] = []
    depth = 0
    quote = ""
    start = 0
    for i, ch in enumerate(text):
        if quote:
            if ch == quote and text[i - 1] != "\\":
                quote = ""
        elif ch in "'\"":
            quote = ch
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    if text[start:].strip():
        parts.append(text[start:].strip())
    return parts


def lookup(table: dict[str | tuple[str, ...], str], cls: str, func: str, name: str) -> str | None:
    for key in ((cls, func, name), (func, name), name):
        if key in table:
            return table[key]
    return None


def type_parameter(param: str, cls: str, func: str, setter: str | None, unknown: list[str]) -> str:
    match = re.match(r"^(?P<name>\w+): (?P<type>.+?)(?: = (?P<default>.+))?$", param)
    if match is None or match["type"] != "typing.Any":
        return param
    name, default = match["name"], match["default"]
    new = SETTER_TYPES.get(setter) if setter else lookup(ARGUMENT_TYPES, cls, func, name)
    if new is None:
        where = f"{cls}.{func}" if cls else func
        unknown.append(
            f"argument {name!r} of {where}" + (f" (setter of {setter})" if setter else "")
        )
        return param
    if default == "None" and "None" not in new:
        new += " | None"
    return f"{name}: {new}" + (f" = {default}" if default is not None else "")


def polish(text: str) -> tuple[str, list[str]]:
    """Give the generated stub its real argument and return types; list what stayed Any."""
    unknown: list[str] = []
    out: list[str] = []
    cls = ""
    setter: str | None = None
    for line in text.splitlines():
        if m := CLASS.match(line):
            cls = m["name"]
        elif line.startswith("def "):
            cls = ""
        if m := SETTER.match(line):
            setter = m["name"]
            out.append(line)
            continue
        if line.rstrip().endswith("(*args, **kwargs):"):
            # The full pybind11 methods behind the fast single-call path (Model._rnea_full, ...):
            # they take whatever the public method takes.
            out.append(
                line.replace(
                    "(*args, **kwargs):", "(*args: typing.Any, **kwargs: typing.Any) -> typing.Any:"
                )
            )
            continue
        if m := DEF.match(line):
            func = m["name"]
            params = [
                type_parameter(p, cls, func, setter, unknown) for p in split_top_level(m["params"])
            ]
            ret = m["ret"].replace("numpy.ndarray", ARRAY)
            if func in RETURN_REPLACEMENTS:
                ret = ret.replace(*RETURN_REPLACEMENTS[func])
            if "typing.Any" in ret and ret != "typing.Any":
                unknown.append(f"return value of {cls + '.' if cls else ''}{func} ({ret})")
            if ret == "typing.Any":
                new = lookup(RETURN_TYPES, cls, func, func)
                if new is None:
                    unknown.append(f"return value of {cls + '.' if cls else ''}{func}")
                else:
                    ret = new
            line = f"{m['indent']}def {func}({', '.join(params)}) -> {ret}:{m['rest']}"
            setter = None
        out.append(line.replace("numpy.ndarray", ARRAY))
    polished = "\n".join(out) + "\n"
    # The header goes after the module docstring (stubgen writes it first).
    marker = "from __future__ import annotations"
    return polished.replace(marker, HEADER + marker, 1), unknown


def _no_text_signature(getfullargspec: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """getfullargspec that refuses the bound functions, as it did before _core gave them a
    __text_signature__ (cpp/bindings/text_signatures.cpp): pybind11-stubgen then reads the typed
    signature pybind11 writes into the docstring instead of the untyped text signature."""

    def refuse_builtins(func: Any) -> Any:
        if getattr(func, "__text_signature__", None) is not None:
            raise TypeError("a builtin: read the pybind11 docstring")
        return getfullargspec(func)

    return refuse_builtins


def run_stubgen() -> str:
    import pybind11_stubgen

    with tempfile.TemporaryDirectory() as tmp:
        original = inspect.getfullargspec
        inspect.getfullargspec = _no_text_signature(original)
        try:
            pybind11_stubgen.main([MODULE, "-o", tmp, "--exit-code"])
        finally:
            inspect.getfullargspec = original
        return (Path(tmp) / (MODULE.replace(".", "/") + ".pyi")).read_text()


def ruff(args: list[str], text: str) -> str:
    result = subprocess.run(
        [sys.executable, "-m", "ruff", *args, "--stdin-filename", str(STUB), "-"],
        input=text,
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=False,
    )
    if result.returncode not in (0, 1):  # 1: lint findings left (they are printed by --check)
        sys.exit(f"ruff {' '.join(args)} failed:\n{result.stderr}")
    return result.stdout


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="compare with the committed stub")
    parser.add_argument("--strict", action="store_true", help="fail on arguments left as Any")
    args = parser.parse_args()

    stub, unknown = polish(run_stubgen())
    stub = ruff(["check", "--fix-only", "--exit-zero"], stub)
    stub = ruff(["format"], stub)
    for item in unknown:
        print(f"generate_stubs: {item} is typing.Any; add it to the tables", file=sys.stderr)

    if args.check:
        current = STUB.read_text() if STUB.exists() else ""
        if current != stub:
            diff = difflib.unified_diff(
                current.splitlines(keepends=True),
                stub.splitlines(keepends=True),
                str(STUB.relative_to(ROOT)),
                "generated",
            )
            sys.stdout.writelines(diff)
            print(f"{STUB.relative_to(ROOT)} is out of date: run python tools/generate_stubs.py")
            return 1
    else:
        STUB.write_text(stub)
        print(f"wrote {STUB.relative_to(ROOT)}")
    return 1 if args.strict and unknown else 0


if __name__ == "__main__":
    sys.exit(main())
