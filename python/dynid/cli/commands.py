"""What each ``dynid`` command does: load its inputs, call the library, print, write."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from typing import Any

from .run_config import RUN_FILE, run_yaml
from .run_warnings import recorded_warnings


def _steps(total: int) -> Callable[[str], None]:
    start = time.perf_counter()
    count = [0]

    def step(text: str) -> None:
        count[0] += 1
        print(f"[{count[0]}/{total}] {text}  ({time.perf_counter() - start:.1f} s)", flush=True)

    return step


def log_options(args: argparse.Namespace, joint_names: Any = None) -> dict[str, Any]:
    """The ``load_log`` options given on the command line; ``joint_names``: the model's, which
    the joints of a ROS bag are matched to."""
    from ..logs.columns import parse_columns

    columns = parse_columns(args.columns) if args.columns is not None else None
    return {
        "skip": args.skip,
        "columns": columns,
        "time_unit": args.time_unit,
        # motor currents as tau (UR RTDE's actual_current_i; a ROS bag's effort)
        "current": getattr(args, "current", False),
        "drop_nonfinite": args.drop_nonfinite,
        "sample_time": getattr(args, "sample_time", None),
        "skip_end": getattr(args, "skip_end", 0) or 0,
        **ros_bag_options(args, joint_names),
    }


def ros_bag_options(args: argparse.Namespace, joint_names: Any) -> dict[str, Any]:
    """``load_log``'s options for ROS bags (docs/data.md, "ROS bags"): --topic and the model's
    joint names (the message's joints are matched to them)."""
    options: dict[str, Any] = {"joint_names": joint_names}
    if args.topic is not None:
        options["topic"] = args.topic
    return options


def log_reading(log: Any) -> str:
    """The log's format and what reading it did (rows dropped, time unit converted): the notes
    after its load note, for the command's output."""
    loaded = [i for i, note in enumerate(log.notes) if note.startswith("loaded from ")]
    after = log.notes[loaded[-1] + 1 :] if loaded else []
    done = [note for note in after if not note.startswith("skipped the first")]
    return f"{log.format or 'unknown format'}" + (f"; {'; '.join(done)}" if done else "")


def load_log_of(args: argparse.Namespace, joint_names: Any = None, path: Any = None) -> Any:
    """``load_log(path or args.log, ...)``; for a motor-side log without the warning of positions
    beyond
    100 rad, which motor angles (before the gear) may well exceed: ``to_joint_side`` checks the
    joint angles instead."""
    import warnings

    from ..logs.log_files import load_log

    with warnings.catch_warnings():
        if getattr(args, "motor_side", False):
            warnings.filterwarnings("ignore", message=r".*q: positions up to", category=UserWarning)
        return load_log(args.log if path is None else path, **log_options(args, joint_names))


def to_joint_side(args: argparse.Namespace, log: Any, robot: Any) -> Any:
    """With ``--motor-side``, ``log`` mapped to the joints through ``robot``'s gear ratios,
    transmission and joint offsets (dynid.logs.motor_side); otherwise ``log`` as it is."""
    if not getattr(args, "motor_side", False):
        return log
    from ..logs.log_files import check_plausible
    from ..logs.motor_side import motor_to_joint

    joint_log = motor_to_joint(log, robot)
    print(f"note: {joint_log.notes[-1]}", flush=True)
    check_plausible(joint_log, f"{log.source} (joint side)", unit_given=True)
    return joint_log


#: prepare_log options and the command-line flags that set them.
PREPARATION_FLAGS = {
    "cutoff": "cutoff",
    "order": "order",
    "decimate": "decimate",
    "min_velocity": "min_velocity",
    "outlier_k": "outliers",
    "nonuniform": "nonuniform",
    "trim_edges": "edge_trim",
    "rest_velocity": "rest_velocity",
}


def given_preparation(args: argparse.Namespace) -> dict[str, Any]:
    """The ``prepare_log`` options given on the command line (nothing for those left out)."""
    given = {
        key: getattr(args, flag)
        for key, flag in PREPARATION_FLAGS.items()
        if getattr(args, flag, None) is not None
    }
    if "order" in given and "cutoff" not in given:
        given.pop("order")  # the order of a low-pass that is not asked for
    return given


def preparation_options(args: argparse.Namespace) -> dict[str, Any]:
    """The ``prepare_log`` options given on the command line, defaults left out (the order 4 of
    a --cutoff made explicit)."""
    options = given_preparation(args)
    if "cutoff" in options:
        options.setdefault("order", 4)
    return _without_defaults(options)


def estimator_options(args: argparse.Namespace, method: str) -> dict[str, Any]:
    """The options of the estimator ``method`` given on the command line: each option of a
    registered estimator (``dynid.identification.estimators``) is the flag of the same name
    (``loss`` is ``--loss``); a flag of another estimator's is refused."""
    from ..identification.estimators.registry import LEAST_SQUARES, REGISTRY, estimator, method_name

    method_name(method)
    takes = () if method in LEAST_SQUARES else estimator(method).options
    options = {}
    for name in dict.fromkeys(o for r in REGISTRY.values() for o in r.options):
        value = getattr(args, name, None)
        if value is None:
            continue
        if name not in takes:
            flag = "--" + name.replace("_", "-")
            raise ValueError(f"{flag}: not an option of --method {method}")
        options[name] = value
    return options


def _without_defaults(options: dict[str, Any]) -> dict[str, Any]:
    defaults = {"decimate": 1, "nonuniform": "resample", "trim_edges": True}
    return {k: v for k, v in options.items() if not (k in defaults and v == defaults[k])}


def demo(args: argparse.Namespace) -> None:
    from .demo import run_demo

    run_demo(
        args.output,
        train=args.train,
        validation=args.validation,
        seed=args.seed,
        overwrite=args.overwrite,
    )


def identify(args: argparse.Namespace) -> None:
    with recorded_warnings() as seen:  # for report.html; shown as they happen all the same
        _identify(args, seen)


def _identify(args: argparse.Namespace, seen: list[str]) -> None:
    from ..export.output_folder import check_output_path
    from ..export.result_files import save_result
    from ..identification.log_identification import identify_log

    check_output_path(args.output, args.overwrite, inputs=identify_inputs(args))  # before the work
    if not args.log:
        raise ValueError("LOG: give at least one measurement log (or `log:` in --config)")
    check_links(args, args.model, args.prior)
    if args.current and args.motor_side:
        raise ValueError("--motor-side: not with --current (motor torques, not currents)")
    if args.current:
        if len(args.log) != 1:
            raise ValueError("--current: one LOG (several logs are not supported with currents)")
        identify_from_currents(args, seen)
        return
    if any(getattr(args, k) is not None for k in ("payload_log", "payload", "payload_mass")):
        raise ValueError("--payload-log, --payload, --payload-mass: only with --current")
    if args.method == "nls":
        raise ValueError(f"--method {args.method}: only with --current (motor currents)")
    if not args.physical and (args.prior is not None or args.prior_weight is not None):
        raise ValueError("--prior, --prior-weight: only with --physical")
    friction = friction_option(args)
    step = _steps(5)
    robot = load_robot(args, args.model)  # first: a ROS bag's joints are matched to its names
    logs = [load_log_of(args, robot.joint_names, path) for path in args.log]
    step(
        "; ".join(
            f"log {path} ({log_reading(log)}): {log.T} samples, {log.n} joints, "
            f"{log.fs:.4g} Hz, {log.duration:.4g} s"
            for path, log in zip(args.log, logs)
        )
        + (f" (first {args.skip} skipped)" if args.skip else "")
    )
    step(f"model {args.model}: {robot.name}, {robot.n} joints, {robot.convention} DH")
    logs = [to_joint_side(args, log, robot) for log in logs]
    # The prior is read here, a URDF's chain chosen by --tip-link, --base-link; the result
    # records it by its path all the same.
    prior = load_robot(args, args.prior) if args.prior is not None else None
    method = args.method or "wls"
    result = identify_log(
        logs if len(logs) > 1 else logs[0],
        robot,
        rotor=args.rotor,
        friction=friction,
        offset=args.offset,
        method=method,
        preparation=preparation_options(args),
        physical=args.physical,
        prior=prior,
        prior_weight=args.prior_weight,
        position_torque=args.position_torque,
        estimator_options=estimator_options(args, method),
    )
    if result.physical is not None and args.prior is not None:
        result.physical["prior"] = str(args.prior)
    step("prepared: " + _preparation_notes(result, logs))
    step(f"identified {result.theta.size} coefficients on {result.training['samples']} samples")
    print(result.summary(), flush=True)
    if getattr(args, "motor_side", False):  # validate maps its log the same way
        result.training["motor_side"] = True
    path = save_result(
        result,
        args.output,
        overwrite=args.overwrite,
        inputs=identify_inputs(args),
        # The defaults worked out here, as the run used them: the method, the prior's weight.
        files={RUN_FILE: run_yaml(args, method=method, **_resolved_prior(result))},
        report=args.report,
        report_warnings=seen,
    )
    step(
        f"wrote {path}, {path.parent / RUN_FILE}, {path.parent / 'torques.png'}, "
        f"{path.parent / 'residuals.png'}"
        + (" (and per log)" if len(logs) > 1 else "")
        + _report_written(args, path)
    )


def friction_option(args: argparse.Namespace) -> bool | str:
    """``friction`` of identify_log from --friction, --asymmetric-friction and
    --stribeck-friction (at most one of them)."""
    flags = {
        "--friction": args.friction,
        "--asymmetric-friction": args.asymmetric_friction,
        "--stribeck-friction": getattr(args, "stribeck_friction", False),
    }
    chosen = [flag for flag, on in flags.items() if on]
    if len(chosen) > 1:
        raise ValueError(f"{', '.join(chosen)}: choose one friction model")
    if args.asymmetric_friction:
        return "asymmetric"
    if getattr(args, "stribeck_friction", False):
        return "stribeck"
    return bool(args.friction)


def _resolved_prior(result: Any) -> dict[str, Any]:
    """The prior weight a physical fit used (its default when --prior-weight is not given)."""
    if result.physical is None or result.physical.get("prior") is None:
        return {}
    return {"prior_weight": result.physical["prior_weight"]}


def _preparation_notes(result: Any, logs: list[Any]) -> str:
    """What preparing the logs did (the notes beyond those of loading them), per log when
    there are several."""
    entries = result.training.get("logs")
    if entries is None:
        new = result.training["notes"][len(logs[0].notes) :]
        return "; ".join(new) if new else "used as given (no filtering)"
    parts = []
    for log, entry in zip(logs, entries):
        new = entry["notes"][len(log.notes) :]
        parts.append(f"{log.source}: " + ("; ".join(new) if new else "used as given"))
    return "; ".join(parts + list(result.training["notes"]))


def identify_inputs(args: argparse.Namespace) -> list[str | None]:
    """The files ``dynid identify`` reads (options not given are None; built-in model names and
    payload numbers are no files), which ``--overwrite`` must never delete."""
    return [
        *args.log,
        args.model,
        args.prior,
        args.payload_log,
        args.payload,
        args.config,
        *closed_loop_inputs(args),
    ]


def closed_loop_inputs(args: argparse.Namespace) -> list[str | None]:
    """The files of --method iv/didim: --reference, --controller-model."""
    return [getattr(args, "reference", None), getattr(args, "controller_model", None)]


def model_links(args: argparse.Namespace, source: Any) -> dict[str, str | None]:
    """``--tip-link``/``--base-link`` as ``load_model``'s arguments when ``source`` is a URDF
    (a DH table has no links to choose): empty otherwise."""
    if source is None or not str(source).lower().endswith(".urdf"):
        return {}
    links = {
        "tip_link": getattr(args, "tip_link", None),
        "base_link": getattr(args, "base_link", None),
    }
    return {k: v for k, v in links.items() if v is not None}


def check_links(args: argparse.Namespace, *sources: Any) -> None:
    """``--tip-link``/``--base-link`` given but no URDF among the command's models: an error
    (they would otherwise be ignored)."""
    given = [
        f"--{k.replace('_', '-')}" for k in ("tip_link", "base_link") if getattr(args, k, None)
    ]
    if given and not any(str(s).lower().endswith(".urdf") for s in sources if s is not None):
        raise ValueError(f"{', '.join(given)}: only with a URDF model (.urdf)")


def load_robot(args: argparse.Namespace, source: Any) -> Any:
    """``load_model(source)`` with the command's ``--tip-link``/``--base-link`` when ``source``
    is a URDF; a URDF with several leaves and no ``--tip-link`` says to give one."""
    from ..model.model_files import load_model

    links = model_links(args, source)
    try:
        return load_model(source, **links)
    except ValueError as exc:
        if "tip_link" in str(exc) and "tip_link" not in links:
            raise ValueError(f"{exc} (on the command line: --tip-link LINK)") from None
        raise


def identify_from_currents(args: argparse.Namespace, seen: list[str] | None = None) -> None:
    """``dynid identify --current``: drive gains and base parameters from motor currents."""
    from ..export.result_files import save_result
    from ..identification.drive_gains import identify_drive_gains
    from ..identification.payload_files import load_payload
    from ..logs.log_files import load_log
    from ..model.model_files import load_model

    if args.physical or args.prior is not None:
        raise ValueError("--current: not with --physical or --prior")
    friction = friction_option(args)
    if args.payload_log is None:
        raise ValueError(
            "--current: needs --payload-log LOG, a run with a known payload: currents fix the "
            "parameters and gains only up to a common scale, which the payload determines"
        )
    if (args.payload is None) == (args.payload_mass is None):
        raise ValueError("--current: give exactly one of --payload FILE|NUMBERS, --payload-mass KG")
    payload = load_payload(args.payload) if args.payload is not None else None
    step = _steps(5)
    robot = load_model(args.model, **model_links(args, args.model))  # first: a ROS bag's joints
    log = load_log(args.log[0], **log_options(args, robot.joint_names))
    loaded = load_log(args.payload_log, **log_options(args, robot.joint_names))
    step(
        f"logs {args.log[0]} ({log_reading(log)}; {log.T} samples), {args.payload_log} "
        f"({log_reading(loaded)}; {loaded.T} samples, loaded)"
    )
    step(f"model {args.model}: {robot.name}, {robot.n} joints, {robot.convention} DH")
    gains = identify_drive_gains(
        robot,
        log,
        loaded,
        payload=payload,
        payload_mass=args.payload_mass,
        rotor=args.rotor,
        friction=friction,
        offset=args.offset,
        position_torque=args.position_torque,
        method=args.method or "nls",
        preparation=preparation_options(args),
    )
    result = gains.result
    new_notes = result.training["notes"][len(log.notes) :]
    step("prepared: " + "; ".join(new_notes))
    step(
        f"identified {gains.gains.size} drive gains and {result.theta.size} coefficients on "
        f"{sum(run['samples'] for run in gains.runs)} samples"
    )
    print(gains.summary(), flush=True)
    path = save_result(
        result,
        args.output,
        overwrite=args.overwrite,
        inputs=identify_inputs(args),
        files={RUN_FILE: run_yaml(args, method=args.method or "nls")},
        report=args.report,
        report_warnings=seen or [],
    )
    step(
        f"wrote {path}, {path.parent / 'torques.png'}, {path.parent / 'residuals.png'}"
        + _report_written(args, path)
    )


def validate(args: argparse.Namespace) -> None:
    with recorded_warnings() as seen:  # for report.html; shown as they happen all the same
        _validate(args, seen)


def _validate(args: argparse.Namespace, seen: list[str]) -> None:
    from ..export.output_folder import check_output_path
    from ..export.result_files import load_result, save_validation
    from ..identification.log_identification import run_validation
    from ..identification.validation import validation_table

    if args.result is None or args.log is None:
        raise ValueError("RESULT, LOG: give a result and a log (or `result:`, `log:` in --config)")
    check_output_path(args.output, args.overwrite, inputs=[args.result, args.log, args.config])
    step = _steps(3)
    if args.current and args.motor_side:
        raise ValueError("--motor-side: not with --current (motor torques, not currents)")
    result = load_result(args.result)
    if result.training.get("motor_side") and args.motor_side is None:
        # trained on a motor-side log: this log is read the same way (as the preparation is)
        print("note: --motor-side (recorded in the result)", flush=True)
        args.motor_side = True
    log = to_joint_side(args, load_log_of(args, result.robot.joint_names), result.robot)
    if args.current:
        from ..identification.drive_gains import torques_from_currents

        log = torques_from_currents(result, log)
    elif result.drive_gains is not None:
        print(
            "note: the result was identified from motor currents; pass --current if LOG "
            "holds currents",
            flush=True,
        )
    options, sources = validation_preparation(result, args)
    validation = run_validation(result, log, preparation=options)
    step(
        f"result {args.result} ({result.model.get('name')}, {result.theta.size} coefficients); "
        f"log {args.log} ({log_reading(log)}): {validation.log.T} samples"
    )
    print(f"preparation applied: {sources}", flush=True)
    new_notes = validation.log.notes[len(log.notes) :]
    if new_notes:
        print("prepared: " + "; ".join(new_notes), flush=True)
    for note in validation.notes:
        print(f"note: {note}", flush=True)
    step("predicted the torques")
    print(
        validation_table(
            validation.metrics,
            training_relative_rms=result.training.get("metrics", {}).get("relative_rms"),
        )
    )
    path = save_validation(
        validation,
        args.output,
        result_source=str(args.result),
        log_source=str(args.log),
        overwrite=args.overwrite,
        files={RUN_FILE: run_yaml(args)},
        report=args.report,
        result=result,
        report_warnings=seen,
    )
    step(
        f"wrote {path}, {path.parent / 'torques.png'}, {path.parent / 'residuals.png'}"
        + _report_written(args, path)
    )


def _report_written(args: argparse.Namespace, path: Any) -> str:
    """ ", FOLDER/report.html" when the command wrote it (not with --no-report)."""
    return f", {path.parent / 'report.html'}" if args.report else ""


def validation_preparation(result: Any, args: argparse.Namespace) -> tuple[dict[str, Any], str]:
    """The preparation of ``dynid validate``: the training log's, as recorded in the result
    (``training.preparation``), unless --no-recorded-preparation; each option given on the
    command line replaces the recorded one. Returns the options and, in words, where each came
    from."""
    recorded: dict[str, Any] = {}
    if args.recorded_preparation:
        recorded = dict(result.training.get("preparation", {}))
        recorded.pop("reference_tau", None)  # a torque of the training log: no use here
    given = given_preparation(args)
    options = {**recorded, **given}
    if "cutoff" in options:
        options.setdefault("order", 4)
    options = _without_defaults(options)
    if not options:
        return options, "none (the log as given, qd and qdd differentiated when missing)"
    flags = {k: f"--{f.replace('_', '-')}" for k, f in PREPARATION_FLAGS.items()}
    flags["trim_edges"] = "--edge-trim"

    def flag(key: str, value: Any) -> str:
        if key == "trim_edges":
            return "--edge-trim" if value else "--no-edge-trim"
        return f"{flags[key]} {value}"

    words = [
        flag(k, v) + (" (command line)" if k in given else " (recorded in the result)")
        for k, v in options.items()
    ]
    return options, ", ".join(words)


def export(args: argparse.Namespace) -> None:
    from ..export.result_files import export_robot

    check_links(args, args.source, args.into)  # the links choose a URDF source's or --into's chain
    written = export_robot(
        args.source,
        args.urdf,
        mjcf=args.mjcf,
        into=args.into,
        base_link=getattr(args, "base_link", None),
        tip_link=getattr(args, "tip_link", None),
        name=args.name,
        overwrite=args.overwrite,
        model_file=args.model_file,
    )
    print(f"wrote {', '.join(map(str, written))}", flush=True)


def residual(args: argparse.Namespace) -> None:
    from ..export.output_folder import check_output_path, output_folder
    from ..export.result_files import load_model_or_result
    from ..identification.observer import plot_residual, residual_from_log, save_residual
    from ..logs.log_files import load_log

    inputs = [args.model, args.log]
    check_output_path(args.output, args.overwrite, inputs=inputs)
    check_links(args, args.model)
    model = load_model_or_result(args.model, **model_links(args, args.model))
    log = load_log(args.log, **log_options(args, _joint_names(model)))
    result = residual_from_log(model, log, args.gain)
    with output_folder(args.output, args.overwrite, inputs=inputs) as staging:
        save_residual(result, staging / "residual.npz")
        plot_residual(result, staging / "residual.png", threshold=args.threshold)
    print(f"momentum observer, gain {args.gain:g} 1/s, {log.T} samples at dt {result.dt:.4g} s")
    print("  joint   rms [N m]   max |r| [N m]")
    for j, (rms, largest) in enumerate(zip(result.rms, result.max_abs)):
        print(f"  J{j + 1:<5}{rms:>11.4g}{largest:>16.4g}")
    print(f"wrote {args.output}/residual.npz, {args.output}/residual.png", flush=True)


def simulate(args: argparse.Namespace) -> None:
    """``dynid simulate``: rehearse an experiment and write the log its controller would record
    (docs/workflow.md)."""
    import json

    from ..excitation.trajectory_files import load_trajectory
    from ..export.output_folder import check_output_path, output_folder
    from ..export.result_files import load_model_or_result
    from ..identification.log_identification import LogIdentification
    from ..identification.realize import consistent_robot
    from ..logs.log_files import Log, save_log
    from ..logs.ros_bag_writer import write_ros_bag
    from ..sim.rehearsal import rehearse

    inputs = [args.model, args.trajectory]
    check_output_path(args.output, args.overwrite, inputs=inputs)
    check_links(args, args.model)
    loaded = load_model_or_result(args.model, **model_links(args, args.model))
    # A result: its robot (a least-squares one's closest physically consistent robot).
    robot = consistent_robot(loaded) if isinstance(loaded, LogIdentification) else loaded
    plan = load_trajectory(args.trajectory)
    if plan.trajectory.n != robot.n:
        raise ValueError(
            f"TRAJECTORY: {plan.trajectory.n} joints for a {robot.n}-joint MODEL ({robot.name})"
        )
    kp = None if args.kp is None else _joint_values(args.kp, robot.n, "--kp")
    kd = None if args.kd is None else _joint_values(args.kd, robot.n, "--kd")
    run = rehearse(
        robot,
        plan.evaluate,
        plan.duration,
        controller=args.controller,
        kp=kp,
        kd=kd,
        bandwidth=args.bandwidth,
        rate=args.rate,
        friction=not args.no_friction,
        torque_noise=args.torque_noise,
        sensor_noise=args.sensor_noise,
        encoder_counts=args.encoder_counts,
        seed=args.seed,
    )
    notes = [
        f"simulated by dynid simulate: {robot.name} tracking {args.trajectory} under "
        f"{args.controller} at {args.rate:g} Hz"
    ]
    log = Log(
        t=run.t,
        q=run.q,
        tau=run.tau,
        qd=run.simulation.qd if args.velocities else None,
        source=str(args.trajectory),
        notes=notes,
        format="dynid simulate",
    )
    settings = {
        "model": str(args.model),
        "robot": robot.name,
        "trajectory": str(args.trajectory),
        "joint_names": list(robot.joint_names),
        **run.settings,
    }
    name = {"npz": "log.npz", "csv": "log.csv", "bag": "bag"}[args.format]
    with output_folder(args.output, args.overwrite, inputs=inputs) as staging:
        if args.format == "bag":
            write_ros_bag(log, staging / name, robot.joint_names)
        else:
            save_log(log, staging / name)
        (staging / "simulation.json").write_text(json.dumps(settings, indent=1) + "\n")
        (staging / RUN_FILE).write_text(run_yaml(args))
    errors = " ".join(f"{1000 * e:.3g}" for e in run.tracking_error)
    print(
        f"simulated {robot.name} ({robot.n} joints) for {plan.duration:.4g} s at {args.rate:g} Hz "
        f"under {args.controller}; tracking error max [mrad]: {errors}",
        flush=True,
    )
    print(f"wrote {args.output}/{name}, {args.output}/simulation.json", flush=True)


def excite(args: argparse.Namespace) -> None:
    """``dynid excite``: optimise the experiment's trajectory and write its files."""
    import numpy as np

    from ..excitation.experiment import design_experiment
    from ..export.output_folder import check_output_path
    from ..export.trajectory_out import save_trajectory_folder

    inputs = [args.model, args.prior]
    check_output_path(args.output, args.overwrite, inputs=inputs)
    check_links(args, args.model, args.prior)
    for option, rate in (("--rate", args.rate), ("--ros-rate", args.ros_rate)):
        if not (np.isfinite(rate) and rate > 0):  # checked before the optimisation, not after
            raise ValueError(f"{option}: expected a positive rate [Hz], got {rate:g}")
    robot = load_robot(args, args.model).copy()
    prior = None if args.prior is None else load_robot(args, args.prior)
    if prior is not None and prior.n != robot.n:
        raise ValueError(f"--prior: expected a model with {robot.n} joints, got {prior.n}")
    qlim = robot.qlim.copy()
    for column, given, option in ((0, args.q_min, "--q-min"), (1, args.q_max, "--q-max")):
        if given is not None:
            qlim[:, column] = _joint_values(given, robot.n, option)
    if np.any(qlim[:, 0] >= qlim[:, 1]):
        raise ValueError("--q-min, --q-max: expected each lower limit below its upper limit")
    robot.qlim = qlim
    urdf_velocity, urdf_effort = _model_limits(robot)
    qd_max = _limit_option(args.qd_max, urdf_velocity, 1.0, robot.n, "--qd-max")
    qdd_max = _limit_option(args.qdd_max, None, 2.0, robot.n, "--qdd-max")
    tau_max = _limit_option(args.tau_max, urdf_effort, None, robot.n, "--tau-max")
    keep_out = _keep_out(args, robot)
    start = time.perf_counter()
    last = [start]

    def progress(iteration: int, cond: float) -> None:
        now = time.perf_counter()
        if now - last[0] >= 2.0:  # a line every 2 s at most, on stderr (stdout: the summary)
            last[0] = now
            print(
                f"dynid excite: iteration {iteration}, cond {cond:.4g} ({now - start:.1f} s)",
                file=sys.stderr,
                flush=True,
            )

    plan, result = design_experiment(
        robot,
        qd_max=qd_max,
        qdd_max=qdd_max,
        tau_max=tau_max,
        torque_model=prior,
        harmonics=args.harmonics,
        period=args.period,
        periods=args.periods,
        samples=args.samples,
        position_margin=args.position_margin,
        rotor=args.rotor,
        friction=args.friction,
        seed=args.seed,
        maxiter=args.maxiter,
        keep_out=keep_out,
        progress=progress,
    )
    save_trajectory_folder(
        plan,
        robot if prior is None else prior,
        args.output,
        rate=args.rate,
        ros_rate=args.ros_rate,
        overwrite=args.overwrite,
        inputs=inputs,
        report=args.report,
    )
    print(
        f"{robot.name}: cond {result.condition_before:.4g} -> {result.condition_after:.4g} "
        f"in {result.iterations} iterations ({time.perf_counter() - start:.1f} s); "
        f"{result.message}"
    )
    print(
        f"{plan.periods} period(s) of {plan.trajectory.period:g} s, {plan.trajectory.harmonics} "
        f"harmonics, starting and ending at rest at q(0)"
    )
    print(
        f"wrote {args.output}/trajectory.json, trajectory.csv ({args.rate:g} Hz), "
        f"trajectory_ros.yaml ({args.ros_rate:g} Hz), trajectory.hpp"
        + (", report.html" if args.report else ""),
        flush=True,
    )


def _keep_out(args: argparse.Namespace, robot: Any) -> Any:
    """--floor, --box, --capsule-radius, --keep-out-margin as a KeepOut (None without any);
    --capsule-radius urdf: each segment's radius from the URDF model's collision geometry."""
    if args.floor is None and args.box is None and args.capsule_radius is None:
        return None
    from ..excitation.cartesian import KeepOut

    if args.capsule_radius == "urdf":
        if not str(args.model).lower().endswith(".urdf"):
            raise ValueError("--capsule-radius urdf: needs a URDF --model (its <collision>)")
        from ..model.urdf.collision import segment_radii

        links = {k: getattr(args, k, None) for k in ("base_link", "tip_link")}
        try:
            args.capsule_radius = segment_radii(args.model, robot.convention, **links).tolist()
        except ValueError as exc:
            raise ValueError(f"--capsule-radius urdf: {exc}") from None

    options = {"floor": "--floor", "box": "--box", "radii": "--capsule-radius"}
    try:
        return KeepOut(
            floor=args.floor,
            box=None if args.box is None else tuple(args.box),
            radii=None if args.capsule_radius is None else args.capsule_radius,
            margin=args.keep_out_margin,
        )
    except ValueError as exc:  # name the option, not the field
        field, _, rest = str(exc).partition(":")
        raise ValueError(f"{options.get(field, '--keep-out-margin')}:{rest}") from None


def _joint_values(values: list[float], n: int, option: str) -> Any:
    import numpy as np

    if len(values) not in (1, n):
        raise ValueError(f"{option}: expected one number or {n} (one per joint), got {len(values)}")
    return np.broadcast_to(np.asarray(values, dtype=float), (n,)).copy()


def _model_limits(robot: Any) -> tuple[Any, Any]:
    """The model's velocity and effort limits (``robot.velocity_limits``, ``effort_limits``: a
    URDF's <limit>, a model file's, the Panda's built in), NaN where not known (inf)."""
    import numpy as np

    v, e = np.asarray(robot.velocity_limits, dtype=float), np.asarray(robot.effort_limits, float)
    return np.where(np.isinf(v), np.nan, v), np.where(np.isinf(e), np.nan, e)


def _limit_option(given: Any, from_urdf: Any, default: float | None, n: int, option: str) -> Any:
    """The option if given, else the URDF's values (the default where it has none), else the
    default (None: no limit)."""
    import numpy as np

    if given is not None:
        values = _joint_values(given, n, option)
        if not np.all(np.isfinite(values) & (values > 0)):
            raise ValueError(f"{option}: expected positive limits, got {given}")
        return values
    if from_urdf is None or np.all(np.isnan(from_urdf)):
        return default
    if default is None and np.any(np.isnan(from_urdf)):
        missing = [j + 1 for j in np.flatnonzero(np.isnan(from_urdf))]
        raise ValueError(
            f"{option}: the model gives no effort limit for joint(s) {missing} (a URDF's "
            "<limit effort> missing or 0); give the limits with --tau-max"
        )
    return np.where(np.isnan(from_urdf), default if default is not None else np.nan, from_urdf)


def info(args: argparse.Namespace) -> None:
    from ..export.summary import model_summary

    check_links(args, args.model)
    print(model_summary(load_robot(args, args.model)))


def _joint_names(model: Any) -> Any:
    """The joint names of a model or a result's model (``load_model_or_result``)."""
    return getattr(model, "robot", model).joint_names


def payload(args: argparse.Namespace) -> None:
    """``dynid payload UNLOADED LOADED --model RESULT|MODEL``: the payload, fitted with the
    unloaded arm's torque model on both logs, written for the controllers (docs/payload.md)."""
    from ..export.output_folder import check_output_path, output_folder
    from ..export.payload_out import write_payload_files
    from ..export.result_files import load_model_or_result
    from ..identification.log_identification import LogIdentification
    from ..identification.payload_logs import estimate_payload_from_logs

    inputs = [args.unloaded, args.loaded, args.model]
    check_output_path(args.output, args.overwrite, inputs=inputs)
    check_links(args, args.model)
    step = _steps(3)
    model = load_model_or_result(args.model, **model_links(args, args.model))
    result = isinstance(model, LogIdentification)
    robot = model.robot if isinstance(model, LogIdentification) else model
    if result and (args.rotor or args.friction or args.offset):
        raise ValueError(
            "--rotor, --friction, --offset: only with a MODEL; a result brings its own"
        )
    logs = [load_log_of(args, robot.joint_names, path) for path in (args.unloaded, args.loaded)]
    if isinstance(model, LogIdentification):
        options, sources = validation_preparation(model, args)
    else:
        options = preparation_options(args)
        sources = ", ".join(f"{k}={v}" for k, v in options.items()) or "none"
    step(
        f"logs {args.unloaded} ({logs[0].T} samples), {args.loaded} ({logs[1].T} samples, "
        f"loaded); model {args.model}: {robot.name}, {robot.n} joints; preparation: {sources}"
    )
    estimate = estimate_payload_from_logs(
        logs[0],
        logs[1],
        model,
        rotor=args.rotor,
        friction=args.friction,
        offset=args.offset,
        preparation=options,
        method=args.method,
        frame="tool",
    )
    assert estimate.fit is not None  # the joint least-squares fit
    step(
        f"fitted the unloaded model and the payload together ({estimate.fit.theta.size} "
        f"coefficients); noise correlation over {estimate.bartlett_width} sample(s)"
    )
    print(payload_summary(estimate), flush=True)
    with output_folder(args.output, args.overwrite, inputs=inputs) as staging:
        written, skipped = write_payload_files(estimate, robot, staging)
    for reason in skipped:
        print(f"note: not written: {reason}", flush=True)
    step(f"wrote {', '.join(f'{args.output}/{name}' for name in written)}")


def payload_summary(estimate: Any) -> str:
    """The payload with its standard deviations, in the estimate's frame."""
    lines = [f"payload in the {estimate.frame} frame (value +- std):"]
    lines.append(f"  mass       {estimate.mass:12.6g} +- {estimate.mass_std:.3g} kg")
    if estimate.com is None:
        lines.append("  (mass not significant: no centre of mass or inertia)")
        return "\n".join(lines)
    for axis, value, std in zip("xyz", estimate.com, estimate.com_std):
        lines.append(f"  com {axis}      {1000 * value:12.6g} +- {1000 * std:.3g} mm")
    if estimate.inertia is not None:
        for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
            name = "I" + "xyz"[i] + "xyz"[j]
            lines.append(
                f"  {name:<10} {estimate.inertia[i, j]:12.6g} +- "
                f"{estimate.inertia_std[i, j]:.3g} kg m^2 (about the com)"
            )
    return "\n".join(lines)
