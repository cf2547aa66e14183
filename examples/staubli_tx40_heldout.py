"""The Staubli TX40 held-out table of docs/real_data.md ("The Staubli TX40"), reproduced.

The recording (motor side, coupled wrist, 5 kHz, no time vector) is not in the repository: give
the folder that holds ``tx40_motor_log.npz`` (FIGAROH's ``pos_read_data.csv`` and
``curr_data.csv`` of thanhndv212/figaroh-plus@c3b51728, ``examples/staubli_TX40/data``,
Apache-2.0, re-packed unchanged as the keys ``motor_position``, ``motor_torque`` (45000, 6) and
``sample_time`` 2e-4) and, for FIGAROH's rows, ``figaroh_1.0.2_heldout_predictions.npz`` (its
held-out predictions, ``pred_asis`` and ``pred_coupled``, samples 29270:44980)::

    python examples/staubli_tx40_heldout.py DATA_DIR [--output DIR] [--options "..."]
                                            [--friction-model symmetric|stribeck] [-- EXTRA]

What it does, as a user would:

1. writes the training rows 0:24750 and the held-out rows 29250:45000 of the log as two NPZ
   files (the same keys, ``sample_time`` 2e-4), the data's README split;
2. runs ``dynid identify train.npz --model examples/staubli_tx40.json --motor-side
   --columns q=motor_position,tau=motor_torque`` with the columns of FIGAROH's model (``--rotor
   --friction --offset``), the preparation the docs recommend for this log (``--cutoff 100
   --decimate 10``) and nothing else: every other preparation option at its default;
3. predicts the held-out rows with the result, prepared as the result records (the held-out file
   alone, as ``dynid validate`` does), and measures the README's yardstick: relative RMS per joint
   on samples 29270:44980 of the joint torque R^T tau_m decimated x10 with a zero-phase filter
   (``scipy.signal.decimate``; a prediction at 5 kHz is decimated the same way, one at the
   log's decimated rate is compared sample by sample).

It prints the table with FIGAROH's rows (recomputed from its shipped predictions with the same
yardstick) and writes ``heldout.json`` into the output folder. ``--friction-model stribeck``
puts ``--stribeck-friction`` (docs/identification.md, "Smooth Stribeck friction") in place of
``--friction`` in the options. Extra options after ``--`` go to
``dynid identify`` (e.g. ``-- --skip-end 50`` once that option exists).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
from scipy import signal

import dynid
from dynid.cli import main as dynid_main
from dynid.export.result_files import load_result
from dynid.identification.log_identification import run_validation

MODEL = Path(__file__).resolve().parent / "staubli_tx40.json"
COLUMNS = {"q": "motor_position", "tau": "motor_torque"}
TRAIN, HELD_OUT, SCORED = (0, 24750), (29250, 45000), (29270, 44980)
FACTOR = 10  # the README's decimation of the target
REST = 1e-12  # |qd| below this is rounding noise of a constant (filtered) angle
OPTIONS = [
    "--rotor",
    "--friction",
    "--offset",
    "--cutoff",
    "100",
    "--decimate",
    "10",
    "--rest-velocity",
    "auto",
]

#: --friction-model: the dynid identify flag of each friction model (coupled wrist: the
#: asymmetric model, which acts on each joint's velocity, refuses it).
FRICTION_FLAGS = {"symmetric": "--friction", "stribeck": "--stribeck-friction"}


def relative_rms(predicted: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """RMS of predicted - measured over RMS of measured, per joint (the README's yardstick)."""
    error = np.sqrt(np.mean((predicted - measured) ** 2, axis=0))
    return error / np.sqrt(np.mean(measured**2, axis=0))


def target(data: dict[str, np.ndarray], robot: dynid.Robot) -> np.ndarray:
    """The joint torque of the whole log, R^T tau_m, decimated x10 zero-phase: FIGAROH's fitting
    target; row k is sample 10 k."""
    R = np.diag(robot.gear_ratios) @ robot.transmission
    tau = data["motor_torque"] @ R
    return signal.decimate(tau, FACTOR, axis=0, zero_phase=True)


def scored_prediction(
    t: np.ndarray, predicted: np.ndarray, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """(rows of the decimated target, predictions there) on the scored samples 29270:44980.

    ``t`` are the prepared held-out log's times (t = 0 at sample 29250). At the log's own rate
    the prediction is decimated x10 as the target was (from a sample that is a multiple of 10);
    at a decimated rate the samples that fall on the target's grid are taken as they are."""
    index = HELD_OUT[0] + np.rint(t / dt).astype(int)
    step = int(np.median(np.diff(index)))
    if step == 1:
        first = int(np.argmax(index % FACTOR == 0))
        index, predicted = index[first:], predicted[first:]
        predicted = signal.decimate(predicted, FACTOR, axis=0, zero_phase=True)
        index = index[::FACTOR][: len(predicted)]
    keep = (index >= SCORED[0]) & (index < SCORED[1]) & (index % FACTOR == 0)
    return index[keep] // FACTOR, predicted[keep]


# Motor angles (before the gear) exceed the loader's 100 rad plausibility bound by design.
warnings.filterwarnings("ignore", message=r".*q: positions up to", category=UserWarning)


def run(
    data_dir: Path, output: Path, extra: list[str], options: list[str] = OPTIONS
) -> dict[str, object]:
    with np.load(data_dir / "tx40_motor_log.npz") as npz:
        data = {key: npz[key] for key in npz.files}
    dt = float(data["sample_time"])
    work = Path(tempfile.mkdtemp(prefix="tx40-"))
    for name, (lo, hi) in (("train", TRAIN), ("heldout", HELD_OUT)):
        np.savez(
            work / f"{name}.npz",
            motor_position=data["motor_position"][lo:hi],
            motor_torque=data["motor_torque"][lo:hi],
            sample_time=dt,
        )
    columns = ",".join(f"{k}={v}" for k, v in COLUMNS.items())
    argv = ["identify", str(work / "train.npz"), "--model", str(MODEL), "--motor-side"]
    argv += ["--columns", columns, *options, *extra, "--output", str(output), "--overwrite"]
    print("dynid " + " ".join(argv), flush=True)
    if dynid_main(argv) != 0:
        raise SystemExit("staubli_tx40_heldout: dynid identify failed")
    result = load_result(output)
    held_out = dynid.motor_to_joint(
        dynid.load_log(work / "heldout.npz", columns=COLUMNS), result.robot
    )
    validation = run_validation(result, held_out, preparation=result.training.get("preparation"))
    rows, predicted = scored_prediction(validation.log.t, validation.predicted, dt)
    # Diagnostic, not dynid's model: at rest the filtered encoder angle is constant up to
    # rounding, qd is +-1e-17 and sign(qd) picks +-Fs at random; with those qd set to 0 the
    # Coulomb term is 0 there (docs/real_data.md, "The Staubli TX40").
    at_rest = validation.log.replace(
        qd=np.where(np.abs(validation.log.qd) < REST, 0.0, validation.log.qd)
    )
    rest_rows, rest_predicted = scored_prediction(at_rest.t, result.predict(at_rest), dt)
    measured = target(data, result.robot)
    scored = SCORED[1] // FACTOR - SCORED[0] // FACTOR
    # The same model on the held-out samples' states prepared from the whole recording (no
    # filter edge at sample 29250; the torques of those samples are not used).
    whole = dynid.motor_to_joint(
        dynid.load_log(data_dir / "tx40_motor_log.npz", columns=COLUMNS), result.robot
    )
    again = run_validation(result, whole, preparation=result.training.get("preparation"))
    shifted = again.log.t - (HELD_OUT[0] - 0) * dt
    whole_rows, whole_predicted = scored_prediction(shifted, again.predicted, dt)
    table = {
        "dynid": (100 * relative_rms(predicted, measured[rows])).tolist(),
        "diagnostic: qd = 0 where |qd| < 1e-12": (
            100 * relative_rms(rest_predicted, measured[rest_rows])
        ).tolist(),
        "dynid, states from the whole log": (
            100 * relative_rms(whole_predicted, measured[whole_rows])
        ).tolist(),
        "dynid training": (100 * np.asarray(result.training["metrics"]["relative_rms"])).tolist(),
        "samples scored": f"{len(rows)} of {scored}",
        "command": "dynid " + " ".join([*argv[:1], "train.npz", *argv[2:-3]]),
        "preparation": result.training.get("preparation"),
    }
    peer = data_dir / "figaroh_1.0.2_heldout_predictions.npz"
    if peer.is_file():
        with np.load(peer) as npz:
            first = int(npz["rows"][0])
            for key, label in (
                ("pred_asis", "FIGAROH as shipped"),
                ("pred_coupled", "FIGAROH coupled"),
            ):
                pred = signal.decimate(npz[key], FACTOR, axis=0, zero_phase=True)
                ref = measured[first // FACTOR : first // FACTOR + len(pred)]
                table[label] = (100 * relative_rms(pred, ref)).tolist()
    (output / "heldout.json").write_text(json.dumps(table, indent=2) + "\n")
    return table


def main() -> None:
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1 :] if "--" in argv else []
    argv = argv[: argv.index("--")] if "--" in argv else argv
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter
    )
    parser.add_argument("data_dir", type=Path, help="folder holding tx40_motor_log.npz")
    parser.add_argument("--output", type=Path, default=Path("tx40-identify"))
    parser.add_argument(
        "--options",
        default=" ".join(OPTIONS),
        help=f"the model and preparation options of dynid identify (default {' '.join(OPTIONS)!r})",
    )
    parser.add_argument(
        "--friction-model",
        choices=FRICTION_FLAGS,
        default="symmetric",
        help="the friction model: the flag put in place of --friction in the options",
    )
    args = parser.parse_args(argv)
    options = [
        FRICTION_FLAGS[args.friction_model] if o == "--friction" else o
        for o in args.options.split()
    ]
    table = run(args.data_dir, args.output, extra, options)
    print(
        f"\nheld-out relative RMS (%), samples {SCORED[0]}:{SCORED[1]} ({table['samples scored']})"
    )
    print("| | J1 | J2 | J3 | J4 | J5 | J6 |\n|---|---|---|---|---|---|---|")
    for label in (
        "FIGAROH as shipped",
        "FIGAROH coupled",
        "dynid",
        "dynid, states from the whole log",
        "diagnostic: qd = 0 where |qd| < 1e-12",
    ):
        if label in table:
            values = table[label]
            print(f"| {label} | " + " | ".join(f"{v:.3g}" for v in values) + " |")  # type: ignore[union-attr]


if __name__ == "__main__":
    main()
