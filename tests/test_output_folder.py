"""Result folders under misuse (issue 22, item 7), on real folders: ``--overwrite`` replaces
only a folder that dynid wrote and that holds no input of the run."""

from __future__ import annotations

from pathlib import Path

import pytest

import dynid
from dynid.cli import main
from dynid.io import save_log
from dynid.io.output_folder import check_output_path
from test_log_identification import fourier_log

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
        [MARKER, "result.json", "torques.png", "residuals.png"]
    )
    assert dynid.load_result(run).friction
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data", "run"]  # no staging debris


def test_the_current_folder_is_never_an_output(tmp_path: Path, monkeypatch) -> None:
    """A folder that is or holds the current folder is refused, empty or not: replacing it would
    leave the process and its shell in a deleted folder."""
    (tmp_path / "run" / "sub").mkdir(parents=True)
    monkeypatch.chdir(tmp_path / "run")
    for folder in (".", tmp_path / "run", tmp_path):
        with pytest.raises(ValueError, match=r"^output: .* the current folder"):
            check_output_path(folder, overwrite=True)
    check_output_path(tmp_path / "run" / "sub", overwrite=False)  # empty, below: fine
