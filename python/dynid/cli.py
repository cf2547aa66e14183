"""The ``dynid`` command line."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from . import models


def _summary() -> str:
    robot = models.kuka_lwr4()
    q = np.zeros(robot.n)
    lines = [
        f"dynid demo: {robot!r}",
        f"  total mass {robot.params[:, 0].sum():.3f} kg",
        f"  physically consistent: {robot.is_physically_consistent()}",
        "  gravity torques at q = 0 [N m]: " + np.array2string(robot.gravity(q), precision=3),
        "  diagonal of M(0) [kg m^2]: " + np.array2string(np.diag(robot.mass_matrix(q)), precision=4),
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="dynid", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("demo", help="show the built-in KUKA LWR-IV model")
    args = parser.parse_args(argv)
    if args.command == "demo":
        print(_summary())
    return 0


if __name__ == "__main__":
    sys.exit(main())
