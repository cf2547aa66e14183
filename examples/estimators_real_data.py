"""Every estimator x every joint on the two real arms: the table of docs/real_data.md,
"Estimators on real data" (issue 23, item 3).

    python examples/estimators_real_data.py TX40_DIR [--lwr4 DIR] [--output DIR] [--overwrite]
                                            [--methods ols,wls,...]

TX40_DIR holds ``tx40_motor_log.npz`` and FIGAROH's ``figaroh_1.0.2_heldout_predictions.npz``
(examples/staubli_tx40_heldout.py says what they are); ``--lwr4`` the FloBaRoID LWR4+ logs
``measurements_1.npz`` and ``measurements_2.npz`` (default tests/data). Every method registered
at run time (``dynid.identification.estimators.methods()``: "ols", "wls", then every estimator)
is run with its default options, once unconstrained and once physically consistent
(``physical=True``), on:

- **LWR4+** (docs/real_data.md): train on measurements_1, held out measurements_2, both from
  sample 500 on; rotor, friction, offsets; the physical fit with the prior
  examples/kuka_lwr4_urdf_prior.json (default prior weight). Yardstick: relative RMS per joint
  on the held-out log (``dynid validate``).
- **TX40** (docs/real_data.md, "The Staubli TX40"): train on rows 0:24750, held out rows
  29250:45000; model examples/staubli_tx40.json, motor side, rotor, friction, offsets, cutoff
  100 Hz, decimation 10, in two preparations: with ``rest_velocity="auto"`` (the command of the
  docs; its caveat: the rest velocity is one encoder count at the cutoff, estimated from the
  recurring step of the quantized angle, docs/data.md) and the default preparation (no rest
  velocity). The physical fit has no prior (the URDF's link 6 has a zero inertia: no
  consistent prior). Yardstick: the data README's, relative RMS per joint on samples
  29270:44980 of the joint torque decimated x10 zero-phase (the functions of
  examples/staubli_tx40_heldout.py), beside FIGAROH 1.0.2's held-out rows.

Wall time: ``identify_log`` alone (preparation, regressors, the estimator, the physical SDP),
one run each, on whatever machine runs it. A method that refuses the data (e.g. "periodic" on a
log that is not periodic) is listed with its message. Writes ``table.md`` and ``table.json``
into the output folder (dynid's output folder: complete or absent) and prints the table.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import dynid
from dynid.export.output_folder import output_folder
from dynid.identification.estimators import methods
from dynid.identification.log_identification import identify_log, run_validation

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import staubli_tx40_heldout as tx40  # noqa: E402  (the TX40 yardstick, one home)

LWR4_PRIOR = HERE / "kuka_lwr4_urdf_prior.json"
LWR4_SKIP = 500
COLUMNS = {"rotor": True, "friction": True, "offset": True}
LWR4_COLUMNS: dict[str, dict[str, Any]] = {
    "LWR4+": {},
    "LWR4+, position torque": {"position_torque": True},
}
TX40_PREPARATIONS = {
    "TX40, rest velocity auto": {"cutoff": 100.0, "decimate": 10, "rest_velocity": "auto"},
    "TX40, default preparation": {"cutoff": 100.0, "decimate": 10},
}

#: The criterion's ratio bounds: physical / unconstrained, per data set (LWR4+: A1-A6).
RATIOS = {
    "TX40, rest velocity auto": 1.10,
    "TX40, default preparation": 1.10,
    "LWR4+": 1.25,
    "LWR4+, position torque": 1.25,
}

warnings.filterwarnings("ignore", message=r".*q: positions up to", category=UserWarning)


#: The accelerations' noise that method "tls" needs (no fit can tell it from the torques): the
#: standard deviation of each joint's prepared qdd above this fraction of its sampling rate,
#: where the arms' exciting motions (below 1 Hz) have no content left.
ACCELERATION_NOISE_BAND = 0.1


def acceleration_noise(log: Any, robot: dynid.Robot, preparation: dict[str, Any]) -> Any:
    """Per joint: the high-pass (above ACCELERATION_NOISE_BAND x fs) std of the prepared log's
    accelerations, the estimate given to "tls" (floored at 1e-6 rad/s^2: "tls" wants > 0)."""
    from dynid.logs.signal import lowpass

    options = {k: v for k, v in preparation.items() if k != "min_velocity"}
    prepared = dynid.prepare_log(log, **options) if options else log
    qdd = prepared.qdd
    if qdd is None:
        qdd = dynid.prepare_log(prepared, differentiate="missing").qdd
    high = qdd - lowpass(qdd, prepared.fs, ACCELERATION_NOISE_BAND * prepared.fs)
    return np.maximum(high.std(axis=0), 1e-6)


def timed_fit(log: Any, robot: dynid.Robot, **options: Any) -> tuple[Any, float, str]:
    """(result or None, wall time in s, the refusal's message or ""); method "tls" gets the
    log's :func:`acceleration_noise`."""
    start = time.perf_counter()
    if options.get("method") == "tls":
        noise = acceleration_noise(log, robot, options.get("preparation") or {})
        options["estimator_options"] = {"acceleration_noise": noise.tolist()}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            result = identify_log(log, robot, **COLUMNS, **options)
    except ValueError as error:
        return None, time.perf_counter() - start, str(error).splitlines()[0]
    return result, time.perf_counter() - start, ""


def lwr4_rows(folder: Path, chosen: list[str]) -> list[dict[str, Any]]:
    """Every method x {unconstrained, physical} on the LWR4+ logs, with the columns of the docs
    (rotor, friction, offsets) and with the position torque added to both fits."""
    train = dynid.load_log(folder / "measurements_1.npz", skip=LWR4_SKIP)
    held_out = dynid.load_log(folder / "measurements_2.npz", skip=LWR4_SKIP)
    robot = dynid.models.kuka_lwr4()
    rows = []
    for label, columns in LWR4_COLUMNS.items():
        for method in chosen:
            for physical in (False, True):
                extra = {"physical": True, "prior": LWR4_PRIOR} if physical else {}
                result, seconds, refused = timed_fit(
                    train, robot, method=method, **columns, **extra
                )
                error = None
                if result is not None:
                    validation = run_validation(
                        result, held_out, preparation=result.training.get("preparation")
                    )
                    error = (100 * validation.metrics["relative_rms"]).tolist()
                rows.append(_row(label, method, physical, error, seconds, refused, result))
    return rows


def tx40_rows(folder: Path, chosen: list[str]) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Every method x {unconstrained, physical} x both preparations on the TX40 recording, and
    FIGAROH's held-out rows."""
    with np.load(folder / "tx40_motor_log.npz") as npz:
        data = {key: npz[key] for key in npz.files}
    dt = float(data["sample_time"])
    robot = dynid.load_model(tx40.MODEL)

    def joint_side(lo: int, hi: int) -> dynid.Log:
        log = dynid.Log(
            t=dt * np.arange(hi - lo),
            q=data["motor_position"][lo:hi],
            tau=data["motor_torque"][lo:hi],
            source=f"tx40_motor_log.npz[{lo}:{hi}]",
        )
        return dynid.motor_to_joint(log, robot)

    train, held_out = joint_side(*tx40.TRAIN), joint_side(*tx40.HELD_OUT)
    measured = tx40.target(data, robot)
    rows = []
    for label, preparation in TX40_PREPARATIONS.items():
        for method in chosen:
            for physical in (False, True):
                result, seconds, refused = timed_fit(
                    train, robot, method=method, physical=physical, preparation=preparation
                )
                error = None
                if result is not None:
                    validation = run_validation(
                        result, held_out, preparation=result.training.get("preparation")
                    )
                    index, predicted = tx40.scored_prediction(
                        validation.log.t, validation.predicted, dt
                    )
                    error = (100 * tx40.relative_rms(predicted, measured[index])).tolist()
                rows.append(_row(label, method, physical, error, seconds, refused, result))
    peers = {}
    peer = folder / "figaroh_1.0.2_heldout_predictions.npz"
    if peer.is_file():
        with np.load(peer) as npz:
            first = int(npz["rows"][0]) // tx40.FACTOR
            for key, label in (("pred_asis", "as shipped"), ("pred_coupled", "coupled wrist")):
                pred = tx40.signal.decimate(npz[key], tx40.FACTOR, axis=0, zero_phase=True)
                reference = measured[first : first + len(pred)]
                peers[label] = (100 * tx40.relative_rms(pred, reference)).tolist()
    return rows, peers


def _row(
    data: str,
    method: str,
    physical: bool,
    error: list[float] | None,
    seconds: float,
    refused: str,
    result: Any,
) -> dict[str, Any]:
    row: dict[str, Any] = {
        "data": data,
        "method": method,
        "fit": "physical" if physical else "unconstrained",
        "relative_rms_percent": error,
        "seconds": seconds,
    }
    if refused:
        row["refused"] = refused
    if result is not None and result.estimator is not None:
        row["estimator"] = result.estimator
    return row


def criterion(rows: list[dict[str, Any]], peers: dict[str, Any]) -> dict[str, Any]:
    """Issue 23's criterion, per method: (a) on the TX40 (rest velocity auto) its held-out error
    within FIGAROH's on every joint (the better of FIGAROH's two rows per joint); (b) physical /
    unconstrained <= 1.10 on every TX40 joint (both preparations) and <= 1.25 on LWR4+ A1-A6."""
    figaroh = np.min([peers[k] for k in peers], axis=0) if peers else None
    found: dict[str, Any] = {}
    by_key = {(r["data"], r["method"], r["fit"]): r["relative_rms_percent"] for r in rows}
    for method in dict.fromkeys(r["method"] for r in rows):
        entry: dict[str, Any] = {}
        tx = by_key.get(("TX40, rest velocity auto", method, "unconstrained"))
        if tx is not None and figaroh is not None:
            entry["tx40_within_figaroh"] = bool(np.all(np.array(tx) <= figaroh))
        for data, bound in RATIOS.items():
            joints = slice(0, 6)  # every TX40 joint; A1-A6 of the LWR4+
            free = by_key.get((data, method, "unconstrained"))
            consistent = by_key.get((data, method, "physical"))
            if free is None or consistent is None:
                continue
            ratio = (np.array(consistent) / np.array(free))[joints]
            entry[f"{data}: physical / unconstrained"] = ratio.tolist()
            entry[f"{data}: within {bound}"] = bool(np.all(ratio <= bound))
        found[method] = entry
    return found


def best(rows: list[dict[str, Any]]) -> list[str]:
    """Markdown: per data set and fit, the method with the lowest held-out error on each joint
    and the one with the lowest mean over the joints (the table the default is chosen from)."""
    lines = ["Best method per joint (lowest held-out error) and over the joints (lowest mean):", ""]
    lines += ["| data | fit | per joint | lowest mean |", "|---|---|---|---|"]
    for data in dict.fromkeys(r["data"] for r in rows):
        for fit in ("unconstrained", "physical"):
            scored = [
                r
                for r in rows
                if r["data"] == data and r["fit"] == fit and r["relative_rms_percent"]
            ]
            if not scored:
                continue
            errors = np.array([r["relative_rms_percent"] for r in scored])
            winners = np.argmin(errors, axis=0)
            per_joint = ", ".join(
                f"{scored[k]['method']} {errors[k, j]:.3g}" for j, k in enumerate(winners)
            )
            mean = int(np.argmin(errors.mean(axis=1)))
            lowest = f"{scored[mean]['method']} {errors[mean].mean():.3g}"
            lines.append(f"| {data} | {fit} | {per_joint} | {lowest} |")
    return [*lines, ""]


def markdown(rows: list[dict[str, Any]], peers: dict[str, Any], check: dict[str, Any]) -> str:
    lines = []
    for data in dict.fromkeys(r["data"] for r in rows):
        subset = [r for r in rows if r["data"] == data]
        n = len(next(r for r in subset if r["relative_rms_percent"])["relative_rms_percent"])
        prefix = "A" if data.startswith("LWR4+") else "J"
        names = [f"{prefix}{j}" for j in range(1, n + 1)]
        lines += [f"**{data}**: held-out relative RMS (%), wall time of identify_log", ""]
        lines += ["| method | fit | " + " | ".join(names) + " | mean | time [s] |"]
        lines += ["|---|---|" + "---|" * n + "---|---|"]
        if data.startswith("TX40"):
            for label, values in peers.items():
                lines.append(
                    f"| FIGAROH 1.0.2, {label} | | "
                    + " | ".join(f"{v:.3g}" for v in values)
                    + f" | {np.mean(values):.3g} | |"
                )
        for r in subset:
            if r["relative_rms_percent"] is None:
                # "period: log 1 (path) is not periodic: ...; ..." -> "log 1 is not periodic"
                why = re.sub(r" \(.*?\)", "", r["refused"]).split(": ")[1].split(";")[0]
                why = why.replace("|", "/")
                cells = f"refused: {why} |" + " |" * n
            else:
                values = r["relative_rms_percent"]
                cells = " | ".join(f"{v:.3g}" for v in values) + f" | {np.mean(values):.3g} |"
            lines.append(f"| {r['method']} | {r['fit']} | {cells} {r['seconds']:.2f} |")
        lines.append("")
    lines += best(rows)
    lines += [
        "**Criterion** (issue 23): the method's unconstrained TX40 error (rest velocity auto) "
        "at most FIGAROH's (the better of its two rows) on every joint; the largest ratio "
        "physical / unconstrained over the TX40 joints (bound 1.10) and over LWR4+ A1-A6 "
        "(bound 1.25), with the joint where it is reached",
        "",
        "| method | TX40 within FIGAROH | " + " | ".join(RATIOS) + " |",
        "|---|---|" + "---|" * len(RATIOS),
    ]
    for method, entry in check.items():
        within = entry.get("tx40_within_figaroh")
        cells = ["–" if within is None else ("yes" if within else "**no**")]
        for data, bound in RATIOS.items():
            ratio = entry.get(f"{data}: physical / unconstrained")
            if ratio is None:
                cells.append("–")
                continue
            worst = int(np.argmax(ratio))
            mark = "" if ratio[worst] <= bound else "**"
            prefix = "A" if data.startswith("LWR4+") else "J"
            cells.append(f"{mark}{ratio[worst]:.2f}{mark} ({prefix}{worst + 1})")
        lines.append(f"| {method} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter
    )
    parser.add_argument("tx40_dir", type=Path, help="folder holding tx40_motor_log.npz")
    parser.add_argument(
        "--lwr4", type=Path, default=HERE.parent / "tests" / "data", help="the LWR4+ logs' folder"
    )
    parser.add_argument("--output", type=Path, default=Path("estimators-real-data"))
    parser.add_argument("--overwrite", action="store_true")
    parser.add_argument(
        "--methods", help=f"comma-separated subset of {', '.join(methods())} (default: all)"
    )
    args = parser.parse_args(argv)
    chosen = list(methods()) if args.methods is None else args.methods.split(",")
    unknown = [m for m in chosen if m not in methods()]
    if unknown:
        parser.error(f"--methods: {unknown} not among {list(methods())}")
    with output_folder(args.output, args.overwrite, "--output") as staging:
        rows, peers = tx40_rows(args.tx40_dir, chosen)
        rows = lwr4_rows(args.lwr4, chosen) + rows
        check = criterion(rows, peers)
        text = markdown(rows, peers, check)
        (staging / "table.md").write_text(text)
        document = {"rows": rows, "figaroh": peers, "criterion": check, "methods": chosen}
        (staging / "table.json").write_text(json.dumps(document, indent=1, default=str) + "\n")
    print(text)


if __name__ == "__main__":
    main()
