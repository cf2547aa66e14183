"""Robot.from_urdf on large files (issue 22.9): reading is linear in the size of the URDF, and a
chain of more joints than a model file may hold is refused before any work on it.

Time is measured by the number of Python lines executed inside ``dynid.model.urdf``
(``sys.settrace``):
unlike a clock it does not depend on the machine's load, so doubling the file must double it (a
ratio of 2; 4 when every link scans every joint, as the reader did)."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from functools import partial
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
import pytest

import dynid
import dynid.cli
import dynid.model.urdf
from dynid._checks import MAX_JOINTS
from dynid.model.model_files import load_model

INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
)


def long_chain(links: int, movable: int) -> str:
    """Links l0..l{links-1}, each with an inertial, 1 mm apart along z; ``movable`` of the joints
    between them (evenly spaced, the last one on the last link) are revolute about y, the others
    fixed."""
    every = (links - 1) // movable
    revolute = {links - 1 - k * every for k in range(movable)}
    parts = [f'<link name="l{i}">{INERTIAL}</link>' for i in range(links)]
    for i in range(1, links):
        kind = "revolute" if i in revolute else "fixed"
        parts.append(
            f'<joint name="j{i}" type="{kind}"><parent link="l{i - 1}"/><child link="l{i}"/>'
            '<origin xyz="0 0 0.001"/><axis xyz="0 1 0"/></joint>'
        )
    return '<robot name="long">' + "".join(parts) + "</robot>"


class TooMuchWork(Exception):
    """Raised by the line counter past its budget (so that quadratic code fails in seconds)."""


def lines_executed(call: Callable[[], object], budget: int) -> int:
    """The number of lines of ``dynid.model.urdf``'s modules that ``call()`` executes."""
    folder = str(Path(dynid.model.urdf.__file__).parent)
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


def test_a_chain_of_more_joints_than_a_model_file_holds_is_refused(tmp_path: Path) -> None:
    """The 64-joint cap of model files (MAX_JOINTS, one constant) applies to the URDF chain: 300
    joints (the issue's URDF, on which `dynid info` ran 755 s) are refused while reading, naming
    the tip link and the count, in fewer lines than reading 64 joints costs."""
    text = long_chain(301, 300)
    with pytest.raises(ValueError, match=r"tip_link 'l300' has 300 movable joints.*at most 64"):
        dynid.Robot.from_urdf(text)

    def refuse() -> None:
        with pytest.raises(ValueError, match="at most 64"):
            dynid.Robot.from_urdf(text)

    refusal = lines_executed(refuse, 1000 * 301)
    reading = lines_executed(partial(dynid.Robot.from_urdf, long_chain(301, MAX_JOINTS)), 10**6)
    assert refusal < reading
    # the cap is the model files': MAX_JOINTS joints are read, one more is refused, either way
    assert dynid.Robot.from_urdf(long_chain(MAX_JOINTS + 1, MAX_JOINTS)).n == MAX_JOINTS
    with pytest.raises(ValueError, match=f"{MAX_JOINTS + 1} movable joints"):
        dynid.Robot.from_urdf(long_chain(MAX_JOINTS + 2, MAX_JOINTS + 1))
    rows = {"convention": "standard", "rows": [[0.1, 0.0, 0.0, 0.0]] * (MAX_JOINTS + 1)}
    (tmp_path / "model.json").write_text(json.dumps(rows))
    with pytest.raises(ValueError, match=f"at most {MAX_JOINTS} joints"):
        load_model(tmp_path / "model.json")


def test_the_command_line_refuses_the_issues_urdf(tmp_path: Path, capsys) -> None:
    path = tmp_path / "arm300.urdf"
    path.write_text(long_chain(301, 300))
    assert dynid.cli.main(["info", "--model", str(path)]) == 2
    error = capsys.readouterr().err
    assert f"{path}: urdf: the chain from 'l0' to tip_link 'l300' has 300 movable joints" in error
