"""dynid.logs (and its 0.2 name dynid.io): file formats, round trips, the real KUKA LWR4+ log,
malformed files, prepare_log."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy import signal as sp

from dynid.io import Log, load_log, prepare_log, save_log
from dynid.logs import signal as sig

DATA = Path(__file__).parent / "data"
FS = 200.0


def sine_log(T: int = 2000, n: int = 3, derivatives: bool = True, fs: float = FS) -> Log:
    """q_j = a_j sin(w_j t + p_j) with exact qd, qdd; tau a smooth function of them."""
    t = 10.0 + np.arange(T) / fs
    a = 0.5 + 0.3 * np.arange(n)
    w = 1.0 + 0.4 * np.arange(n)
    p = 0.7 * np.arange(n)
    q = a * np.sin(w * t[:, None] + p)
    qd = a * w * np.cos(w * t[:, None] + p)
    qdd = -a * w**2 * np.sin(w * t[:, None] + p)
    tau = 2.0 * qdd + 0.5 * qd + 10.0 * np.cos(q)
    if not derivatives:
        return Log(t, q, tau, source="synthetic")
    return Log(t, q, tau, qd, qdd, source="synthetic")


def assert_same_log(a: Log, b: Log) -> None:
    for name in ("t", "q", "tau", "qd", "qdd"):
        x, y = getattr(a, name), getattr(b, name)
        if x is None or y is None:
            assert x is None and y is None, name
        else:
            np.testing.assert_array_equal(x, y, err_msg=name)


# ------------------------------------------------------------------------------ round trips


@pytest.mark.parametrize("ext", ["npz", "csv", "NPZ"])
@pytest.mark.parametrize("derivatives", [True, False])
def test_save_then_load_gives_the_same_log(tmp_path: Path, ext: str, derivatives: bool) -> None:
    log = sine_log(T=300, n=4, derivatives=derivatives)
    rng = np.random.default_rng(2)
    log = log.replace(tau=log.tau + rng.normal(0.0, 1e-3, log.tau.shape), note="noise added")
    path = tmp_path / f"log.{ext}"
    save_log(log, path)
    back = load_log(path)
    assert_same_log(back, log)  # bit for bit: NPZ is binary, CSV writes 17 digits
    assert back.notes[:-1] == log.notes
    assert back.notes[-1].startswith("loaded from log.")
    assert back.source == str(path)


def test_csv_layout_is_as_documented(tmp_path: Path) -> None:
    """A hand-written CSV in the documented layout (comments, any column order, spaces)."""
    path = tmp_path / "hand.csv"
    path.write_text(
        "# recorded by hand\n"
        "t, tau1, tau2, q1, q2, extra\n"
        "0.0, 1.0, 2.0, 0.1, 0.2, 9\n"
        "# a comment between rows\n"
        "\n"
        "0.01, 1.5, 2.5, 0.11, 0.21, 9\n"
        "0.02, 1.6, 2.6, 0.12, 0.22, 9\n"
    )
    log = load_log(path)
    assert (log.T, log.n) == (3, 2)
    np.testing.assert_array_equal(log.q, [[0.1, 0.2], [0.11, 0.21], [0.12, 0.22]])
    np.testing.assert_array_equal(log.tau[:, 1], [2.0, 2.5, 2.6])
    assert log.qd is None and log.qdd is None
    assert "ignored columns extra" in log.notes[-1]


def test_npz_accepts_flobaroid_names(tmp_path: Path) -> None:
    log = sine_log(T=50, n=2)
    path = tmp_path / "flo.npz"
    np.savez(
        path,
        times=log.t,
        positions=log.q,
        velocities=log.qd,
        accelerations=log.qdd,
        torques=log.tau,
        target_positions=np.zeros_like(log.q),
    )
    back = load_log(path)
    assert_same_log(back, log)
    assert "FloBaRoID" in back.notes[-1]


# ------------------------------------------------------------------------------ the real log


@pytest.mark.parametrize("name", ["measurements_1.npz", "measurements_2.npz"])
def test_real_kuka_log_loads_as_it_is(name: str) -> None:
    """The FloBaRoID recordings of the LWR4+ (tests/data, LGPL-3.0, see the README there):
    7 joints, 5027 samples at 200 Hz over 25.13 s, arrays unchanged."""
    log = load_log(DATA / name)
    raw = np.load(DATA / name)
    assert (log.n, log.T) == (7, 5027)
    assert log.fs == pytest.approx(200.0, abs=0.1)
    assert log.duration == pytest.approx(25.13, abs=0.01)
    for mine, theirs in (
        ("t", "times"),
        ("q", "positions"),
        ("qd", "velocities"),
        ("qdd", "accelerations"),
        ("tau", "torques"),
    ):
        np.testing.assert_array_equal(getattr(log, mine), raw[theirs])
    skipped = load_log(DATA / name, skip=500)  # FloBaRoID's startOffset for these logs
    assert skipped.T == 4527
    assert skipped.t[0] == raw["times"][500]
    assert skipped.notes[-1] == "skipped the first 500 samples"


def test_real_log_velocities_agree_with_differentiated_positions() -> None:
    """The README: from sample 200 on, the stored velocities match the derivative of the
    positions to ~6 % RMS. Differentiating and filtering at 3 Hz (prepare_log) agrees so."""
    log = load_log(DATA / "measurements_1.npz")
    # trim_edges=False: the sample-by-sample comparison needs the whole grid (the edges are
    # left out below anyway); the default trim is tested in test_preparation_edges.py.
    ours = prepare_log(log, cutoff=3.0, differentiate="always", trim_edges=False)
    err = np.sqrt(np.mean((ours.qd - log.qd)[200:-200] ** 2, axis=0))
    rms = np.sqrt(np.mean(log.qd[200:-200] ** 2, axis=0))
    assert np.all(err / rms < 0.1), err / rms


# ------------------------------------------------------------------------------ malformed files


def write_npz(path: Path, **arrays: np.ndarray) -> Path:
    np.savez(path, **arrays)
    return path


def good_arrays(T: int = 20, n: int = 3) -> dict[str, np.ndarray]:
    log = sine_log(T=T, n=n)
    return {"t": log.t, "q": log.q, "tau": log.tau, "qd": log.qd, "qdd": log.qdd}


def npz_case(tmp_path: Path, case: str) -> Path:
    a = good_arrays()
    path = tmp_path / f"{case}.npz"
    if case == "missing_tau":
        del a["tau"]
    elif case == "missing_t":
        del a["t"]
    elif case == "short_q":
        a["q"] = a["q"][:-1]
    elif case == "tau_columns":
        a["tau"] = a["tau"][:, :2]
    elif case == "qdd_columns":
        a["qdd"] = a["qdd"][:, :4].repeat(2, axis=1)[:, :4]
    elif case == "nan_q":
        a["q"][7, 1] = np.nan
    elif case == "inf_tau":
        a["tau"][12, 0] = np.inf
    elif case == "t_backwards":
        a["t"][5] = a["t"][3]
    elif case == "one_sample":
        a = {k: v[:1] for k, v in a.items()}
    elif case == "q_1d":
        a["q"] = a["q"][:, 0]
    elif case == "both_names":
        a["torques"] = a["tau"]
    elif case == "strings":
        a["q"] = np.array([["x"] * 3] * 20)
    return write_npz(path, **a)


@pytest.mark.parametrize(
    ("case", "match"),
    [
        ("missing_tau", r"missing key 'tau' \(or FloBaRoID 'torques'\); found keys: t, q, qd, qdd"),
        ("missing_t", r"missing key 't' \(or FloBaRoID 'times'\); found keys"),
        ("short_q", r"length mismatch: .*t has 20, q has 19, tau has 20"),
        ("tau_columns", r"tau: has 2 joints \(columns\) but q has 3"),
        ("qdd_columns", r"qdd: has 4 joints \(columns\) but q has 3"),
        ("nan_q", r"q: non-finite value at row 7, joint\(s\) 2"),
        ("inf_tau", r"tau: non-finite value at row 12, joint\(s\) 1"),
        (
            "t_backwards",
            r"t: not strictly increasing at sample 5 \(t\[5\] = 10.015 <= t\[4\] = 10.02\)",
        ),
        ("one_sample", r"t: expected at least 2 samples, got 1"),
        ("q_1d", r"q: expected shape \(T, n\), got \(20,\)"),
        ("both_names", r"both keys 'tau' and 'torques'"),
        ("strings", r"q: expected numbers"),
    ],
)
def test_malformed_npz_is_rejected_with_a_message_naming_the_problem(
    tmp_path: Path, case: str, match: str
) -> None:
    path = npz_case(tmp_path, case)
    with pytest.raises(ValueError, match=match) as info:
        load_log(path)
    assert str(path) in str(info.value)  # the file is named too


CSV_HEADER = "t,q1,q2,tau1,tau2"
CSV_ROWS = ["0.00,0.1,0.2,1.0,2.0", "0.01,0.1,0.2,1.0,2.0", "0.02,0.1,0.2,1.0,2.0"]


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (
            "t,q1,q2,tau1\n" + "\n".join(r[:-4] for r in CSV_ROWS),
            r"inconsistent joint columns: expected tau1..tau2 \(n = 2 from column q2\), "
            r"missing tau2",
        ),
        (
            "t,q1,q2\n" + "\n".join(r[:-8] for r in CSV_ROWS),
            r"missing columns tau1..tau2; found columns: t, q1, q2",
        ),
        (
            "time,q1,q2,tau1,tau2\n" + "\n".join(CSV_ROWS),
            r"missing column 't'; found columns: time, q1, q2, tau1, tau2",
        ),
        ("t,tau1,tau2\n0,1,2\n1,1,2\n", r"missing columns q1..qn; found columns: t, tau1, tau2"),
        ("t,q1,q3,tau1,tau3\n0,1,2,3,4\n1,1,2,3,4\n", r"expected q1..q3 .*missing q2"),
        ("t,q1,q2,tau1,tau2,tau3\n0,1,2,3,4,5\n1,1,2,3,4,5\n", r"expected tau1..tau2 .*extra tau3"),
        ("t,q1,q2,tau1,tau2,qd1\n0,1,2,3,4,5\n1,1,2,3,4,5\n", r"expected qd1..qd2 .*missing qd2"),
        (
            CSV_HEADER + "\n" + CSV_ROWS[0] + "\n0.01,0.1,nan,1.0,2.0\n",
            r"q: non-finite value at line 3 \(data row 1\), joint\(s\) 2",
        ),
        (
            CSV_HEADER + "\n" + CSV_ROWS[0] + "\n0.01,0.1,abc,1.0,2.0\n",
            r"line 3, column 'q2': cannot read 'abc' as a number",
        ),
        (
            CSV_HEADER + "\n" + CSV_ROWS[0] + "\n0.01,0.1,1.0,2.0\n",
            r"line 3: 4 fields, but the header \(line 1\) has 5 columns",
        ),
        (
            "# c\n" + CSV_HEADER + "\n" + "\n".join(CSV_ROWS[:2]) + "\n0.005,0.1,0.2,1.0,2.0\n",
            r"t: not strictly increasing at line 5 \(data row 2\)",
        ),
        (CSV_HEADER + "\n" + CSV_ROWS[0] + "\n", r"expected at least 2 data rows, got 1"),
        ("# only comments\n", r"no header row"),
        ("t,q1,q1,tau1\n0,1,1,1\n1,1,1,1\n", r"duplicate columns in the header: q1"),
    ],
)
def test_malformed_csv_is_rejected_with_a_message_naming_the_problem(
    tmp_path: Path, text: str, match: str
) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=match):
        load_log(path)


def test_file_level_errors(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"nope.npz"):
        load_log(tmp_path / "nope.npz")
    (tmp_path / "log.txt").write_text("t,q1,tau1\n0,0,0\n1,1,1\n")
    with pytest.raises(ValueError, match=r"unknown extension '.txt'.*expected .npz or .csv"):
        load_log(tmp_path / "log.txt")
    (tmp_path / "fake.npz").write_text("not a zip archive")
    with pytest.raises(ValueError, match="not a readable NPZ file"):
        load_log(tmp_path / "fake.npz")
    with pytest.raises(ValueError, match="unknown extension"):
        save_log(sine_log(T=10), tmp_path / "log.mat")
    with pytest.raises(ValueError, match="skip"):
        load_log(write_npz(tmp_path / "g.npz", **good_arrays()), skip=19)
    with pytest.raises(ValueError, match="skip"):
        load_log(tmp_path / "g.npz", skip=-1)


# ------------------------------------------------------------------------------ Log


def test_log_properties_select_slice() -> None:
    log = sine_log(T=201, n=2)
    assert (log.n, log.T) == (2, 201)
    assert log.duration == pytest.approx(1.0)
    assert log.fs == pytest.approx(FS)
    part = log.slice(10, 20)
    np.testing.assert_array_equal(part.t, log.t[10:20])
    np.testing.assert_array_equal(part.qdd, log.qdd[10:20])
    assert part.notes[-1] == "kept samples 10:20 of 201"
    picked = log.select(log.q[:, 1] > 0, note="positive q2")
    assert 2 < picked.T == int((log.q[:, 1] > 0).sum()) < log.T
    assert picked.notes[-1] == "positive q2"
    assert log.notes == []  # the original is untouched
    with pytest.raises(ValueError, match="mask"):
        log.select(np.ones(5, dtype=bool))
    with pytest.raises(ValueError, match="not strictly increasing"):
        log.select(np.array([3, 1, 2]))
    with pytest.raises(ValueError, match="at least 2 samples"):
        log.slice(5, 6)
    assert "T=201" in repr(log)


# ------------------------------------------------------------------------------ prepare_log


def test_prepare_log_does_nothing_unless_asked() -> None:
    log = sine_log(T=300)
    same = prepare_log(log)
    assert_same_log(same, log)
    assert same.notes == log.notes


def test_prepare_log_lowpass_same_zero_phase_filter_on_every_signal() -> None:
    """Noisy q and tau: each comes out as scipy's sosfiltfilt of the same 4th-order design
    (independent call), and the noise-free sinusoids are kept in phase (the filtered qd still
    matches the exact derivative in the middle of the log)."""
    rng = np.random.default_rng(4)
    clean = sine_log(T=2000)
    noisy = clean.replace(
        q=clean.q + rng.normal(0, 1e-3, clean.q.shape),
        tau=clean.tau + rng.normal(0, 0.05, clean.tau.shape),
    )
    out = prepare_log(noisy, cutoff=5.0)
    sos = sp.butter(4, 5.0, fs=FS, output="sos")
    # Since issue 20 the filter's edge transients are trimmed (test_preparation_edges.py): the
    # kept samples are scipy's filtered signal without its first and last `trim`.
    trim = (noisy.T - out.T) // 2
    assert trim > 0 and f"trimmed {trim} samples" in out.notes[-1]
    for name in ("q", "tau", "qd", "qdd"):
        np.testing.assert_allclose(
            getattr(out, name),
            sp.sosfiltfilt(sos, getattr(noisy, name), axis=0)[trim:-trim],
            atol=1e-12,
        )
    inner = slice(200, -200)  # slow sinusoids (<= 0.3 Hz) pass a 5 Hz zero-phase filter as they are
    smooth = prepare_log(clean, cutoff=5.0, trim_edges=False)  # same grid as clean
    for name in ("q", "tau", "qd", "qdd"):
        np.testing.assert_allclose(
            getattr(smooth, name)[inner], getattr(clean, name)[inner], atol=1e-6, err_msg=name
        )
    assert out.notes[-2] == (
        "low-pass zero-phase order-4 Butterworth 5 Hz (sosfiltfilt, fs 200 Hz) on q, tau, qd, qdd"
    )


def test_prepare_log_paper_eq33_experiment() -> None:
    """Paper eq. (33): q = pi/2 cos(pi t / 7) on all joints, T = 14 s, measured positions
    differentiated twice and filtered by a 4th-order zero-phase Butterworth at 1 Hz. With
    1e-4 rad of position noise at 200 Hz (raw second differences have ~10 rad/s^2 of noise) the
    result matches the analytic qd and qdd away from the ends."""
    rng = np.random.default_rng(33)
    t = np.arange(0.0, 14.0 + 1e-9, 1.0 / FS)
    w = np.pi / 7
    q = np.pi / 2 * np.cos(w * t)[:, None].repeat(7, axis=1)
    log = Log(t, q + rng.normal(0, 1e-4, q.shape), np.zeros_like(q))
    # trim_edges=False: the same grid as t (2 s are left out at each end below; the default
    # trim, 2.54 s at 1 Hz, is tested in test_preparation_edges.py)
    out = prepare_log(log, cutoff=1.0, order=4, trim_edges=False)
    inner = slice(400, -400)  # 2 s from each end
    qd = -np.pi / 2 * w * np.sin(w * t)
    qdd = -np.pi / 2 * w**2 * np.cos(w * t)
    assert np.max(np.abs(out.qd[inner] - qd[inner, None])) < 2e-3
    assert np.max(np.abs(out.qdd[inner] - qdd[inner, None])) < 1e-2
    assert out.notes[0].startswith("time stamps: median step 0.005 s") and "uniform" in out.notes[0]
    assert "Butterworth 1 Hz" in out.notes[1]
    assert out.notes[2] == (
        "qd and qdd computed by second-order central differences on t from low-passed q (twice)"
    )


def test_prepare_log_differentiate_modes() -> None:
    log = sine_log(T=1000, derivatives=False)
    exact = sine_log(T=1000)
    missing = prepare_log(log)
    np.testing.assert_allclose(missing.qd, exact.qd, atol=2e-4)
    np.testing.assert_allclose(missing.qdd[3:-3], exact.qdd[3:-3], atol=2e-3)  # ends 1st order
    assert prepare_log(log, differentiate="never").qd is None
    wrong = exact.replace(qd=np.zeros_like(exact.qd))
    kept = prepare_log(wrong, differentiate="missing")
    np.testing.assert_array_equal(kept.qd, 0.0)
    redone = prepare_log(wrong, differentiate="always")
    np.testing.assert_allclose(redone.qd, exact.qd, atol=2e-4)
    assert "replacing the given qd, qdd" in redone.notes[-1]
    half = exact.replace(qdd=None)
    only_qdd = prepare_log(half)
    np.testing.assert_array_equal(only_qdd.qd, exact.qd)
    np.testing.assert_allclose(only_qdd.qdd[3:-3], exact.qdd[3:-3], atol=2e-3)
    assert only_qdd.notes[-1].startswith("qdd computed") and "from qd" in only_qdd.notes[-1]


def test_prepare_log_decimate() -> None:
    log = sine_log(T=1000)
    out = prepare_log(log, decimate=4, trim_edges=False)  # the trim: test_preparation_edges.py
    np.testing.assert_array_equal(out.t, log.t[::4])
    assert out.fs == pytest.approx(FS / 4)
    inner = slice(20, -20)  # the slow sinusoids pass the 20 Hz anti-alias filter unchanged
    np.testing.assert_allclose(out.q[inner], log.q[::4][inner], atol=1e-6)
    assert out.notes[-1].startswith("decimated by 4") and "20 Hz" in out.notes[-1]
    low = prepare_log(log, cutoff=2.0, decimate=4)
    assert "already band-limited" in low.notes[-2]  # the last: the edge trim (issue 20)


def test_prepare_log_drops_slow_samples() -> None:
    log = sine_log(T=1500)
    threshold = 0.2
    out = prepare_log(log, min_velocity=threshold)
    slow = np.any(np.abs(log.qd) < threshold, axis=1)  # independent count
    assert log.T - slow.sum() == out.T
    assert np.all(np.abs(out.qd) >= threshold)
    np.testing.assert_array_equal(out.t, log.t[~slow])
    assert out.notes[-1] == (
        f"dropped {slow.sum()} of 1500 samples: {slow.sum()} samples with |qd| < 0.2 on some "
        "joint (friction sign ill-defined near zero velocity)"
    )
    per_joint = prepare_log(log, min_velocity=[0.0, 0.0, 0.5])
    assert np.all(np.abs(per_joint.qd[:, 2]) >= 0.5)


def test_prepare_log_outliers_against_a_reference() -> None:
    """tau = model + noise, with 12 samples off by 1 N m: exactly those go, whether the
    reference is an array on the input log or a callable on the prepared log."""
    rng = np.random.default_rng(8)
    clean = sine_log(T=1200)
    model = clean.tau.copy()
    tau = model + rng.normal(0.0, 0.02, model.shape)
    bad = rng.choice(1200, 12, replace=False)
    tau[bad, rng.integers(0, 3, 12)] += rng.choice([-1.0, 1.0], 12)
    log = clean.replace(tau=tau)
    out = prepare_log(log, outlier_k=5.0, reference_tau=model)
    np.testing.assert_array_equal(out.t, np.delete(log.t, bad))
    assert "12 samples whose torque deviates from reference_tau (given)" in out.notes[-1]

    def predict(prepared: Log) -> np.ndarray:
        return 2.0 * prepared.qdd + 0.5 * prepared.qd + 10.0 * np.cos(prepared.q)

    # Decimated: the reference rows follow the kept samples. The anti-alias filter spreads an
    # outlier over its neighbours, which are then dropped too (they are contaminated), but no
    # sample far from an outlier is.
    decimated = prepare_log(
        log, decimate=2, outlier_k=5.0, reference_tau=model, trim_edges=False
    )  # the whole grid: the edge trim would count as dropped samples here
    grid = np.arange(0, 1200, 2)
    dropped = np.setdiff1d(grid, np.searchsorted(log.t, decimated.t))
    assert set(bad[bad % 2 == 0]) <= set(dropped)
    assert all(np.min(np.abs(bad - i)) <= 6 for i in dropped)
    called = prepare_log(log, outlier_k=5.0, reference_tau=predict)
    np.testing.assert_array_equal(called.t, np.delete(log.t, bad))
    assert "reference_tau(log)" in called.notes[-1]


def test_prepare_log_spikes_without_reference_are_dropped_before_they_spread() -> None:
    """Spikes in the raw torque: found on the raw signal, kept out of the low-pass (so their
    neighbours equal the filtered spike-free torque) and then dropped."""
    rng = np.random.default_rng(12)
    clean = sine_log(T=2000)
    tau = clean.tau + rng.normal(0.0, 0.01, clean.tau.shape)
    spiky = tau.copy()
    bad = np.sort(rng.choice(np.arange(100, 1900), 8, replace=False))
    spiky[bad, 1] += 20.0
    # trim_edges=False: the spikes lie 100 samples or more from the ends, inside the 2 Hz
    # filter's trim of 254; the trim itself is tested in test_preparation_edges.py
    out = prepare_log(clean.replace(tau=spiky), cutoff=2.0, outlier_k=5.0, trim_edges=False)
    np.testing.assert_array_equal(out.t, np.delete(clean.t, bad))
    reference = np.delete(sig.lowpass(tau, FS, 2.0), bad, axis=0)
    # a 20 N m spike spread by the 2 Hz filter would shift its neighbours by ~0.4 N m
    np.testing.assert_allclose(out.tau, reference, atol=0.05)
    assert "8 samples whose torque as given deviated" in out.notes[-1]


def test_prepare_log_steps_are_noted_in_order() -> None:
    log = sine_log(T=2000, derivatives=False)
    out = prepare_log(log, cutoff=4.0, decimate=2, min_velocity=0.05, outlier_k=6.0)
    # since issue 20: the time base first, the edge trim after the decimation
    steps = ["time", "low-pass", "qd", "decimated", "trimmed", "dropped"]
    assert [note.split()[0] for note in out.notes] == steps


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"differentiate": "sometimes"}, "differentiate"),
        ({"decimate": 0}, "decimate"),
        ({"cutoff": 100.0}, "cutoff"),
        ({"order": -1}, "order"),
        ({"reference_tau": np.zeros((500, 3))}, "reference_tau: given without outlier_k"),
        ({"outlier_k": 5.0, "reference_tau": np.zeros((499, 3))}, r"reference_tau: .*\(500, 3\)"),
        ({"outlier_k": 5.0, "reference_tau": lambda log: np.zeros(3)}, r"reference_tau\(log\)"),
        ({"outlier_k": 0.0}, "outlier_k"),
        ({"min_velocity": 0.1, "differentiate": "never"}, "min_velocity: needs qd"),
        ({"min_velocity": 10.0}, "fewer than 2 samples would remain"),
    ],
)
def test_prepare_log_rejects_bad_arguments(kwargs: dict, match: str) -> None:
    log = sine_log(T=500, derivatives=False)
    with pytest.raises(ValueError, match=match):
        prepare_log(log, **kwargs)


def test_prepare_log_refuses_to_filter_a_log_with_gaps() -> None:
    log = sine_log(T=500)
    gappy = log.select(np.r_[np.arange(200), np.arange(300, 500)])
    # Filtering as if uniform (the behaviour before issue 20) still refuses a gap ...
    with pytest.raises(ValueError, match=r"t: .* gap of 0.505 s .* after sample 199"):
        prepare_log(gappy, cutoff=5.0, nonuniform="ignore")
    # ... by default the log is split there (test_preparation_timing.py), and segments of 200
    # samples are too short for a 5 Hz filter's edge trim at both ends (2 x 102 samples)
    with pytest.raises(ValueError, match=r"no segment long enough .* 2 segments of 200, 200"):
        prepare_log(gappy, cutoff=5.0)
    prepare_log(gappy, min_velocity=0.01)  # selection alone is fine


def test_the_0_2_name_dynid_io_gives_the_same_log_layer() -> None:
    # Code written against dynid 0.2 imported the log layer as dynid.io (docs/architecture.md).
    import dynid.io
    import dynid.logs

    for name in ("Log", "load_log", "prepare_log", "save_log"):
        assert getattr(dynid.io, name) is getattr(dynid.logs, name)
