"""A run that writes a result folder through ``dynid.export.output_folder.output_folder``, as every
dynid command does, for the tests of racing and killed runs (test_output_folder.py):

    python output_writer.py TARGET LABEL --signals DIR [--overwrite] [--wait PATH ...] [--hold]

It writes ``label.txt`` (LABEL) and ``data.bin`` (``content(LABEL)``, 1 MiB) into the staging
folder, creates ``DIR/LABEL.staged``, waits until every ``--wait PATH`` exists (or, with
``--hold``, forever: to be killed), then leaves the block, which moves the folder into place.
Exit status 0 when it did, 2 with one line ``error: ...`` on a ValueError (as the CLI does),
3 when a wait timed out.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from dynid.export.output_folder import output_folder

#: How long a wait may last before the run gives up (exit 3): far beyond the tests' needs.
TIMEOUT = 30.0


def content(label: str) -> bytes:
    """The 1 MiB of ``data.bin`` of run ``label``: different for every label."""
    return (label.encode() + b"\0" + bytes(range(256))) * ((1 << 20) // (len(label) + 257)) + b"."


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("target")
    parser.add_argument("label")
    parser.add_argument("--signals", required=True)
    parser.add_argument("--overwrite", action="store_true")
    parser.add_argument("--wait", action="append", default=[])
    parser.add_argument("--hold", action="store_true")
    args = parser.parse_args()
    try:
        with output_folder(args.target, args.overwrite) as staging:
            (staging / "label.txt").write_text(args.label)
            (staging / "data.bin").write_bytes(content(args.label))
            (Path(args.signals) / f"{args.label}.staged").touch()
            deadline = time.monotonic() + TIMEOUT
            while args.hold or not all(Path(p).exists() for p in args.wait):
                if time.monotonic() > deadline:
                    print(f"error: timed out waiting for {args.wait}", file=sys.stderr)
                    return 3
                time.sleep(0.01)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
