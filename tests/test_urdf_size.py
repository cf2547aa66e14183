"""Robot.from_urdf on large files (issue 22.9): reading is linear in the size of the URDF, and a
chain of more joints than a model file may hold is refused before any work on it.

Time is measured by the number of Python lines executed inside ``dynid.urdf`` (``sys.settrace``):
unlike a clock it does not depend on the machine's load, so doubling the file must double it (a
ratio of 2; 4 when every link scans every joint, as the reader did)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from functools import partial
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np

import dynid
import dynid.urdf

INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
)


def long_chain(links: int, movable: int) -> str:
    """Links l0..l{links-1}, each with an inertial, 1 mm apart along z; ``movable`` of the joints
    between them (evenly spaced, the last one on the last link) are revolute about y, the others
    fixed."""
    every = (links - 1) // movable
    parts = [f'<link name="l{i}">{INERTIAL}</link>' for i in range(links)]
    for i in range(1, links):
        kind = "revolute" if (links - 1 - i) % every == 0 and i >= every else "fixed"
        parts.append(
            f'<joint name="j{i}" type="{kind}"><parent link="l{i - 1}"/><child link="l{i}"/>'
            '<origin xyz="0 0 0.001"/><axis xyz="0 1 0"/></joint>'
        )
    return '<robot name="long">' + "".join(parts) + "</robot>"


class TooMuchWork(Exception):
    """Raised by the line counter past its budget (so that quadratic code fails in seconds)."""


def lines_executed(call: Callable[[], object], budget: int) -> int:
    """The number of lines of ``dynid.urdf``'s modules that ``call()`` executes."""
    folder = str(Path(dynid.urdf.__file__).parent)
    count = 0

    def local(frame: FrameType, event: str, arg: Any) -> Any:
        nonlocal count
        if event == "line":
            count += 1
            if count > budget:
                raise TooMuchWork(f"more than {budget} lines")
        return local

    def trace(frame: FrameType, event: str, arg: Any) -> Any:
        return local if frame.f_code.co_filename.startswith(folder) else None

    previous = sys.gettrace()
    sys.settrace(trace)
    try:
        call()
    finally:
        sys.settrace(previous)
    return count


def test_the_generated_chain_is_what_it_says() -> None:
    robot = dynid.Robot.from_urdf(long_chain(101, 5))
    assert robot.n == 5
    # 1 kg per link: l0..l19 are fixed to the root (the world), l20..l100 move (81 kg)
    np.testing.assert_array_equal(robot.params[:, 0], [20.0, 20.0, 20.0, 20.0, 1.0])
    np.testing.assert_allclose(robot.fkine(np.zeros(5))[:3, 3], [0.0, 0.0, 0.1], atol=1e-12)


def test_reading_is_linear_in_the_number_of_links() -> None:
    """A 10k-link chain (6 revolute joints, the rest fixed) costs twice the lines of a 5k-link one
    (measured: 1.9997; bound 2.5; scanning every joint for each link gave 4); and at most 1000
    lines per link (measured: 286)."""
    counts = {}
    for links in (5_000, 10_000):
        read = partial(dynid.Robot.from_urdf, long_chain(links, 6))
        counts[links] = lines_executed(read, 1000 * links)
    assert counts[10_000] < 2.5 * counts[5_000], counts
