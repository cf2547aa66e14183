"""Errors about a log file quote it briefly (issue 22, item 11: a UR RTDE header gave 1,140+
characters): the fact the error is about stays readable whatever the file's width."""

from __future__ import annotations

from pathlib import Path

import pytest

import dynid
from dynid.logs.messages import name_list, quote

# The columns of a UR RTDE recording (record_data.py of ur_rtde / RTDE client library), as the
# robot's own tool writes them: one header line of names separated by spaces.
RTDE_FIELDS = ["timestamp"] + [
    f"{signal}_{joint}"
    for signal in ("target_q", "target_qd", "target_qdd", "target_current", "target_moment",
                   "actual_q", "actual_qd", "actual_current", "joint_control_output")
    for joint in range(6)
] + ["robot_mode"]  # fmt: skip


def test_quote_keeps_short_text_and_bounds_long_text() -> None:
    assert quote("1.5e") == "'1.5e'"
    long = "a" * 30 + "b" * 440 + "c" * 30
    shortened = quote(long, limit=60)
    assert shortened == f"{'a' * 30!r} ... {'c' * 30!r} (500 characters)"


def test_name_list_lists_few_names_whole_and_many_by_their_ends() -> None:
    assert name_list(["t", "q1", "tau1"]) == "t, q1, tau1"
    names = [f"n{k}" for k in range(100)]
    text = name_list(names, limit=12)
    assert text == "n0, n1, n2, n3, n4, n5, n6, n7, n8, ..., n98, n99 (100 in all)"


def test_a_space_separated_rtde_file_is_read_and_a_wide_foreign_one_gets_a_short_error(
    tmp_path: Path,
) -> None:
    # Issue 22 asked for a short error on this file; issue 20 reads it (the UR RTDE reader).
    path = tmp_path / "robot_data.csv"
    rows = [
        " ".join(f"{0.002 * k + 0.1 * c:.6f}" for c in range(len(RTDE_FIELDS))) for k in range(5)
    ]
    path.write_text(" ".join(RTDE_FIELDS) + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    log = dynid.load_log(path)
    assert (log.format, log.n, log.T) == ("UR RTDE CSV", 6, 5)
    # A blank-separated file of 80+ names that no reader knows: the error stays short.
    names = ["stamp"] + [f"{s}_{j}" for s in ("pos", "vel", "eff") for j in range(30)]
    path = tmp_path / "foreign.csv"
    rows = [" ".join(f"{0.002 * k + c:.6f}" for c in range(len(names))) for k in range(5)]
    path.write_text(" ".join(names) + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"missing column 't'; found columns: stamp, pos_0") as e:
        dynid.load_log(path)
    message = str(e.value)
    assert len(message) < 400
    assert f"({len(names)} in all)" in message


def test_a_wide_log_missing_torques_names_its_columns_briefly(tmp_path: Path) -> None:
    path = tmp_path / "wide.csv"
    names = ["t"] + [f"q{j}" for j in range(1, 61)]
    path.write_text(",".join(names) + "\n" + ",".join(["0"] * 61) + "\n", encoding="utf-8")
    with pytest.raises(
        ValueError, match=r"missing columns tau1..tau60; found columns: t, q1, .* \(61 in all\)"
    ) as error:
        dynid.load_log(path)
    assert len(str(error.value)) < 300


def test_an_unreadable_long_field_is_quoted_by_its_ends(tmp_path: Path) -> None:
    path = tmp_path / "bad.csv"
    path.write_text("t,q1,tau1\n0,1," + "x" * 5000 + "\n", encoding="utf-8")
    with pytest.raises(
        ValueError, match=r"line 2, column 'tau1': cannot read .*\(5000 characters\)"
    ):
        dynid.load_log(path)
