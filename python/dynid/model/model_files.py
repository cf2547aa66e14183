"""Robot models from files: a DH table in JSON or YAML (PyYAML, a dependency of dynid imported
when a YAML file is read), or a built-in name.

A model file is one object (format in ``docs/cli.md``)::

    {"name": "KUKA LWR4+", "convention": "standard", "joint_types": "RRRRRRR",
     "gravity": [0, 0, -9.81],
     "rows": [{"a": 0, "alpha": 1.5707963267948966, "d": 0.3105, "theta": 0}, ...]}

``convention`` and ``rows`` are required. Each row is an object ``{a, alpha, d, theta}``
(docs/conventions.md, "DH tables"; ``theta_offset`` is accepted for ``theta``) or a list
``[a, alpha, d, theta]``; in modified DH the names ``a_prev`` and ``alpha_prev`` (a_{i-1},
alpha_{i-1}) may replace ``a`` and ``alpha``, as in the LWR4+ tables of
``tests/data/kuka_lwr4_dh.json``. Optional: ``name``, ``joint_types`` (default all revolute),
``gravity`` (default (0, 0, -9.81)), ``base`` and ``tool`` (4x4), ``qlim`` (n x 2),
``velocity_limits`` and ``effort_limits`` (n numbers > 0 each, null for no limit), ``params`` (n x
10 standard parameters), ``Ia``, ``Fv``, ``Fs`` (n each), ``transmission`` (n x n coupling matrix T,
theta_dot = T qd; docs/transmission.md; absent means identity). Unknown fields are errors, so that a
misspelt ``gravity`` is not silently replaced by the default.

The fields, their order, which are required and which are left out at their default value come
from :mod:`dynid.model.robot_fields` (one entry per field of the robot); only the DH rows have a
format of their own here.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, Union

import numpy as np

from .._checks import MAX_JOINTS
from . import models, robot_fields
from .robot import Robot

PathLike = Union[str, Path]

#: Built-in models by name (``dynid.model.models``).
BUILTIN_MODELS: dict[str, Callable[[], Robot]] = {
    "kuka_lwr4": models.kuka_lwr4,
    "puma560": models.puma560,
    "planar_2r": models.planar_2r,
    "panda": models.panda,
    "ur5": models.ur5,
    "ur10": models.ur10,
}

FORMAT = "dynid-model"
#: Fields a model file may hold besides the model itself (ignored).
METADATA = ("format", "version", "description", "notes", "source", "units")
#: The model's fields in a file, in the order they are written (dynid.model.robot_fields).
FIELDS = tuple(f.file_key for f in robot_fields.FIELDS)
#: Row fields: the standard name, then the names accepted for it.
ROW_NAMES = {
    "standard": {"a": ("a",), "alpha": ("alpha",), "d": ("d",), "theta": ("theta", "theta_offset")},
    "modified": {
        "a": ("a", "a_prev"),
        "alpha": ("alpha", "alpha_prev"),
        "d": ("d",),
        "theta": ("theta", "theta_offset"),
    },
}
#: The names model files are written with, per convention (a_{i-1}, alpha_{i-1} in modified DH).
ROW_KEYS = {
    "standard": ("a", "alpha", "d", "theta"),
    "modified": ("a_prev", "alpha_prev", "d", "theta"),
}
YAML_SUFFIXES = (".yaml", ".yml")

#: Limits on what a file may ask for (docs/cli.md), checked before any work; the number of
#: joints, MAX_JOINTS, is shared with URDF reading (dynid._checks).
MAX_FILE_BYTES = 16 * 2**20
MAX_YAML_ALIASES = 100
MAX_EXPANDED_VALUES = 1_000_000


def load_model(
    path_or_name: PathLike, *, tip_link: str | None = None, base_link: str | None = None
) -> Robot:
    """A built-in model (``kuka_lwr4``, ``puma560``, ``planar_2r``, ``panda``, ``ur5``,
    ``ur10``), a model file (JSON/YAML) or a URDF file (``.urdf``: :meth:`Robot.from_urdf`, the
    chain from ``base_link`` (default: the root) to ``tip_link`` (default: the single leaf),
    standard DH).

    Raises FileNotFoundError for a missing file and ValueError naming the field that is missing
    or malformed (prefixed by the file name); ``tip_link`` or ``base_link`` with anything but a
    URDF is a ValueError too (a DH table has no links to choose from).
    """
    text = str(path_or_name)
    links = {k: v for k, v in (("tip_link", tip_link), ("base_link", base_link)) if v is not None}
    for key, value in links.items():
        if not isinstance(value, str) or not value:
            raise ValueError(f"{key}: expected the name of a URDF link, got {value!r}")
    if links and not text.lower().endswith(".urdf"):
        raise ValueError(f"{', '.join(links)}: only for a URDF model (.urdf), not for {text!r}")
    if text in BUILTIN_MODELS:
        return BUILTIN_MODELS[text]()
    path = Path(text)
    if not path.is_file():
        if path.suffix == "" and len(path.parts) == 1:
            raise ValueError(
                f"model: {text!r} is neither a built-in model ({', '.join(BUILTIN_MODELS)}) "
                "nor an existing file"
            )
        raise FileNotFoundError(f"model: no such file: {path}")
    try:
        if path.suffix.lower() == ".urdf":
            if path.stat().st_size > MAX_FILE_BYTES:
                raise ValueError(f"more than {MAX_FILE_BYTES} bytes: not a robot description")
            return Robot.from_urdf(path, base_link=base_link, tip_link=tip_link)
        return model_from_dict(read_structured(path))
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def save_model(robot: Robot, path: PathLike) -> Path:
    """Write ``robot`` as a model file (JSON, or YAML for .yaml/.yml).

    ``load_model`` of the file gives back the same table, transforms, limits, parameters and
    drive terms (floats are written with 17 significant digits, i.e. exactly).
    """
    path = Path(path)
    path.write_text(model_text(robot, path))
    return path


def model_text(robot: Robot, path: PathLike) -> str:
    """The content of ``robot``'s model file at ``path``: JSON, or YAML for .yaml/.yml
    (ValueError naming ``path`` for another extension)."""
    path = Path(path)
    data = model_to_dict(robot)
    if path.suffix.lower() in YAML_SUFFIXES:
        yaml = _yaml(path)
        text: str = yaml.safe_dump(data, sort_keys=False)
        return text
    if path.suffix.lower() == ".json":
        return dumps_json(data) + "\n"
    raise ValueError(f"path: unknown extension {path.suffix!r}; expected .json, .yaml or .yml")


# --------------------------------------------------------------------------- dict <-> Robot


def model_from_dict(data: Any) -> Robot:
    """A Robot from the parsed content of a model file (see the module docstring)."""
    if not isinstance(data, Mapping):
        raise ValueError(f"expected an object with the model's fields, got {type(data).__name__}")
    unknown = [str(k) for k in data if k not in FIELDS and k not in METADATA]
    if unknown:
        hint = ""
        if "rows" not in data and isinstance(data.get("dh"), Mapping):
            hint = " (the DH rows must be a top-level 'rows' list, with 'convention')"
        raise ValueError(
            f"unknown field(s) {', '.join(repr(k) for k in unknown)}{hint}; expected "
            f"{', '.join(FIELDS)}"
        )
    required = [f.file_key for f in robot_fields.FIELDS if f.required]
    for key in required:
        if key not in data:
            raise ValueError(f"{key}: missing (a model needs {' and '.join(map(repr, required))})")
    convention = data["convention"]
    if convention not in ROW_NAMES:
        raise ValueError(f"convention: expected 'standard' or 'modified', got {convention!r}")
    rows = data["rows"]
    if not isinstance(rows, list) or not rows:
        raise ValueError(f"rows: expected a non-empty list of DH rows, got {rows!r:.60}")
    if len(rows) > MAX_JOINTS:
        raise ValueError(
            f"rows: {len(rows)} DH rows; dynid model files hold at most {MAX_JOINTS} joints"
        )
    dh = np.array([_row(row, i, convention) for i, row in enumerate(rows)])
    n = len(dh)
    joint_types = data.get("joint_types", "R" * n)
    if not isinstance(joint_types, str):
        raise ValueError(f"joint_types: expected a string of R/P letters, got {joint_types!r}")
    # Every value is checked for its type and shape before the model is built; the setters then
    # check what they need (homogeneous transforms, ordered limits, an invertible T).
    values = {
        f.attribute: _value(data[f.file_key], f, n)
        for f in robot_fields.SETTABLE
        if data.get(f.file_key) is not None
    }
    robot = Robot.from_dh(dh, joint_types, convention)
    for attribute, value in values.items():
        if value is not None:
            setattr(robot, attribute, value)
    return robot


def model_to_dict(robot: Robot, identified: bool = True) -> dict[str, Any]:
    """The content of a model file for ``robot`` (JSON-ready: lists and floats).

    ``identified=False`` leaves out what identification estimates (the standard parameters and
    the drive terms Ia, Fv, Fs: the fields flagged ``identified`` in dynid.model.robot_fields): the
    model record of a least-squares result, whose values of those were only a prior."""
    fresh = robot_fields.defaults(robot)
    data: dict[str, Any] = {"format": FORMAT}
    for f in robot_fields.FIELDS:
        if (f.identified and not identified) or (
            f.omit_default and robot_fields.is_default(robot, f, fresh)
        ):
            continue
        value = getattr(robot, f.attribute)
        if f.kind == "dh":
            keys = ROW_KEYS[robot.convention]
            data[f.file_key] = [dict(zip(keys, _floats(row))) for row in value]
        elif f.kind == "text":
            data[f.file_key] = str(value)
        elif f.kind == "names":
            data[f.file_key] = [str(v) for v in value]
        elif f.kind == "limits":  # no limit (inf) is null: JSON has no infinity
            data[f.file_key] = [None if np.isinf(v) else float(v) for v in value]
        else:
            data[f.file_key] = _floats(value)
    return data


def _value(value: Any, field: robot_fields.RobotField, n: int) -> Any:
    """A settable field's value from a file: a string, a list of strings (``names``), or numbers
    of the field's shape. An empty
    text (``"name": ""``) means the default, as an absent one."""
    if field.kind == "text":
        if not isinstance(value, str):
            raise ValueError(f"{field.file_key}: expected a string, got {value!r}")
        return value or None
    if field.kind == "names":
        # the count, empty and repeated names are checked by the setter (ValueError naming it)
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise ValueError(f"{field.file_key}: expected a list of {n} strings, got {value!r:.60}")
        return value
    if field.kind == "limits":  # null: no limit (inf); the setter refuses values <= 0
        if not isinstance(value, list) or len(value) != n:
            raise ValueError(
                f"{field.file_key}: expected a list of {n} numbers or nulls, got {value!r:.60}"
            )
        return np.array(
            [
                np.inf if v is None else _number(v, f"{field.file_key}[{i}]")
                for i, v in enumerate(value)
            ]
        )
    return _numbers(value, field.file_key, field.shape_for(n))


def _row(row: Any, i: int, convention: str) -> list[float]:
    where = f"rows[{i}]"
    if isinstance(row, list):
        return _numbers(row, where, (4,)).tolist()
    if not isinstance(row, Mapping):
        raise ValueError(
            f"{where}: expected an object {{a, alpha, d, theta}} or a list of 4 numbers, "
            f"got {row!r:.60}"
        )
    names = ROW_NAMES[convention]
    accepted = {alias for aliases in names.values() for alias in aliases}
    for key in row:
        if key not in accepted:
            note = ""
            if key in ROW_NAMES["modified"]["a"] + ROW_NAMES["modified"]["alpha"]:
                note = f" ({key!r} is modified-DH notation, but convention is {convention!r})"
            raise ValueError(
                f"{where}: unknown field {key!r}{note}; expected {', '.join(sorted(accepted))}"
            )
    values = []
    for field, aliases in names.items():
        given = [alias for alias in aliases if alias in row]
        if not given:
            raise ValueError(f"{where}: missing {' or '.join(repr(a) for a in aliases)}")
        if len(given) > 1:
            raise ValueError(f"{where}: both {given[0]!r} and {given[1]!r} given for {field}")
        values.append(_number(row[given[0]], f"{where}.{given[0]}"))
    return values


def _number(value: Any, where: str) -> float:
    try:
        number = float(value) if not isinstance(value, (bool, str, bytes)) else np.nan
    except (TypeError, ValueError, OverflowError):  # OverflowError: an integer beyond 1e308
        number = np.nan
    if not isinstance(value, (int, float)) or not np.isfinite(number):
        raise ValueError(f"{where}: expected a finite number, got {value!r:.60}")
    return number


def _numbers(value: Any, where: str, shape: tuple[int, ...]) -> np.ndarray:
    """A float array of ``shape`` from nested lists of numbers (10n is accepted for (n, 10))."""
    try:
        if isinstance(value, (str, bytes)) or _has_bool(value):
            raise TypeError
        array = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        array = None
    if array is None or not (
        array.shape == shape or (shape[-1:] == (10,) and array.shape == (shape[0] * 10,))
    ):
        got = f"shape {array.shape}" if array is not None else f"{value!r:.60}"
        raise ValueError(f"{where}: expected numbers of shape {shape}, got {got}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{where}: contains NaN or inf")
    return array


def _has_bool(value: Any) -> bool:
    if isinstance(value, bool):
        return True
    return isinstance(value, list) and any(_has_bool(v) for v in value)


def _floats(value: Any) -> Any:
    return np.asarray(value, dtype=float).tolist()


# --------------------------------------------------------------------------- files


def read_structured(path: Path) -> Any:
    """The parsed content of a JSON or YAML file; ValueError with the place of a syntax error."""
    suffix = path.suffix.lower()
    if suffix not in YAML_SUFFIXES and suffix != ".json":
        raise ValueError(f"unknown extension {path.suffix!r}; expected .json, .yaml or .yml")
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise ValueError(
            f"{size} bytes is more than a model or result file can need "
            f"(limit {MAX_FILE_BYTES} bytes)"
        )
    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise ValueError("not a text file") from None
    try:
        if suffix in YAML_SUFFIXES:
            return _load_yaml(text, path)
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(
            f"not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}"
        ) from None
    except RecursionError:
        raise ValueError("nesting too deep to be a model or result file") from None


def _load_yaml(text: str, path: Path) -> Any:
    """YAML through PyYAML's safe loader, with at most MAX_YAML_ALIASES aliases: a few hundred
    bytes of nested aliases (a "billion laughs" file) would otherwise expand to gigabytes."""
    yaml = _yaml(path)

    # yaml is a module object here (imported on demand), which mypy cannot use as a base class.
    class BoundedLoader(yaml.SafeLoader):  # type: ignore[name-defined]
        aliases = 0

        def compose_node(self, parent: Any, index: Any) -> Any:
            if self.check_event(yaml.events.AliasEvent):
                self.aliases += 1
                if self.aliases > MAX_YAML_ALIASES:
                    raise ValueError(f"more than {MAX_YAML_ALIASES} YAML aliases (&/*): refused")
            return super().compose_node(parent, index)

    try:
        data = yaml.load(text, Loader=BoundedLoader)
    except yaml.YAMLError as exc:
        raise ValueError(f"not valid YAML ({exc})".replace("\n", " ")) from None
    _check_expanded_size(data)
    return data


def _check_expanded_size(data: Any) -> None:
    """Aliases share one object; counted as often as they are referenced, a file's values must
    stay below MAX_EXPANDED_VALUES (few aliases nested deeply still multiply)."""
    budget = [MAX_EXPANDED_VALUES]

    def visit(value: Any) -> None:
        budget[0] -= 1
        if budget[0] < 0:
            raise ValueError(
                f"the YAML file expands to more than {MAX_EXPANDED_VALUES} values "
                "(nested aliases): refused"
            )
        children = value.values() if isinstance(value, dict) else value
        if isinstance(value, (dict, list)):
            for child in children:
                visit(child)

    visit(data)


def _yaml(path: Path) -> Any:
    try:
        import yaml
    except ImportError:
        raise ValueError(
            f"{path.suffix} files need PyYAML, which is not installed (a dependency of dynid "
            "that this installation lacks): `pip install pyyaml`, or write the file as JSON"
        ) from None
    return yaml


def dumps_json(value: Any, indent: int = 0) -> str:
    """JSON with objects one field per line and lists of numbers (or of such lists, or of flat
    objects) on one line each: readable DH tables and parameter matrices, exact floats."""
    pad, inner = " " * indent, " " * (indent + 2)
    if isinstance(value, Mapping) and value and not _flat(value):
        items = [
            f"{inner}{json.dumps(str(k))}: {dumps_json(v, indent + 2)}" for k, v in value.items()
        ]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list) and value and not _flat(value):
        items = [inner + dumps_json(v, indent + 2) for v in value]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return json.dumps(value, allow_nan=False, separators=(", ", ": "))


def _flat(value: Any) -> bool:
    """Lists of scalars, and objects of at most 6 scalars (a DH row), go on one line."""
    scalars = (str, int, float, bool, type(None))
    items = list(value.values()) if isinstance(value, Mapping) else value
    return all(isinstance(v, scalars) for v in items) and (
        isinstance(value, list) or len(items) <= 6
    )
