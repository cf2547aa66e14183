"""The ``dynid`` command line's arguments (docs/cli.md); each command's ``run`` is in
:mod:`.commands`."""

from __future__ import annotations

import argparse
from typing import Any

from . import commands

DEFAULT_MODEL = "kuka_lwr4"


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="dynid",
        description="Dynamics and identification of robot arms given by DH tables or URDF.",
    )
    subcommands = parser.add_subparsers(dest="command", required=True)
    demo = subcommands.add_parser(
        "demo", help="the KUKA LWR-IV identification of Gaz et al. (ICRA 2014) on a simulated arm"
    )
    _add_output(demo, "dynid-demo")
    demo.add_argument("--train", type=int, default=1000, help="training configurations")
    demo.add_argument("--validation", type=int, default=200, help="validation configurations")
    demo.add_argument("--seed", type=int, default=0)
    demo.set_defaults(run=commands.demo)
    _add_identify(subcommands)
    _add_validate(subcommands)
    _add_info(subcommands)
    _add_export(subcommands)
    _add_residual(subcommands)
    # Each command knows its own parser, so that an option it does not have is reported with the
    # command's usage, not the top level's (main()).
    for command in subcommands.choices.values():
        command.set_defaults(command_parser=command)
    return parser


# --------------------------------------------------------------------------- parsers


def _add_identify(subcommands: Any) -> None:
    p = subcommands.add_parser(
        "identify",
        help="identify the base parameters on a measurement log (docs/cli.md)",
        description="Identify the base dynamic parameters of a DH model on a log (NPZ or CSV, "
        "docs/data.md) by least squares; write result.json and PNG plots.",
    )
    p.add_argument(
        "log",
        nargs="*",
        metavar="LOG",
        help="measurement log(s), .npz or .csv; several logs are prepared separately and "
        "fitted together",
    )
    _add_model(p)
    _add_links(p)
    _add_config(p)
    p.add_argument("--rotor", action="store_true", help="add the rotor inertia columns Ia")
    p.add_argument(
        "--friction", action="store_true", help="add viscous and Coulomb friction columns Fv, Fs"
    )
    p.add_argument(
        "--asymmetric-friction",
        action="store_true",
        help="friction with one coefficient per direction of motion, Fv+, Fv-, Fs+, Fs- "
        "(with --offset: Fv+, Fv-, Fs, the offset holding the Coulomb asymmetry), instead of "
        "--friction's Fv, Fs (docs/identification.md)",
    )
    p.add_argument(
        "--offset", action="store_true", help="add a constant torque (sensor offset) per joint"
    )
    p.add_argument(
        "--position-torque",
        action="store_true",
        help="add a torque ks_j sin q_j + kc_j cos q_j per joint (sensor/gear ripple "
        "once per turn, cable or spring stiffness), on the joints where it is "
        "distinguishable from gravity (docs/identification.md)",
    )
    p.add_argument(
        "--method",
        type=_method,
        help="ols or wls: ordinary or weighted (per-joint noise) least squares (the default); "
        "or an estimator of docs/identification.md, 'Estimators' (robust, errors in "
        "variables, periodic data, instrumental variables); with --current: nls (the "
        "default there), tls, ols or wls (docs/drive_gains.md)",
    )
    p.add_argument(
        "--physical",
        action="store_true",
        help="physically consistent fit (SDP: every link a possible rigid body, "
        "Ia, Fv, Fs >= 0); the result holds a full robot (docs/identification.md)",
    )
    p.add_argument(
        "--prior",
        metavar="MODEL|URDF",
        help="with --physical: the model (built-in name, model file or URDF) whose "
        "parameters fill the directions the data cannot see",
    )
    p.add_argument(
        "--prior-weight",
        type=float,
        metavar="W",
        help="with --prior: its weight (default 1e-5, docs/identification.md)",
    )
    _add_current(p)
    _add_preparation(p)
    _add_motor_side(p)
    _add_periodic(p)
    _add_output(p, "dynid-identify")
    p.set_defaults(run=commands.identify)


def _add_validate(subcommands: Any) -> None:
    p = subcommands.add_parser(
        "validate",
        help="apply a saved identification to another log",
        description="Predict the torques of LOG with a result of `dynid identify` and report "
        "per-joint RMS, relative RMS, maximum error and R^2; write validation.json and plots.",
    )
    # Optional here so that --config can give them (commands.validate checks they are there).
    p.add_argument(
        "result", nargs="?", help="result folder of `dynid identify`, or its result.json"
    )
    p.add_argument("log", nargs="?", help="measurement log, .npz or .csv")
    p.add_argument(
        "--current",
        action="store_true",
        help="LOG holds motor currents: converted to torques by the result's drive gains "
        "(a result of `dynid identify --current`)",
    )
    _add_preparation(p)
    _add_motor_side(p)
    p.add_argument(
        "--recorded-preparation",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="apply the preparation recorded in the result (the training log's), each option "
        "given here replacing the recorded one (default: on)",
    )
    _add_config(p)
    _add_output(p, "dynid-validate")
    p.set_defaults(run=commands.validate)


def _add_info(subcommands: Any) -> None:
    p = subcommands.add_parser(
        "info",
        help="show a model: DH table, parameters, base-parameter counts",
    )
    _add_model(p)
    _add_links(p)
    p.set_defaults(run=commands.info)


def _add_export(subcommands: Any) -> None:
    p = subcommands.add_parser(
        "export",
        help="write a model or a physically consistent result as URDF and/or MuJoCo MJCF",
        description="Write the robot of SOURCE as a URDF and/or a MuJoCo MJCF file: SOURCE is a "
        "result folder (or its result.json) of `dynid identify --physical`, a built-in model "
        "name, a model file or a URDF. Least-squares results hold base parameters only and "
        "cannot be exported.",
    )
    p.add_argument("source", metavar="SOURCE", help="result folder/result.json, model or URDF")
    p.add_argument("--urdf", metavar="FILE", help="the URDF file to write")
    p.add_argument(
        "--into",
        metavar="USER_URDF",
        help="with --urdf: write into a copy of your own URDF of the arm (its inertials and "
        "<dynamics> replaced, names, meshes, limits, ros2_control/Gazebo tags and comments "
        "kept; docs/export.md)",
    )
    p.add_argument(
        "--mjcf",
        metavar="FILE",
        help="the MuJoCo MJCF file to write (armature = Ia, damping = Fv, frictionloss = Fs; "
        "docs/export.md)",
    )
    p.add_argument("--name", help="robot name in the URDF (default: the model's name)")
    p.add_argument("--overwrite", action="store_true", help="replace the files if they exist")
    _add_links(p)
    p.set_defaults(run=commands.export)


def _add_residual(subcommands: Any) -> None:
    p = subcommands.add_parser(
        "residual",
        help="collision residual (momentum observer) of a model along a log",
        description="Run the generalized-momentum observer (De Luca; docs/uses.md) of MODEL over "
        "LOG: r tracks the external joint torques, zero (to the model error) without contact. "
        "Writes residual.npz (t, r, gain, dt, rms, max_abs) and residual.png.",
    )
    p.add_argument(
        "model",
        metavar="MODEL",
        help="result folder/result.json of `dynid identify`, a built-in model, a "
        "model file or a URDF",
    )
    p.add_argument("log", help="measurement log, .npz or .csv")
    p.add_argument(
        "--gain",
        type=float,
        default=20.0,
        help="observer gain K_O [1/s], the inverse time constant (default 20)",
    )
    p.add_argument(
        "--threshold",
        type=float,
        metavar="T",
        help="draw +-T [N m] in the plot (a collision threshold)",
    )
    _add_log_reading(p)
    _add_links(p)
    _add_output(p, "dynid-residual")
    p.set_defaults(run=commands.residual)


def _add_current(p: argparse.ArgumentParser) -> None:
    """Drive gains from motor currents (commands.identify_from_currents)."""
    p.add_argument(
        "--current",
        action="store_true",
        help="LOG holds motor currents, not torques: identify the drive gains k "
        "(tau = k * current) with the base parameters, the scale from a run with a known "
        "payload (--payload-log with --payload or --payload-mass; docs/drive_gains.md)",
    )
    p.add_argument(
        "--payload-log",
        metavar="LOG",
        help="with --current: a log (currents) of the arm carrying the payload on its last link",
    )
    p.add_argument(
        "--payload",
        metavar="FILE|NUMBERS",
        help="with --current: the payload, a JSON/YAML file (mass, com, inertia about the com, "
        "in the last DH frame; or parameters) or its 10 standard parameters "
        "m,mx,my,mz,Ixx,Ixy,Ixz,Iyy,Iyz,Izz",
    )
    p.add_argument(
        "--payload-mass",
        type=float,
        metavar="KG",
        help="with --current, instead of --payload: the payload's mass alone (its centre of "
        "mass and inertia are identified too)",
    )


def _add_model(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--model",
        default=DEFAULT_MODEL,
        metavar="NAME|FILE",
        help="built-in model (kuka_lwr4, puma560, planar_2r, panda, ur5, ur10), a "
        f"model file (JSON or YAML, docs/cli.md) or a URDF; default {DEFAULT_MODEL}",
    )


def _add_links(p: argparse.ArgumentParser) -> None:
    """The chain of a URDF model (commands.model_links): Robot.from_urdf's tip_link, base_link."""
    p.add_argument(
        "--tip-link",
        metavar="LINK",
        help="with a URDF model (or --prior): the last link of the chain (needed when the tree "
        "has several leaves, e.g. ee_link and tool0)",
    )
    p.add_argument(
        "--base-link",
        metavar="LINK",
        help="with a URDF model (or --prior): the first link of the chain (default the root)",
    )


def _add_config(p: argparse.ArgumentParser) -> None:
    """Options from a run file (cli/run_config.py)."""
    p.add_argument(
        "--config",
        metavar="FILE",
        help="read the options from a YAML file, e.g. the run.yaml of a result folder (keys: "
        "the options without --, the logs under log); options given here override it",
    )


def _add_output(p: argparse.ArgumentParser, default: str) -> None:
    p.add_argument(
        "--output", default=default, metavar="DIR", help=f"output folder (default ./{default})"
    )
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the output folder if it exists and is not empty",
    )


def _add_log_reading(p: argparse.ArgumentParser) -> None:
    """The options of load_log (commands.log_options)."""
    p.add_argument(
        "--skip",
        type=int,
        default=0,
        metavar="N",
        help="drop the first N samples (start-up transient)",
    )
    p.add_argument(
        "--skip-end",
        type=int,
        default=0,
        metavar="N",
        help="drop the last N samples (the filters' edge transients are trimmed anyway)",
    )
    p.add_argument(
        "--columns",
        metavar="MAP",
        help="columns/keys of a foreign log, e.g. 't=stamp,q=pos_*,tau=effort_*' "
        "('*' any characters, brackets literal, joints in natural order), or by 0-based index "
        "in a CSV without a header, 't=0,q=1:8,tau=15:22' (docs/data.md)",
    )
    p.add_argument(
        "--time-unit",
        choices=("s", "ms", "us", "ns"),
        default=None,
        help="unit of the log's time stamps (default: s, and a sampling rate outside 1 Hz to "
        "100 kHz is an error; with the unit given, a warning)",
    )
    p.add_argument(
        "--topic",
        metavar="TOPIC",
        help="ROS bag: the sensor_msgs/JointState topic to read (default: the bag's only one); "
        "its joints are matched by name to the model's joint names (docs/data.md)",
    )
    p.add_argument(
        "--drop-nonfinite",
        action="store_true",
        help="drop the log's rows holding a NaN or inf (counted in the output) instead of "
        "refusing the file",
    )
    p.add_argument(
        "--sample-time",
        type=float,
        metavar="DT",
        help="sample time [s] of a log without a time vector, t = 0, DT, 2 DT, ... (an NPZ "
        "key 'sample_time' is read without it)",
    )


def _add_motor_side(p: argparse.ArgumentParser) -> None:
    """A motor-side log (commands.to_joint_side)."""
    p.add_argument(
        "--motor-side",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="LOG holds motor angles and motor torques: mapped to the joints through the "
        "model's gear_ratios, transmission and joint_offsets, q = R^-1 theta - joint_offsets, "
        "tau = R^T tau_m, R = diag(gear_ratios) T (docs/data.md); validate applies it by itself "
        "to a result trained on a motor-side log, --no-motor-side reads LOG as joint side",
    )


def _add_periodic(p: argparse.ArgumentParser) -> None:
    """The options of --method periodic (dynid.identification.estimators.periodic)."""
    p.add_argument(
        "--period",
        type=float,
        metavar="S",
        help="with --method periodic: the trajectory's period in s (default: found from the "
        "autocorrelation of q; fewer than two whole periods are refused)",
    )


def _method(text: str) -> str:
    """--method: "ols", "wls", a registered estimator (dynid.identification.estimators), or
    with --current "nls"/"tls" (checked by the command)."""
    from ..identification.estimators import methods

    choices = tuple(dict.fromkeys((*methods(), "nls", "tls")))
    if text not in choices:
        raise argparse.ArgumentTypeError(
            f"expected one of {', '.join(map(repr, choices))}, got {text!r}"
        )
    return text


def _velocity_or_auto(text: str) -> float | str:
    """--rest-velocity: a number or 'auto'."""
    if text == "auto":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a velocity or 'auto', got {text!r}") from None


def _add_preparation(p: argparse.ArgumentParser) -> None:
    """Reading the log, then the options of prepare_log (commands.preparation_options)."""
    _add_log_reading(p)
    p.add_argument(
        "--cutoff",
        type=float,
        metavar="HZ",
        help="zero-phase Butterworth low-pass of q, qd, qdd, tau at HZ",
    )
    # Defaults None (applied in commands.preparation_options), so that `dynid validate` can
    # tell an option given on its command line from one to take from the result.
    p.add_argument("--order", type=int, help="order of that filter (default 4)")
    p.add_argument("--decimate", type=int, metavar="K", help="keep every K-th sample")
    _add_preparation_checks(p)


def _add_preparation_checks(p: argparse.ArgumentParser) -> None:
    """The prepare_log options against silent degradation (issue 20, item 2), and the row
    selection of identify and validate."""
    p.add_argument(
        "--min-velocity",
        type=float,
        metavar="V",
        help="leave out the rows of joint j where |qd_j| < V (friction near zero speed); "
        "the errors are reported on the rows kept",
    )
    p.add_argument(
        "--outliers", type=float, metavar="K", help="drop torque spikes beyond K robust sigmas"
    )
    p.add_argument(
        "--rest-velocity",
        type=_velocity_or_auto,
        metavar="V|auto",
        help="joints at rest: qd_j = 0 where |qd_j| < V (rad/s), so that the Coulomb friction "
        "there is 0, not +-Fs at random; 'auto': one encoder count at the filter's cutoff "
        '(docs/data.md, "Joints at rest")',
    )
    p.add_argument(
        "--nonuniform",
        choices=("resample", "refuse", "ignore"),
        help="time stamps with jitter or dropped samples, before filtering: resample onto a "
        "uniform grid (default), refuse, or filter as if uniform (docs/data.md)",
    )
    p.add_argument(
        "--edge-trim",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="drop the filters' edge transients at both ends of every segment (default: on)",
    )
