"""Logs in and out: the checked measurement log, loading it in any registered format, and
saving it as NPZ or CSV.

A :class:`Log` holds time, joint positions and joint torques, with velocities and accelerations
when the recording has them. ``load_log`` finds the file's format in the registry
(:mod:`dynid.logs.formats`; the readers, one per format, are in :mod:`dynid.logs.readers`) and
adds what every format shares: ``skip`` and the plausibility of the time base. ``save_log``
writes dynid's NPZ and CSV (``docs/data.md``). Preparing a log for identification (filtering,
differentiation, decimation, dropping samples) is :mod:`dynid.logs.preparation`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Union

import numpy as np

from .._checks import count, positive
from .columns import check_columns, time_scale
from .log import SIGNALS, Log

PathLike = Union[str, Path]

# --------------------------------------------------------------------------- loading


def load_log(
    path: PathLike,
    *,
    skip: int = 0,
    columns: Mapping[str, str] | None = None,
    time_unit: str | None = None,
    current: bool = False,
    drop_nonfinite: bool = False,
    topic: str | None = None,
    joint_names: Sequence[str] | None = None,
    sample_time: float | None = None,
    skip_end: int = 0,
) -> Log:
    """Load a log in any registered format (``dynid.logs.formats``; docs/data.md): dynid's NPZ
    and CSV, UR RTDE, libfranka, pyfri/FRI, any CSV, MATLAB. The format is chosen by the suffix
    and the file's header and named in ``Log.format``.

    ``skip`` drops the first samples (e.g. a start-up transient; FloBaRoID's configuration for
    the LWR4+ logs skips 500); ``skip_end`` drops the last samples (e.g. a final rest; the
    filters' edge transients are trimmed by :func:`dynid.prepare_log` itself). ``columns`` maps
    signals of a foreign log to its columns or keys
    (``{"t": "stamp", "q": "pos_*", "tau": "effort_*"}``, :mod:`dynid.logs.columns`; a CSV
    without a header by column index, ``{"t": "0", "q": "1:8", "tau": "15:22"}``) and
    ``time_unit`` ("s", "ms", "us", "ns") says what the time stamps count; None reads the
    format's own unit (seconds, libfranka milliseconds). ``current`` reads motor currents as tau
    where the format records them (UR RTDE ``actual_current_i``). ``drop_nonfinite`` drops rows
    holding a NaN or inf (counted in the notes) instead of refusing the file. ``topic`` and
    ``joint_names`` are for ROS bags (the topic, and the model's joint names the message's joints
    are matched to). A log without a time vector (a motor-side recording such as the Staubli
    TX40's) needs ``sample_time`` [s], or an NPZ key ``sample_time``: t = 0, dt, 2 dt, ...
    Errors name the file and what is missing or malformed. A sampling rate no
    robot log has (outside PLAUSIBLE_RATE: nanosecond stamps read as seconds give 2e-7 Hz and a
    meaningless fit) is an error, unless ``time_unit`` was given (then a warning: the caller
    said what the stamps count); a position range no robot has is a warning.
    """
    from .detection import detect
    from .formats import ReadOptions

    path = Path(path)
    if not path.exists():  # a folder is a log too where a format reads one (ROS 2 bags)
        raise FileNotFoundError(f"path: no such file: {path}")
    skip = count(skip, "skip", 0)
    skip_end = count(skip_end, "skip_end", 0)
    if time_unit is not None:
        time_scale(time_unit)  # checked before the file is read
    if topic is not None and (not isinstance(topic, str) or not topic):
        raise ValueError(f"topic: expected a topic name, got {topic!r}")
    if joint_names is not None:
        if isinstance(joint_names, str) or not all(
            isinstance(name, str) and name for name in joint_names
        ):
            raise ValueError(f"joint_names: expected a sequence of names, got {joint_names!r}")
        joint_names = tuple(joint_names)
    if sample_time is not None:
        sample_time = positive(sample_time, "sample_time")  # seconds
    options = ReadOptions(
        sample_time=sample_time,
        columns=check_columns(columns) if columns is not None else None,
        time_unit=time_unit,
        current=bool(current),
        topic=topic,
        joint_names=joint_names,
        drop_nonfinite=bool(drop_nonfinite),
    )
    fmt = detect(path)
    if topic is not None and not fmt.topics:
        raise ValueError(f"topic: only for ROS bags, not {path.name} ({fmt.name})")
    try:
        log = fmt.read(path, options)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
    if skip:
        if skip > log.T - 2:
            raise ValueError(f"skip: {skip} leaves fewer than 2 of the {log.T} samples of {path}")
        log = log.slice(skip, None, note=f"skipped the first {skip} samples")
    if skip_end:
        if skip_end > log.T - 2:
            raise ValueError(
                f"skip_end: {skip_end} leaves fewer than 2 of the {log.T} samples of {path}"
            )
        log = log.slice(0, log.T - skip_end, note=f"skipped the last {skip_end} samples")
    check_plausible(log, path.name, unit_given=time_unit is not None)
    return log


#: Sampling rates outside this band [Hz] are not a robot log read in the right time unit.
PLAUSIBLE_RATE = (1.0, 100e3)
#: |q| beyond this many radians (or metres) suggests degrees or encoder counts.
PLAUSIBLE_POSITION = 100.0


def check_plausible(log: Log, what: str, *, unit_given: bool) -> None:
    """Refuse a sampling rate outside PLAUSIBLE_RATE (a warning when the caller gave the time
    unit), and warn of positions beyond PLAUSIBLE_POSITION."""
    fs = log.fs
    if not PLAUSIBLE_RATE[0] <= fs <= PLAUSIBLE_RATE[1]:
        guess = "ns" if fs < 1e-3 else ("ms" if fs < 1.0 else "s")
        message = (
            f"{what}: t: the median sampling rate is {fs:.3g} Hz, implausible for a robot log "
            f"({PLAUSIBLE_RATE[0]:g} Hz to {PLAUSIBLE_RATE[1]:g} Hz)"
        )
        if not unit_given:
            raise ValueError(
                f"{message}: the time stamps are probably not in seconds (e.g. {guess!r}); "
                "give their unit with time_unit / --time-unit (s, ms, us, ns)"
            )
        warnings.warn(
            f"{message} with time stamps in the unit given; check time_unit / --time-unit",
            UserWarning,
            stacklevel=3,
        )
    largest = float(np.max(np.abs(log.q)))
    if largest > PLAUSIBLE_POSITION:
        warnings.warn(
            f"{what}: q: positions up to {largest:.4g}; dynid expects radians (or metres): "
            "degrees or encoder counts?",
            UserWarning,
            stacklevel=3,
        )


# --------------------------------------------------------------------------- saving


def save_log(log: Log, path: PathLike) -> None:
    """Write a log as ``.npz`` (keys t, q, tau[, qd, qdd], notes) or ``.csv`` (docs/data.md).

    Values are written exactly (NPZ binary, CSV with 17 significant digits), so loading the
    file gives back the same arrays. The notes and the format go into the file (string arrays
    in NPZ, ``# note:`` and ``# format:`` lines in CSV) and come back on loading.
    """
    if not isinstance(log, Log):
        raise ValueError(f"log: expected a dynid.Log, got {type(log).__name__}")
    path = Path(path)
    suffix = path.suffix.lower()
    present = [name for name in SIGNALS if getattr(log, name) is not None]
    if suffix == ".npz":
        arrays = {name: getattr(log, name) for name in ("t", *present)}
        with path.open("wb") as handle:  # a handle: np.savez would append ".npz" to "x.NPZ"
            if log.format:
                arrays["format"] = np.asarray(log.format)
            np.savez(handle, **arrays, notes=np.asarray(log.notes, dtype=str))
    elif suffix == ".csv":
        order = [name for name in ("q", "qd", "qdd", "tau") if name in present]
        header = ["t"] + [f"{name}{j}" for name in order for j in range(1, log.n + 1)]
        table = np.column_stack([log.t] + [getattr(log, name) for name in order])
        comments = ["# dynid log: t in s, q in rad or m, tau in N*m or N (docs/data.md)"]
        comments += [f"# format: {log.format}"] if log.format else []
        comments += [f"# note: {note}" for note in log.notes]
        with path.open("w", newline="") as handle:
            handle.write("\n".join(comments) + "\n" + ",".join(header) + "\n")
            np.savetxt(handle, table, delimiter=",", fmt="%.17g")
    else:
        raise ValueError(f"path: unknown extension {path.suffix!r}; expected .npz or .csv")
