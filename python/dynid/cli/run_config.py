"""A command's options from a YAML file (``--config run.yaml``) and back (each result folder's
``run.yaml``), so that a run can be replayed (docs/cli.md, "Replaying a run").

The keys are the command's options as on the command line without the dashes (``tip-link`` or
``tip_link``), the logs under ``log``; the options given on the command line override the file.
A key the command does not have is an error naming it, and each value is checked as argparse
would check the option (type, choices). ``command``, ``dynid_version`` and ``working_directory``
are what the written file records besides the options: the command it belongs to, the version
that wrote it (another version is a warning: the result may differ) and the directory relative
paths were given in.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path
from typing import Any

from .._version import dynid_version

#: The file written into each result folder.
RUN_FILE = "run.yaml"
#: Keys a run file holds besides the options.
METADATA = ("command", "dynid_version", "working_directory")
#: Options never read from or written to a run file.
NOT_OPTIONS = ("help", "config")


def with_config(
    parser: argparse.ArgumentParser, args: argparse.Namespace, argv: list[str] | None
) -> argparse.Namespace:
    """``args`` again, parsed with the options of ``args.config`` as the command's defaults (so
    that the command line overrides them); ``args`` itself when no ``--config`` was given. A bad
    file is the command's usage error (exit 2)."""
    path = getattr(args, "config", None)
    if path is None:
        return args
    command: argparse.ArgumentParser = args.command_parser
    try:
        # Before main()'s handler of warnings: printed here as it prints them, one line each.
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            defaults = read_config(path, command, args.command)
    except (ValueError, OSError) as exc:
        command.error(f"--config {path}: {' '.join(str(exc).split())}")
    for warning in caught:
        print(f"dynid {args.command}: warning: {warning.message}", file=sys.stderr, flush=True)
    command.set_defaults(**defaults)
    again, _ = parser.parse_known_args(argv)
    return again


def read_config(path: str | Path, command: argparse.ArgumentParser, name: str) -> dict[str, Any]:
    """The options of the run file ``path`` for the command ``name`` (its parser ``command``),
    by destination, checked as argparse checks them."""
    from ..model.model_files import read_structured

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    if path.suffix.lower() not in (".yaml", ".yml", ".json"):
        raise ValueError(f"expected a .yaml, .yml or .json file, got {path.suffix!r}")
    data = read_structured(path)
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ValueError(f"expected a mapping of options, got {type(data).__name__}")
    actions = _options(command)
    keys: dict[str, Any] = {}
    for key in data:
        dest = str(key).replace("-", "_")
        if dest in keys:
            raise ValueError(f"{keys[dest]}, {key}: the same option twice")
        keys[dest] = key
    unknown = sorted(
        str(key) for dest, key in keys.items() if dest not in actions and dest not in METADATA
    )
    if unknown:
        raise ValueError(
            f"unknown key(s) {', '.join(unknown)}; `dynid {name}` has {', '.join(sorted(actions))}"
        )
    if "command" in keys and data[keys["command"]] != name:
        raise ValueError(f"command: this file is for `dynid {data[keys['command']]}`, not {name}")
    version = data.get(keys.get("dynid_version", "dynid_version"))
    if version is not None and str(version) != dynid_version():
        warnings.warn(
            f"{path}: written by dynid {version}, this is {dynid_version()}: the result may differ",
            UserWarning,
            stacklevel=2,
        )
    options = {
        dest: _value(actions[dest], data[key], key)
        for dest, key in keys.items()
        if dest not in METADATA
    }
    where = data.get(keys.get("working_directory", "working_directory"))
    if isinstance(where, str):
        _check_relative_paths(options, Path(where))
    return options


def _check_relative_paths(options: dict[str, Any], where: Path) -> None:
    """A warning for each relative path of the file that is missing here but exists in the
    directory the run was made in (replayed from another directory)."""
    for dest, value in options.items():
        for item in value if isinstance(value, list) else [value]:
            if not isinstance(item, str) or not item or Path(item).is_absolute():
                continue
            if not Path(item).exists() and (where / item).exists():
                warnings.warn(
                    f"{dest}: {item} is not in the current directory but in {where}, where "
                    "the run was made (relative paths are taken from the current directory): "
                    "replay it from there",
                    UserWarning,
                    stacklevel=3,
                )


def run_yaml(args: argparse.Namespace, **resolved: Any) -> str:
    """The run file of ``args``: every option of the command (its value, or its default when
    not given; ``resolved`` replaces defaults that the command works out, such as ``method``),
    the command, the dynid version and the working directory, as YAML."""
    import yaml  # a dependency of dynid (pyproject.toml)

    options = {
        dest: resolved.get(dest, getattr(args, dest)) for dest in _options(args.command_parser)
    }
    data = {
        "command": args.command,
        "dynid_version": dynid_version(),
        "working_directory": os.getcwd(),
        **{k: list(v) if isinstance(v, tuple) else v for k, v in options.items()},
    }
    head = (
        f"# dynid {args.command}: every option of this run; replay it with\n"
        f"#   dynid {args.command} --config {RUN_FILE} --output NEW_FOLDER\n"
        "# (relative paths are relative to working_directory; options on the command line\n"
        "# override the values here)\n"
    )
    return head + yaml.safe_dump(data, sort_keys=False, default_flow_style=None)


def _options(command: argparse.ArgumentParser) -> dict[str, argparse.Action]:
    """The command's options by destination, in the parser's order."""
    return {
        action.dest: action
        for action in command._actions
        if action.dest not in NOT_OPTIONS and action.dest is not argparse.SUPPRESS
    }


def _value(action: argparse.Action, value: Any, key: str) -> Any:
    """``value`` of the option ``action`` from a file, checked (and converted) as argparse
    checks a value from the command line; ValueError naming ``key``."""
    flags = (argparse._StoreTrueAction, argparse._StoreFalseAction, argparse.BooleanOptionalAction)
    if isinstance(action, flags):
        if value is None and action.default is None:  # a three-way --x/--no-x left unset
            return None
        if not isinstance(value, bool):
            raise ValueError(f"{key}: expected true or false, got {value!r}")
        return value
    if action.nargs in ("*", "+"):
        items = [value] if isinstance(value, str) else value
        if not isinstance(items, list) or not all(isinstance(v, str) for v in items):
            raise ValueError(f"{key}: expected a path or a list of paths, got {value!r}")
        return items
    if value is None:
        if action.default is not None:
            raise ValueError(f"{key}: expected a value (default {action.default!r}), got null")
        return None
    if action.type is int:
        if not isinstance(value, int) or isinstance(value, bool):
            raise ValueError(f"{key}: expected an integer, got {value!r}")
    elif action.type is float:
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise ValueError(f"{key}: expected a number, got {value!r}")
        value = float(value)
    elif callable(action.type):  # a parser's own type (--method, --rest-velocity): its check
        if isinstance(value, list) and all(_number(v) for v in value):  # --kp 1,2 as a list
            value = ",".join(repr(float(v)) for v in value)
        if isinstance(value, bool) or not isinstance(value, (str, int, float)):
            raise ValueError(f"{key}: expected a string or a number, got {value!r}")
        try:
            value = action.type(str(value))
        except (argparse.ArgumentTypeError, ValueError) as exc:
            raise ValueError(f"{key}: {exc}") from None
    elif not isinstance(value, str):
        raise ValueError(f"{key}: expected a string, got {value!r}")
    if action.choices is not None and value not in action.choices:
        raise ValueError(
            f"{key}: expected one of {', '.join(map(str, action.choices))}, got {value!r}"
        )
    return value


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)
