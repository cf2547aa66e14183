"""``dynid``'s entry point: parse, run one command, turn user errors into one line and exit 2."""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Callable
from typing import Any

from ..errors import PhysicalIdentificationError
from .parsers import build_parser
from .run_config import with_config

#: Exit status for bad input (missing file, malformed log, model or result), as argparse's.
EXIT_BAD_INPUT = 2


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    # parse_args would report an unknown option of a command with the top-level usage ("dynid
    # [-h] {demo,identify,...}"), which does not say which command's options to look at.
    args, unknown = parser.parse_known_args(argv)
    if unknown:
        args.command_parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    args = with_config(parser, args, argv)  # --config FILE: its options, the command line's first
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always", UserWarning)
            warnings.showwarning = _one_line_warning(args.command)
            args.run(args)
    except BrokenPipeError:  # output piped into e.g. `head`: stop quietly
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 -- the interpreter closes it at exit
        return 1
    except KeyboardInterrupt:
        print(f"dynid {args.command}: interrupted", file=sys.stderr)
        return 130
    except (
        ValueError,
        OSError,
        OverflowError,
        MemoryError,
        RecursionError,
        PhysicalIdentificationError,
    ) as exc:
        # A user error (a file, a field, a value): one line naming it, never a traceback.
        # RecursionError: absurdly deep nesting in a JSON/YAML file; MemoryError: a file
        # asking for more than the machine has.
        message = " ".join(str(exc).split()) or type(exc).__name__
        print(f"dynid {args.command}: error: {message}", file=sys.stderr)
        return EXIT_BAD_INPUT
    return 0


def _one_line_warning(command: str) -> Callable[..., None]:
    """Print a warning when it happens, as one line without Python's file and line."""

    def show(message: Warning | str, *_: Any, **__: Any) -> None:
        print(f"dynid {command}: warning: {message}", file=sys.stderr, flush=True)

    return show
