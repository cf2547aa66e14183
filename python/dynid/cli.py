"""The ``dynid`` command line."""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from .demo import check_demo_sizes, run_demo  # noqa: F401  (check_demo_sizes: public here too)

#: Exit status for bad input (missing file, malformed log, model or result), as argparse's.
EXIT_BAD_INPUT = 2
DEFAULT_MODEL = "kuka_lwr4"



def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="dynid", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    demo = commands.add_parser(
        "demo", help="the KUKA LWR-IV identification of Gaz et al. (ICRA 2014) on a simulated arm"
    )
    demo.add_argument("--output", default="dynid-demo", help="output folder (default ./dynid-demo)")
    demo.add_argument("--train", type=int, default=1000, help="training configurations")
    demo.add_argument("--validation", type=int, default=200, help="validation configurations")
    demo.add_argument("--seed", type=int, default=0)
    demo.set_defaults(run=_demo)
    _add_identify(commands)
    _add_validate(commands)
    _add_info(commands)
    args = parser.parse_args(argv)
    try:
        args.run(args)
    except BrokenPipeError:  # output piped into e.g. `head`: stop quietly
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 -- the interpreter closes it at exit
        return 1
    except (FileNotFoundError, ValueError, OSError) as exc:
        message = " ".join(str(exc).split())  # one line
        print(f"dynid {args.command}: error: {message}", file=sys.stderr)
        return EXIT_BAD_INPUT
    return 0


# --------------------------------------------------------------------------- parsers


def _add_identify(commands: Any) -> None:
    p = commands.add_parser(
        "identify", help="identify the base parameters on a measurement log (docs/cli.md)",
        description="Identify the base dynamic parameters of a DH model on a log (NPZ or CSV, "
        "docs/data.md) by least squares; write result.json and PNG plots.",
    )
    p.add_argument("log", help="measurement log, .npz or .csv")
    _add_model(p)
    p.add_argument("--rotor", action="store_true", help="add the rotor inertia columns Ia")
    p.add_argument("--friction", action="store_true",
                   help="add viscous and Coulomb friction columns Fv, Fs")
    p.add_argument("--offset", action="store_true",
                   help="add a constant torque (sensor offset) per joint")
    p.add_argument("--method", choices=("ols", "wls"), default="wls",
                   help="ordinary or weighted (per-joint noise) least squares (default wls)")
    _add_preparation(p)
    p.add_argument("--min-velocity", type=float, metavar="V",
                   help="drop samples where some joint has |qd| < V (friction near zero speed)")
    p.add_argument("--outliers", type=float, metavar="K",
                   help="drop torque spikes beyond K robust sigmas")
    p.add_argument("--output", default="dynid-identify", metavar="DIR",
                   help="output folder (default ./dynid-identify)")
    p.set_defaults(run=_identify)


def _add_validate(commands: Any) -> None:
    p = commands.add_parser(
        "validate", help="apply a saved identification to another log",
        description="Predict the torques of LOG with a result of `dynid identify` and report "
        "per-joint RMS, relative RMS, maximum error and R^2; write validation.json and plots.",
    )
    p.add_argument("result", help="result folder of `dynid identify`, or its result.json")
    p.add_argument("log", help="measurement log, .npz or .csv")
    _add_preparation(p)
    p.add_argument("--output", default="dynid-validate", metavar="DIR",
                   help="output folder (default ./dynid-validate)")
    p.set_defaults(run=_validate)


def _add_info(commands: Any) -> None:
    p = commands.add_parser(
        "info", help="show a model: DH table, parameters, base-parameter counts",
    )
    _add_model(p)
    p.set_defaults(run=_info)


def _add_model(p: argparse.ArgumentParser) -> None:
    p.add_argument("--model", default=DEFAULT_MODEL, metavar="NAME|FILE",
                   help="built-in model (kuka_lwr4, puma560, planar_2r) or a model file, JSON "
                   f"or YAML (docs/cli.md); default {DEFAULT_MODEL}")


def _add_preparation(p: argparse.ArgumentParser) -> None:
    p.add_argument("--skip", type=int, default=0, metavar="N",
                   help="drop the first N samples (start-up transient)")
    p.add_argument("--cutoff", type=float, metavar="HZ",
                   help="zero-phase Butterworth low-pass of q, qd, qdd, tau at HZ")
    p.add_argument("--order", type=int, default=4, help="order of that filter (default 4)")
    p.add_argument("--decimate", type=int, default=1, metavar="K", help="keep every K-th sample")


def _preparation(args: argparse.Namespace) -> dict[str, Any]:
    options: dict[str, Any] = {"cutoff": args.cutoff, "decimate": args.decimate}
    if args.cutoff is not None:
        options["order"] = args.order
    for key, option in (("min_velocity", "min_velocity"), ("outlier_k", "outliers")):
        if getattr(args, option, None) is not None:
            options[key] = getattr(args, option)
    return {k: v for k, v in options.items() if v is not None and not (k == "decimate" and v == 1)}


# --------------------------------------------------------------------------- commands


def _steps(total: int) -> Callable[[str], None]:
    start = time.perf_counter()
    count = [0]

    def step(text: str) -> None:
        count[0] += 1
        print(f"[{count[0]}/{total}] {text}  ({time.perf_counter() - start:.1f} s)", flush=True)

    return step


def _demo(args: argparse.Namespace) -> None:
    run_demo(args.output, train=args.train, validation=args.validation, seed=args.seed)


def _identify(args: argparse.Namespace) -> None:
    from .io import load_log
    from .log_identification import identify_log
    from .model_files import load_model

    step = _steps(5)
    log = load_log(args.log, skip=args.skip)
    step(f"log {args.log}: {log.T} samples, {log.n} joints, {log.fs:.4g} Hz, {log.duration:.4g} s"
         + (f" (first {args.skip} skipped)" if args.skip else ""))
    robot = load_model(args.model)
    step(f"model {args.model}: {robot.name}, {robot.n} joints, {robot.convention} DH")
    result = identify_log(log, robot, rotor=args.rotor, friction=args.friction,
                          offset=args.offset, method=args.method, preparation=_preparation(args))
    new_notes = result.training["notes"][len(log.notes):]
    step("prepared: " + ("; ".join(new_notes) if new_notes else "used as given (no filtering)"))
    step(f"identified {result.theta.size} coefficients on {result.training['samples']} samples")
    print(result.summary(), flush=True)
    path = result.save(args.output)
    step(f"wrote {path}, {path.parent / 'torques.png'}, {path.parent / 'residuals.png'}")


def _validate(args: argparse.Namespace) -> None:
    from .io import load_log, prepare_log
    from .log_identification import load_result
    from .model_files import dumps_json
    from .result_files import metrics_to_dict, save_plots
    from .validation import error_metrics

    step = _steps(3)
    result = load_result(args.result)
    log = load_log(args.log, skip=args.skip)
    options = _preparation(args)
    prepared = prepare_log(log, **options) if options else log
    step(f"result {args.result} ({result.model.get('name')}, {result.theta.size} coefficients); "
         f"log {args.log}: {prepared.T} samples")
    trained = result.training.get("preparation", {}).get("cutoff")
    if trained != options.get("cutoff"):
        print(f"note: the training log was {_filtered(trained)}, this one is "
              f"{_filtered(options.get('cutoff'))} (--cutoff)", flush=True)
    predicted = result.predict(prepared)
    metrics = error_metrics(prepared.tau, predicted)
    step("predicted the torques")
    train = result.training.get("metrics", {}).get("relative_rms")
    print(_validation_table(metrics, train))
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    report = {
        "format": "dynid-validation",
        "result": str(args.result),
        "log": str(args.log),
        "samples": prepared.T,
        "preparation": options,
        "notes": prepared.notes,
        "metrics": metrics_to_dict(metrics),
    }
    (out / "validation.json").write_text(dumps_json(report) + "\n")
    save_plots(out, prepared, predicted, "validation log")
    step(f"wrote {out / 'validation.json'}, {out / 'torques.png'}, {out / 'residuals.png'}")


def _filtered(cutoff: float | None) -> str:
    return "not low-passed" if cutoff is None else f"low-passed at {cutoff:g} Hz"


def _validation_table(metrics: dict[str, Any], train: Any) -> str:
    """Per-joint RMS, relative RMS (and the training log's), maximum error and R^2."""
    lines = ["  joint   rms [N m]   rel. rms   max [N m]        R2   rel. rms on training log"]
    for j in range(len(metrics["rms"])):
        trained = f"{100 * train[j]:>10.2f}%" if train is not None else ""
        lines.append(
            f"  J{j + 1:<5}{metrics['rms'][j]:>11.4g}{100 * metrics['relative_rms'][j]:>10.2f}%"
            f"{metrics['max_abs'][j]:>12.4g}{metrics['r2'][j]:>10.4f}{trained:>24}"
        )
    return "\n".join(lines)


def _info(args: argparse.Namespace) -> None:
    from .base_parameters import base_parameters
    from .model_files import load_model

    robot = load_model(args.model)
    print(f"{robot.name}: {robot.n} joints ({robot.joint_types}), {robot.convention} DH, "
          f"gravity {np.round(robot.gravity_vector, 6).tolist()}")
    modified = robot.convention == "modified"
    heads = ("a_{i-1}", "alpha_{i-1}") if modified else ("a", "alpha")
    print(f"  {'row':<4}{'type':<5}{heads[0]:>10}  {heads[1]:>16}  {'d':>10}  {'theta':>10}  "
          f"{'qmin':>8}  {'qmax':>8}")
    for i, (row, kind, lim) in enumerate(zip(robot.dh, robot.joint_types, robot.qlim)):
        alpha = f"{row[1]:.6g} ({np.degrees(row[1]):.4g}°)"
        print(f"  {i + 1:<4}{kind:<5}{row[0]:>10.6g}  {alpha:>16}  {row[2]:>10.6g}  "
              f"{row[3]:>10.6g}  {lim[0]:>8.4g}  {lim[1]:>8.4g}")
    for key in ("base", "tool"):
        value = np.asarray(getattr(robot, key))
        if not np.array_equal(value, np.eye(4)):
            print(f"  {key}: {np.round(value, 6).tolist()}")
    params = robot.params
    print(f"parameters (frame-i origin, SPEC order m mx my mz Ixx Ixy Ixz Iyy Iyz Izz); total "
          f"mass {params[:, 0].sum():.4g} kg, physically consistent: "
          f"{'yes' if robot.is_physically_consistent() else 'no'}")
    for i, row in enumerate(params):
        print(f"  link {i + 1}:" + "".join(f"{v:>11.4g}" for v in row))
    for key in ("Ia", "Fv", "Fs"):
        print(f"  {key}: " + " ".join(f"{v:.4g}" for v in getattr(robot, key)))
    counts = [
        (label, base_parameters(robot, "torque", rotor=rotor, friction=friction).count)
        for label, rotor, friction in (("rigid body", False, False), ("+ rotor", True, False),
                                       ("+ friction", False, True),
                                       ("+ rotor + friction", True, True))
    ]
    print("base parameters: torque " + ", ".join(f"{c} ({label})" for label, c in counts)
          + f"; gravity {base_parameters(robot, 'gravity').count}; inertia "
          f"{base_parameters(robot, 'inertia').count}")


if __name__ == "__main__":
    sys.exit(main())
