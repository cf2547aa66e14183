"""Result folders under misuse, races and kills (issue 22, items 7 and 8), on real folders and
real processes: ``--overwrite`` replaces only a folder that dynid wrote and that holds no input
of the run; of two runs racing for one ``--output`` without ``--overwrite`` the second to finish
fails and the first result survives byte for byte; a run killed with SIGKILL leaves the target as
it was, and the next run on that target removes the killed run's staging folder and nothing else.
The racing and killed runs are subprocesses of ``output_writer.py``, which writes through
``output_folder`` as every dynid command does; they are ordered by files they wait for, not by
sleeps, so the outcome does not depend on the machine's load."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import dynid
from dynid.cli import main
from dynid.export.output_folder import check_output_path, output_folder
from dynid.logs import save_log
from output_writer import content
from test_log_identification import fourier_log

WRITER = Path(__file__).with_name("output_writer.py")
#: The file that marks a folder as written by dynid (docs/cli.md).
MARKER = ".dynid-output.json"


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (relative path: content)."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


@pytest.fixture
def data(tmp_path: Path) -> Path:
    """A folder of the user's: a 2 s log of a planar 2R arm and a notes file."""
    folder = tmp_path / "data"
    folder.mkdir()
    save_log(fourier_log(dynid.models.planar_2r(), 1, seconds=2.0), folder / "log.npz")
    (folder / "notes.txt").write_text("the user's notes")
    return folder


def identify(log: Path, output: Path, *options: str) -> int:
    return main(["identify", str(log), "--model", "planar_2r", "--output", str(output), *options])


# --------------------------------------------------------------------------- item 7


def test_overwrite_refuses_the_folder_of_an_input(data: Path, capsys) -> None:
    """`identify data/log.npz --output data --overwrite` deleted the log and every other file of
    data/ (exit 0). Refused, exit 2, one line naming --output and the input; for the log's folder
    and for an ancestor of it, nothing is touched."""
    before = snapshot(data.parent)
    for output in (data, data.parent):
        assert identify(data / "log.npz", output, "--overwrite") == 2
        error = capsys.readouterr().err
        assert error.startswith("dynid identify: error: output:"), error
        assert "--output" in error and "log.npz" in error and "Traceback" not in error
    assert snapshot(data.parent) == before


def test_overwrite_refuses_a_dynid_folder_that_holds_an_input(data: Path, tmp_path, capsys) -> None:
    """A dynid result folder is refused too when an input of the run is in it: a log copied
    into it, or the folder itself (`validate RUN LOG --output RUN --overwrite` would delete the
    result it applies)."""
    run = tmp_path / "run"
    assert identify(data / "log.npz", run) == 0
    (run / "log.npz").write_bytes((data / "log.npz").read_bytes())
    before = snapshot(run)
    capsys.readouterr()
    assert identify(run / "log.npz", run, "--overwrite") == 2
    assert "log.npz" in capsys.readouterr().err
    argv = ["validate", str(run), str(data / "log.npz"), "--output", str(run), "--overwrite"]
    assert main(argv) == 2
    error = capsys.readouterr().err
    assert error.startswith("dynid validate: error: output:") and "--output" in error
    assert snapshot(run) == before


def test_overwrite_refuses_a_folder_dynid_did_not_write(data: Path, tmp_path, capsys) -> None:
    """A folder without dynid's marker (the user's, or written by hand) is refused with
    --overwrite, whatever its files; an empty one is used, with or without --overwrite."""
    mine = tmp_path / "mine"
    (mine / "sub").mkdir(parents=True)
    (mine / "result.json").write_text("{}")
    (mine / "sub" / "thesis.tex").write_text("months of work")
    before = snapshot(mine)
    assert identify(data / "log.npz", mine, "--overwrite") == 2
    error = capsys.readouterr().err
    assert error.startswith("dynid identify: error: output:") and "not written by dynid" in error
    assert "--output" in error and "Traceback" not in error
    assert snapshot(mine) == before
    empty = tmp_path / "empty"
    empty.mkdir()
    assert identify(data / "log.npz", empty, "--overwrite") == 0
    assert (empty / "result.json").is_file() and (empty / MARKER).is_file()


def test_overwrite_replaces_a_previous_result(data: Path, tmp_path) -> None:
    """A folder dynid wrote is replaced as a whole (a file the user added is gone), and nothing
    but the result is left beside it."""
    run = tmp_path / "run"
    assert identify(data / "log.npz", run) == 0
    assert (run / MARKER).is_file()
    (run / "stray.txt").write_text("added by hand")
    assert identify(data / "log.npz", run, "--friction", "--overwrite") == 0
    assert sorted(p.name for p in run.iterdir()) == sorted(
        [MARKER, "result.json", "run.yaml", "torques.png", "residuals.png", "report.html"]
    )
    assert dynid.load_result(run).friction
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data", "run"]  # no staging debris


# --------------------------------------------------------------------------- item 8


def start_writer(target: Path, label: str, signals: Path, *options: str) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path), OPENBLAS_NUM_THREADS="1")
    return subprocess.Popen(
        [sys.executable, str(WRITER), str(target), label, "--signals", str(signals), *options],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


def wait_for(path: Path, process: subprocess.Popen, timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while not path.exists():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, f"{path} did not appear"
        time.sleep(0.01)


def finish(process: subprocess.Popen) -> tuple[int, str]:
    _, err = process.communicate(timeout=30)
    return process.returncode, err


def assert_holds(target: Path, label: str) -> None:
    """``target`` is the complete result of run ``label`` (its files, byte for byte)."""
    files = snapshot(target)
    assert set(files) == {"label.txt", "data.bin", MARKER}, sorted(files)
    assert files["label.txt"] == label.encode() and files["data.bin"] == content(label)


@pytest.mark.parametrize("existing", ["absent", "empty folder"])
def test_two_racing_runs_keep_the_first_result(tmp_path: Path, existing: str) -> None:
    """Two runs check the same target, both stage their files, A moves its folder into place,
    then B tries: B fails with one line naming the target and the first result survives (B's
    replaced it: both exited 0). Also when the target was an empty folder, which both accept."""
    target, signals = tmp_path / "out", tmp_path / "signals"
    signals.mkdir()
    if existing == "empty folder":
        target.mkdir()
    a = start_writer(target, "A", signals, "--wait", str(signals / "B.staged"))
    b = start_writer(
        target,
        "B",
        signals,
        "--wait",
        str(signals / "A.staged"),
        "--wait",
        str(target / "label.txt"),
    )
    assert finish(a) == (0, "")
    status, error = finish(b)
    assert status == 2, error
    assert error.startswith("error: output:") and str(target) in error and "meanwhile" in error
    assert_holds(target, "A")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "signals"]  # B's staging removed


def test_two_racing_runs_with_overwrite_leave_one_whole_result(tmp_path: Path) -> None:
    """With --overwrite the second to finish replaces the first's result as a whole."""
    target, signals = tmp_path / "out", tmp_path / "signals"
    signals.mkdir()
    a = start_writer(target, "A", signals, "--overwrite", "--wait", str(signals / "B.staged"))
    b = start_writer(target, "B", signals, "--overwrite", "--wait", str(target / "label.txt"))
    assert finish(a) == (0, "")
    assert finish(b) == (0, "")
    assert_holds(target, "B")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "signals"]


def test_a_killed_run_leaves_the_target_and_the_next_run_removes_its_debris(tmp_path: Path) -> None:
    """A run killed (SIGKILL) while staging leaves the previous result intact and a hidden
    `.out.*.partial` folder; the next run on `out` removes it, but not the staging folder of a
    run still writing (which then completes), nor anything else that is not such a folder."""
    target, signals = tmp_path / "out", tmp_path / "signals"
    signals.mkdir()
    with output_folder(target) as staging:
        (staging / "label.txt").write_text("first")
        (staging / "data.bin").write_bytes(content("first"))
    killed = start_writer(target, "killed", signals, "--overwrite", "--hold")
    live = start_writer(target, "live", signals, "--overwrite", "--wait", str(signals / "go"))
    wait_for(signals / "killed.staged", killed)
    wait_for(signals / "live.staged", live)
    killed.send_signal(signal.SIGKILL)
    killed.wait(timeout=30)
    assert_holds(target, "first")
    debris = sorted(p.name for p in tmp_path.glob(".out.*.partial"))
    assert len(debris) == 2  # the killed run's and the live run's
    others = [".out.notes", ".out.0123abcd.old", ".other.0123abcd.partial", "out.0123abcd.partial"]
    for name in others:
        (tmp_path / name).mkdir()
        (tmp_path / name / "keep").write_text(name)

    with output_folder(target, overwrite=True) as staging:
        (staging / "label.txt").write_text("next")
        (staging / "data.bin").write_bytes(content("next"))
    assert_holds(target, "next")
    remaining = sorted(p.name for p in tmp_path.glob(".out.*.partial"))
    assert len(remaining) == 1 and remaining[0] in debris  # the live run's
    (signals / "go").touch()
    assert finish(live) == (0, "")
    assert_holds(target, "live")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["out", "signals", *others])
    assert all((tmp_path / name / "keep").read_text() == name for name in others)


def test_results_are_synced_before_they_are_moved_into_place(tmp_path: Path, monkeypatch) -> None:
    """Every file and folder of a result is fsync'ed before the rename that publishes it, and
    the parent folder after it, so that a power cut leaves the old result or the whole new one
    (a rename can reach the disk before the data it names). Nothing was synced."""
    if not Path("/proc/self/fd").is_dir():
        pytest.skip("needs /proc/self/fd to name the synced descriptors")
    events: list[tuple[str, str]] = []
    fsync, rename = os.fsync, os.rename

    def spy_fsync(fd: int) -> None:
        events.append(("fsync", os.readlink(f"/proc/self/fd/{fd}")))
        fsync(fd)

    def spy_rename(source: str, destination: str, **kwargs: object) -> None:
        rename(source, destination, **kwargs)
        events.append(("rename", os.path.realpath(destination)))

    monkeypatch.setattr(os, "fsync", spy_fsync)
    monkeypatch.setattr(os, "rename", spy_rename)
    target = tmp_path / "out"
    with output_folder(target) as staging:
        (staging / "a.json").write_text("{}")
        (staging / "sub").mkdir()
        (staging / "sub" / "b.png").write_bytes(b"png")
        staged = os.path.realpath(staging)
    published = events.index(("rename", os.path.realpath(target)))
    synced = {path for kind, path in events[:published] if kind == "fsync"}
    expected = {"a.json", "sub", "sub/b.png", MARKER, "."}
    assert {os.path.relpath(path, staged) for path in synced} >= expected
    assert ("fsync", os.path.realpath(tmp_path)) in events[published:]


def test_overwrite_without_rename_exchange(tmp_path: Path, monkeypatch) -> None:
    """Where renameat2 RENAME_EXCHANGE is missing (C library, kernel or file system), the old
    folder is renamed aside and the new one moved in: the same result, no debris."""
    import dynid.export.output_folder as module

    def missing(a: Path, b: Path) -> None:
        raise OSError(errno.ENOSYS, "renameat2: not in this C library")

    target = tmp_path / "out"
    for label in ("first", "second"):
        with output_folder(target, overwrite=True) as staging:
            (staging / "label.txt").write_text(label)
            (staging / "data.bin").write_bytes(content(label))
        monkeypatch.setattr(module, "_rename_exchange", missing)
    assert_holds(target, "second")
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_the_current_folder_is_never_an_output(tmp_path: Path, monkeypatch) -> None:
    """A folder that is or holds the current folder is refused, empty or not: replacing it would
    leave the process and its shell in a deleted folder."""
    (tmp_path / "run" / "sub").mkdir(parents=True)
    monkeypatch.chdir(tmp_path / "run")
    for folder in (".", tmp_path / "run", tmp_path):
        with pytest.raises(ValueError, match=r"^output: .* the current folder"):
            check_output_path(folder, overwrite=True)
    check_output_path(tmp_path / "run" / "sub", overwrite=False)  # empty, below: fine
