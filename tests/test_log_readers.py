"""The log readers (dynid.logs.readers, registry dynid.logs.formats; issue 20, item 1): each
format read from a file the test writes as the robot's own tool does (tests/log_writers.py,
from a simulated arm), the arrays checked against the simulated ones; the format recognised
from the header and named; the errors short and naming the file and what is missing."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.logs import load_log, save_log
from dynid.logs.detection import detect, formats
from log_writers import (
    Motion,
    simulate,
    write_libfranka,
    write_pyfri,
    write_rostopic_csv,
    write_rtde,
)


@pytest.fixture(scope="module")
def ur5_motion() -> Motion:
    return simulate(dynid.models.ur5(), seed=3, seconds=2.0, fs=500.0)


@pytest.fixture(scope="module")
def panda_motion() -> Motion:
    return simulate(dynid.models.panda(), seed=4, seconds=2.0, fs=1000.0)


def six_digits(x: np.ndarray) -> np.ndarray:
    """What a C++ stream's default formatting keeps of x: 6 significant digits."""
    return np.vectorize(lambda v: float(f"{v:g}"))(x)


# ------------------------------------------------------------------------------ UR RTDE


@pytest.mark.parametrize("delimiter", [" ", ","])
def test_ur_rtde_space_or_comma_separated(tmp_path: Path, ur5_motion: Motion, delimiter: str):
    m = ur5_motion
    current = 0.1 * m.tau + 0.01  # motor currents [A], any known array
    path = tmp_path / "robot_data.csv"
    write_rtde(path, m, current=current, delimiter=delimiter)
    log = load_log(path)
    assert log.format == "UR RTDE CSV" == detect(path).name
    # Written with repr: read back exactly.
    np.testing.assert_array_equal(log.t, m.t)
    np.testing.assert_array_equal(log.q, m.q)
    np.testing.assert_array_equal(log.qd, m.qd)
    np.testing.assert_array_equal(log.tau, m.tau)  # target_moment, not the current window
    assert log.qdd is None
    currents = load_log(path, current=True)
    np.testing.assert_array_equal(currents.tau, current)  # actual_current_0..5 only
    assert "actual_current_0..actual_current_5" in currents.notes[-1]


def test_ur_rtde_without_torques_names_the_file_and_the_column(tmp_path: Path, ur5_motion):
    path = tmp_path / "no_moment.csv"
    m = ur5_motion
    header = ["timestamp"] + [f"actual_q_{j}" for j in range(6)]
    rows = [" ".join(str(x) for x in (m.t[k], *m.q[k])) for k in range(5)]
    path.write_text(" ".join(header) + "\n" + "\n".join(rows) + "\n")
    with pytest.raises(ValueError, match=r"nothing matches 'target_moment_N' for tau") as e:
        load_log(path)
    assert str(path) in str(e.value) and len(str(e.value)) < 300


# ------------------------------------------------------------------------------ libfranka


@pytest.mark.parametrize("old_header", [True, False])
def test_libfranka_log_to_csv(tmp_path: Path, panda_motion: Motion, old_header: bool):
    m = panda_motion
    path = tmp_path / "log.csv"
    write_libfranka(path, m, old_header=old_header)
    log = load_log(path)
    assert log.format == "libfranka logToCSV"
    np.testing.assert_allclose(log.t, m.t, rtol=0, atol=1e-12)  # whole ms, converted to s
    assert "time stamps in ms, converted to s" in log.notes
    np.testing.assert_array_equal(log.q, six_digits(m.q))
    np.testing.assert_array_equal(log.qd, six_digits(m.qd))
    np.testing.assert_array_equal(log.tau, six_digits(m.tau))
    with pytest.raises(ValueError, match="current: a libfranka log has no motor currents"):
        load_log(path, current=True)


def test_column_patterns_match_brackets_literally(tmp_path: Path, panda_motion: Motion):
    path = tmp_path / "franka.csv"
    write_libfranka(path, panda_motion)
    log = load_log(path, columns={"q": "state.q_d[*]", "tau": "cmd.tau_J_d[*]"})
    np.testing.assert_array_equal(log.q, six_digits(panda_motion.q))  # q_d: written as q
    np.testing.assert_array_equal(log.tau, np.zeros_like(log.tau))
    # fnmatch read "[0]" as a class matching "0": literal now, so it names one column
    one = load_log(path, columns={"q": "state.q[0]", "tau": "state.tau_J[0]"})
    assert one.n == 1
    with pytest.raises(ValueError, match=r"nothing matches 'state\.q0' for q"):
        load_log(path, columns={"q": "state.q0", "tau": "state.tau_J[*]"})


# ------------------------------------------------------------------------------ pyfri


def test_pyfri_collect_data(tmp_path: Path):
    m = simulate(dynid.models.kuka_lwr4(), seed=5, seconds=1.0, fs=1000.0)
    path = tmp_path / "fri.csv"
    write_pyfri(path, m)
    log = load_log(path)
    assert log.format == "KUKA FRI CSV (pyfri)"
    # the controller's time from the first whole second: the recording starts 0.25 s in
    np.testing.assert_allclose(log.t, m.t + 0.25, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(log.q, six_digits(m.q))
    np.testing.assert_array_equal(log.tau, six_digits(m.tau))
    assert log.qd is None
    with pytest.raises(ValueError, match="time_unit: KUKA FRI CSV"):
        load_log(path, time_unit="ms")


# ------------------------------------------------------------------------------ any CSV


def test_rostopic_csv_with_text_columns(tmp_path: Path, panda_motion: Motion):
    m = panda_motion
    names = [f"panda_joint{j}" for j in range(1, 8)]
    path = tmp_path / "joint_states.csv"
    write_rostopic_csv(path, m, names, stamp0=1_700_000_000_000_000_000)
    columns = {"t": "%time", "q": "field.position*", "qd": "field.velocity*",
               "tau": "field.effort*"}  # fmt: skip
    log = load_log(path, columns=columns, time_unit="ns")
    assert log.format == "CSV"
    np.testing.assert_allclose(log.t - log.t[0], m.t, rtol=0, atol=1e-6)  # ns in float64
    np.testing.assert_array_equal(log.q, m.q)
    np.testing.assert_array_equal(log.tau, m.tau)
    with pytest.raises(ValueError, match=r"column 'field.name0': cannot read 'panda_joint1'"):
        load_log(path, columns={**columns, "q": "field.name*"}, time_unit="ns")


@pytest.mark.parametrize("delimiter", [";", "\t", "  "])
def test_the_delimiter_is_found_from_the_lines(tmp_path: Path, delimiter: str):
    rng = np.random.default_rng(0)
    t = np.arange(50) * 0.01
    q, tau = rng.normal(size=(2, 50, 2))
    path = tmp_path / "log.csv"
    lines = [delimiter.join(["t", "q1", "q2", "tau1", "tau2"])]
    lines += [delimiter.join(repr(float(x)) for x in (t[k], *q[k], *tau[k])) for k in range(50)]
    path.write_text("\n".join(lines) + "\n")
    log = load_log(path)
    np.testing.assert_array_equal(log.q, q)
    np.testing.assert_array_equal(log.tau, tau)


def test_headerless_csv_by_column_index(tmp_path: Path, panda_motion: Motion):
    m = panda_motion
    table = np.column_stack([m.t, m.q, m.qd, m.qdd, m.tau])
    path = tmp_path / "plain.csv"
    np.savetxt(path, table, delimiter=",", fmt="%.17g")
    log = load_log(path, columns={"t": "0", "q": "1:8", "qd": "8:15", "qdd": "15:22",
                                  "tau": "22:29"})  # fmt: skip
    for name in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(getattr(log, name), getattr(m, name), err_msg=name)
    with pytest.raises(ValueError, match=r"no header row \(line 1 holds numbers\)") as e:
        load_log(path)
    assert str(path) in str(e.value)
    with pytest.raises(ValueError, match=r"'22:30' for tau is outside the file's 29 columns"):
        load_log(path, columns={"t": "0", "q": "1:8", "tau": "22:30"})
    with pytest.raises(ValueError, match="has no header; give the time's column too"):
        load_log(path, columns={"q": "1:8", "tau": "22:29"})
    with pytest.raises(ValueError, match=r"q needs a 0-based column index .* got 'q\*'"):
        load_log(path, columns={"t": "0", "q": "q*", "tau": "22:29"})


# ------------------------------------------------------------------------------ non-finite rows


def test_a_nan_row_is_refused_naming_the_option_or_dropped_and_counted(tmp_path: Path):
    t = np.arange(20) * 0.01
    q = np.sin(t)[:, None] * [1.0, 2.0]
    tau = np.cos(t)[:, None] * [3.0, 4.0]
    q[7, 1] = np.nan
    path = tmp_path / "nan.csv"
    text = "t,q1,q2,tau1,tau2\n" + "\n".join(
        ",".join(repr(float(x)) for x in (t[k], *q[k], *tau[k])) for k in range(20)
    )
    path.write_text(text + "\n")
    with pytest.raises(ValueError, match=r"q: non-finite value at line 9 \(data row 7\), "
                       r"joint\(s\) 2; drop_nonfinite=True \(--drop-nonfinite\)"):  # fmt: skip
        load_log(path)
    log = load_log(path, drop_nonfinite=True)
    keep = np.arange(20) != 7
    np.testing.assert_array_equal(log.t, t[keep])
    np.testing.assert_array_equal(log.q, q[keep])
    assert "dropped 1 of 20 rows with non-finite values (the first at line 9" in log.notes[-1]
    # the same in an NPZ (rows instead of lines)
    npz = tmp_path / "nan.npz"
    np.savez(npz, t=t, q=q, tau=tau)
    with pytest.raises(ValueError, match=r"q: non-finite value at row 7, joint\(s\) 2; drop"):
        load_log(npz)
    assert load_log(npz, drop_nonfinite=True).T == 19


# ------------------------------------------------------------------------------ MATLAB


def test_matlab_v5_files(tmp_path: Path):
    from scipy.io import savemat

    m = simulate(dynid.models.planar_2r(), seed=6, seconds=1.0, fs=200.0)
    path = tmp_path / "log.mat"
    savemat(path, {"t": m.t, "q": m.q, "qd": m.qd, "tau": m.tau})  # t saved as (1, T)
    log = load_log(path)
    assert log.format == "MATLAB .mat"
    np.testing.assert_array_equal(log.t, m.t)
    np.testing.assert_array_equal(log.q, m.q)
    np.testing.assert_array_equal(log.qd, m.qd)
    np.testing.assert_array_equal(log.tau, m.tau)
    # FloBaRoID names, one joint per row (n, T), and mapped variables
    savemat(path, {"times": m.t[:, None], "positions": m.q.T, "torques": m.tau.T})
    log = load_log(path)
    np.testing.assert_array_equal(log.q, m.q)
    assert "q, tau saved one joint per row, transposed" in log.notes[-1]
    savemat(path, {"time": m.t, "pos": m.q, "effort": m.tau})
    log = load_log(path, columns={"t": "time", "q": "pos", "tau": "effort"})
    np.testing.assert_array_equal(log.tau, m.tau)
    with pytest.raises(
        ValueError, match=r"missing key 't' \(or FloBaRoID 'times'\); found keys: time, pos, effort"
    ):
        load_log(path)


def test_matlab_v73_is_a_clear_error(tmp_path: Path):
    # The 128-byte header MATLAB writes before the HDF5 data of a v7.3 file: text, subsystem
    # offset, version 0x0200, endian indicator "IM" (MATLAB's MAT-File Format, p. 1-7).
    text = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5"
    header = text.ljust(116, b" ") + b"\0" * 8 + (0x0200).to_bytes(2, "little") + b"IM"
    path = tmp_path / "big.mat"
    path.write_bytes(header + b"\x89HDF\r\n\x1a\n" + b"\0" * 512)
    with pytest.raises(ValueError, match=r"MATLAB v7.3 \(HDF5\) file.*'-v7'") as e:
        load_log(path)
    assert str(path) in str(e.value)


# ------------------------------------------------------------------------------ the registry


def test_the_format_survives_save_and_load(tmp_path: Path, ur5_motion: Motion):
    path = tmp_path / "robot_data.csv"
    write_rtde(path, ur5_motion, current=ur5_motion.tau)
    log = load_log(path).slice(0, 100)
    assert log.format == "UR RTDE CSV"
    for ext in ("npz", "csv"):
        save_log(log, tmp_path / f"saved.{ext}")
        back = load_log(tmp_path / f"saved.{ext}")
        assert back.format == "UR RTDE CSV"
        np.testing.assert_array_equal(back.q, log.q)


def test_specific_formats_come_before_the_generic_ones():
    names = [fmt.name for fmt in formats()]
    assert names.index("UR RTDE CSV") < names.index("CSV")
    assert names.index("libfranka logToCSV") < names.index("CSV")
    assert names.index("KUKA FRI CSV (pyfri)") < names.index("CSV")
    assert {"NPZ", "MATLAB .mat"} <= set(names)


def test_unknown_extension_lists_the_readable_ones(tmp_path: Path):
    path = tmp_path / "log.xlsx"
    path.write_text("x")
    with pytest.raises(ValueError, match=re.escape("expected .npz or .csv, or ")) as raised:
        load_log(path)
    assert ".mat" in str(raised.value) and ".bag, .mcap, .db3" in str(raised.value)


def test_a_folder_is_read_as_a_ros2_bag(tmp_path: Path):
    # The ROS bag format reads folders (a ROS 2 bag is one); any other folder is no bag.
    with pytest.raises(ValueError, match=r"without metadata\.yaml"):
        load_log(tmp_path, joint_names=["q1"])


@pytest.mark.parametrize(
    ("header", "match"),
    [
        (
            "time,success_rate,state.q[0],state.q[1],state.dq[0],state.dq[1]",
            r"nothing matches 'state.tau_J\[N\]' for tau; found time, success_rate, state.q\[0\]",
        ),
        (
            "index,time,record_time_nsec,tsec,tnsec,mp1,mp2,et1,et2,dt",
            r"nothing matches 'mtN' for tau; found index, time",
        ),
        ("timestamp actual_q_0 actual_q_1", r"nothing matches 'timestamp'|'target_moment_N'"),
    ],
)
def test_a_robot_format_missing_a_column_names_the_file_and_the_column(
    tmp_path: Path, header: str, match: str
):
    delimiter = " " if header.startswith("timestamp") else ","
    width = len(header.split(delimiter))
    rows = [delimiter.join(str(k + 1 + 0.001 * c) for c in range(width)) for k in range(3)]
    path = tmp_path / "robot.csv"
    path.write_text(header + "\n" + "\n".join(rows) + "\n")
    with pytest.raises(ValueError, match=match) as e:
        load_log(path)
    assert str(e.value).startswith(str(path)) and len(str(e.value)) < 300


def test_libfranka_time_unit_given_overrides_its_milliseconds(tmp_path: Path, panda_motion):
    path = tmp_path / "log.csv"
    write_libfranka(path, panda_motion)
    default = load_log(path)
    with pytest.warns(UserWarning, match="implausible"):  # ms read as us: 1 MHz
        given = load_log(path, time_unit="us")
    np.testing.assert_allclose(given.t, default.t * 1e-3, rtol=1e-15, atol=0)


def test_repeated_time_stamps_keep_the_later_sample(tmp_path: Path):
    """A recorder that wrote a stamp twice: the earlier of the two samples is dropped (noted);
    time running backwards is still an error naming the line."""
    path = tmp_path / "log.csv"
    path.write_text("t,q1,tau1\n0.00,0.0,1\n0.01,0.1,2\n0.01,0.2,3\n0.02,0.3,4\n0.03,0.4,5\n")
    log = load_log(path)
    np.testing.assert_array_equal(log.t, [0.0, 0.01, 0.02, 0.03])
    np.testing.assert_array_equal(log.q[:, 0], [0.0, 0.2, 0.3, 0.4])
    assert "dropped 1 of 5 samples whose time stamp the next sample repeats" in " ".join(log.notes)
    assert "line 4" in " ".join(log.notes)
    path.write_text("t,q1,tau1\n0.00,0.0,1\n0.02,0.1,2\n0.01,0.2,3\n")
    with pytest.raises(ValueError, match="t: not strictly increasing at line 4"):
        load_log(path)
