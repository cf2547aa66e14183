"""The ``dynid`` command line."""

from __future__ import annotations

import argparse
import sys

from .demo import run_demo


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="dynid", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    demo = commands.add_parser(
        "demo", help="the KUKA LWR-IV identification of Gaz et al. (ICRA 2014) on a simulated arm"
    )
    demo.add_argument("--output", default="dynid-demo", help="output folder (default ./dynid-demo)")
    demo.add_argument("--train", type=int, default=1000, help="training configurations")
    demo.add_argument("--validation", type=int, default=200, help="validation configurations")
    demo.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    if args.command == "demo":
        run_demo(args.output, train=args.train, validation=args.validation, seed=args.seed)
    return 0


if __name__ == "__main__":
    sys.exit(main())
