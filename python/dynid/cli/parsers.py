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
    _add_payload(subcommands)
    _add_excite(subcommands)
    _add_simulate(subcommands)
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
        "--stribeck-friction",
        action="store_true",
        help="smooth Stribeck friction per drive and direction, [Fc (1 - e) + Fst e] "
        "tanh(w/vc) + Fv w with e = exp(-(w/vs)^2), its velocity scales vc, vs estimated on "
        "the log (separable least squares), instead of --friction's Fv, Fs "
        "(docs/identification.md)",
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
    _add_robust_estimators(p)
    _add_current(p)
    _add_closed_loop_estimators(p)
    _add_preparation(p)
    _add_motor_side(p)
    _add_periodic(p)
    _add_output(p, "dynid-identify")
    _add_report(p)
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
    _add_report(p)
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
        help="write a model or an identified robot as URDF, MuJoCo MJCF or a model file",
        description="Write the robot of SOURCE as a URDF, a MuJoCo MJCF and/or a model file "
        "(JSON: what dynid::load_model reads in C++): SOURCE is a result folder (or its "
        "result.json) of `dynid identify`, a built-in model name, a model file or a URDF. A "
        "least-squares result is written as the physically consistent robot closest to it "
        "(refused when none is within a standard deviation of every base parameter; "
        "docs/export.md).",
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
    p.add_argument(
        "--model-file",
        metavar="FILE",
        help="the model file to write (.json, which C++'s dynid::load_model reads, or .yaml)",
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


def _add_payload(subcommands: Any) -> None:
    p = subcommands.add_parser(
        "payload",
        help="estimate a payload from logs without and with it; write it for the controllers",
        description="Estimate the mass, centre of mass and inertia of a payload on the last link "
        "(with standard deviations) from a log of the arm without it (UNLOADED) and one with it "
        "(LOADED), fitted together with the unloaded arm's torque model; write payload.json, "
        "franka_endeffector.json, urscript.txt, kuka_load_data.txt and model.json (the model "
        "with the payload) in the model's tool frame (docs/payload.md).",
    )
    p.add_argument("unloaded", metavar="UNLOADED", help="log of the arm without the payload")
    p.add_argument("loaded", metavar="LOADED", help="log of the arm carrying the payload")
    p.add_argument(
        "--model",
        required=True,
        metavar="RESULT|MODEL",
        help="the unloaded arm: a result of `dynid identify` (its torque model and recorded "
        "preparation), a built-in model, a model file or a URDF",
    )
    p.add_argument(
        "--rotor", action="store_true", help="with a MODEL: the rotor inertia columns Ia"
    )
    p.add_argument(
        "--friction", action="store_true", help="with a MODEL: viscous and Coulomb friction"
    )
    p.add_argument(
        "--offset", action="store_true", help="with a MODEL: a constant torque per joint"
    )
    p.add_argument(
        "--method",
        choices=("ols", "wls"),
        default="wls",
        help="ordinary or weighted (per-joint noise) least squares (default wls)",
    )
    _add_links(p)
    _add_preparation(p)
    _add_output(p, "dynid-payload")
    # A result's recorded preparation applies, each option given replacing it (as validate).
    p.set_defaults(run=commands.payload, recorded_preparation=True)


def _per_joint(text: str) -> list[float]:
    """A per-joint option: one number for every joint, or one per joint separated by commas."""
    try:
        return [float(item) for item in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a number or comma-separated numbers, one per joint, got {text!r}"
        ) from None


def _radii_or_urdf(text: str) -> list[float] | str:
    """--capsule-radius: numbers (one, or one per segment) or 'urdf'."""
    return text if text == "urdf" else _per_joint(text)


def _add_simulate(subcommands: Any) -> None:
    p = subcommands.add_parser(
        "simulate",
        help="rehearse an experiment: track a trajectory in simulation and write the log "
        "(docs/workflow.md)",
        description="Simulate MODEL tracking TRAJECTORY (trajectory.json of `dynid excite`, or "
        "its folder) under a controller at its rate, with friction, sensor noise and encoder "
        "quantisation, and write the log the controller would record in a format `dynid "
        "identify` reads: log.npz, log.csv or a ROS 2 bag (bag/), with simulation.json (what "
        "was simulated) and run.yaml.",
    )
    p.add_argument(
        "model",
        metavar="MODEL",
        help="the simulated arm: a built-in model, a model file, a URDF, or the result folder of "
        "`dynid identify --physical`",
    )
    p.add_argument("trajectory", metavar="TRAJECTORY", help="trajectory.json or its folder")
    p.add_argument(
        "--controller",
        choices=("pd", "pd_gravity", "computed_torque"),
        default="pd_gravity",
        help="the control law (default pd_gravity); computed_torque and pd_gravity use MODEL",
    )
    p.add_argument(
        "--kp", type=_per_joint, metavar="K", help="proportional gains: one, or one per joint"
    )
    p.add_argument(
        "--kd", type=_per_joint, metavar="K", help="derivative gains: one, or one per joint"
    )
    p.add_argument(
        "--bandwidth",
        type=float,
        default=10.0,
        help="closed-loop bandwidth [Hz] of the default gains (default 10)",
    )
    p.add_argument(
        "--rate", type=float, default=1000.0, help="controller and log rate [Hz] (default 1000)"
    )
    p.add_argument("--sensor-noise", type=float, default=0.0, help="torque sensor noise std [N m]")
    p.add_argument(
        "--torque-noise",
        type=float,
        default=0.0,
        help="disturbance torque std [N m] acting on the arm (not logged)",
    )
    p.add_argument(
        "--encoder-counts",
        type=float,
        help="encoder counts per revolution (or metre): the logged positions are quantised",
    )
    p.add_argument(
        "--no-friction", action="store_true", help="no joint friction in the simulated arm"
    )
    p.add_argument(
        "--velocities",
        action="store_true",
        help="log the joint velocities too (exact, as a robot that logs its own would)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the noises (default 0)")
    p.add_argument(
        "--format",
        choices=("npz", "csv", "bag"),
        default="npz",
        help="the log's format (default npz; bag: a ROS 2 MCAP bag, needs dynid[ros])",
    )
    _add_links(p)
    _add_config(p)
    _add_output(p, "dynid-simulate")
    p.set_defaults(run=commands.simulate)


def _add_excite(subcommands: Any) -> None:
    p = subcommands.add_parser(
        "excite",
        help="design an exciting trajectory for identification (docs/excitation.md)",
        description="Optimise a rest-to-rest Fourier trajectory minimising the condition number "
        "of the base regressor within position, velocity, acceleration and torque limits; write "
        "trajectory.json, trajectory.csv, trajectory_ros.yaml and trajectory.hpp into DIR. "
        "Per-joint limits take one number for all joints or one per joint, comma-separated "
        "(negative numbers as --q-min=-1,-2).",
    )
    _add_model(p)
    _add_links(p)
    p.add_argument(
        "--prior",
        metavar="MODEL|URDF",
        help="the model whose torque is limited and written to the CSV (built-in name, model "
        "file or URDF of the same arm; default --model)",
    )
    p.add_argument(
        "--q-min", type=_per_joint, metavar="Q", help="lower joint limits (default the model's)"
    )
    p.add_argument(
        "--q-max", type=_per_joint, metavar="Q", help="upper joint limits (default the model's)"
    )
    p.add_argument(
        "--qd-max",
        type=_per_joint,
        metavar="QD",
        help="velocity limits [rad/s] (default the model's, e.g. a URDF's <limit velocity>, "
        "else 1.0)",
    )
    p.add_argument(
        "--qdd-max",
        type=_per_joint,
        metavar="QDD",
        help="acceleration limits [rad/s^2] (default 2.0)",
    )
    p.add_argument(
        "--tau-max",
        type=_per_joint,
        metavar="TAU",
        help="torque limits [N m] (default the model's, e.g. a URDF's <limit effort>, else none)",
    )
    p.add_argument(
        "--position-margin",
        type=float,
        default=0.02,
        metavar="F",
        help="distance kept from each position limit, a fraction of the range (default 0.02)",
    )
    p.add_argument("--harmonics", type=int, default=5, help="Fourier harmonics (default 5)")
    p.add_argument(
        "--period", type=float, default=10.0, metavar="S", help="period [s] (default 10)"
    )
    p.add_argument("--periods", type=int, default=1, metavar="N", help="periods played (default 1)")
    p.add_argument(
        "--samples", type=int, default=200, help="samples per period of the objective (default 200)"
    )
    p.add_argument(
        "--rate",
        type=float,
        default=1000.0,
        metavar="HZ",
        help="controller rate of the CSV (default 1000)",
    )
    p.add_argument(
        "--ros-rate",
        type=float,
        default=100.0,
        metavar="HZ",
        help="points per second of trajectory_ros.yaml (default 100; controllers interpolate)",
    )
    p.add_argument(
        "--floor",
        type=float,
        metavar="Z",
        help="keep the link origins and the tool point above the plane z = Z [m, world frame]",
    )
    p.add_argument(
        "--box",
        type=float,
        nargs=6,
        metavar=("XMIN", "XMAX", "YMIN", "YMAX", "ZMIN", "ZMAX"),
        help="keep the link origins and the tool point inside this box [m, world frame]",
    )
    p.add_argument(
        "--capsule-radius",
        type=_radii_or_urdf,
        metavar="R|urdf",
        help="keep non-adjacent links apart, each a capsule of this radius [m] about the segment "
        "between consecutive DH frame origins (n + 1 segments, the last to the tool point; one "
        "radius or n + 1), or 'urdf': each from its link's URDF <collision> geometry",
    )
    p.add_argument(
        "--keep-out-margin",
        type=float,
        default=0.05,
        metavar="M",
        help="free distance [m] the optimiser keeps from the floor, box and capsules on its "
        "grid (default 0.05)",
    )
    p.add_argument("--rotor", action="store_true", help="excite the rotor inertia columns too")
    p.add_argument("--friction", action="store_true", help="excite the friction columns too")
    p.add_argument("--seed", type=int, default=0, help="random start (default 0)")
    p.add_argument("--maxiter", type=int, default=200, help="SLSQP iterations (default 200)")
    _add_report(p)
    _add_output(p, "dynid-excite")
    p.set_defaults(run=commands.excite)


def _add_closed_loop_estimators(p: argparse.ArgumentParser) -> None:
    """The options of --method iv and --method didim (identification/estimators/
    closed_loop_model.py): the controller of the experiment, simulated with the estimate."""
    p.add_argument(
        "--controller",
        choices=("pd", "pd_gravity", "computed_torque"),
        help="with --method iv/didim: the control law of the experiment (PD, PD + gravity "
        "of --controller-model, computed torque of --controller-model; docs/identification.md)",
    )
    p.add_argument(
        "--kp",
        type=_gains,
        metavar="K[,K...]",
        help="with --method iv/didim: the controller's position gains, one or one per joint",
    )
    p.add_argument(
        "--kd",
        type=_gains,
        metavar="K[,K...]",
        help="with --method iv/didim: the controller's velocity gains, one or one per joint",
    )
    p.add_argument(
        "--reference",
        metavar="FILE",
        help="with --method iv/didim: the trajectory the controller tracked, an .npz (t, q_d"
        "[, qd_d, qdd_d]) or .csv (t,q_d1..q_dn[,...]) on the log's clock (docs/identification.md)",
    )
    p.add_argument(
        "--controller-model",
        metavar="MODEL",
        help="with --controller pd_gravity/computed_torque: the model the controller uses "
        "(built-in name or model file; default --model)",
    )
    p.add_argument(
        "--control-period",
        type=float,
        metavar="S",
        help="with --method iv/didim: the controller's period [s] (default: the prepared "
        "log's sample period; the log's samples must be whole periods apart)",
    )
    if "--iterations" not in p._option_string_actions:  # other iterative estimators share it
        p.add_argument(
            "--iterations",
            type=int,
            metavar="N",
            help="iterative estimators (iv, didim, ...): at most N iterations",
        )


def _gains(text: str) -> float | list[float]:
    """--kp, --kd of iv/didim: one number (a scalar gain) or one per joint (:func:`_per_joint`)."""
    values = _per_joint(text)
    return values[0] if len(values) == 1 else values


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


def _add_report(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--report",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="write report.html, the run's figures and tables in one page for a browser "
        "(default: on; --no-report saves its 1-1.5 s of CPU on a 7-joint arm)",
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


def _add_robust_estimators(p: argparse.ArgumentParser) -> None:
    """The options of --method irls, tls and essential (dynid.identification.estimators; each
    flag is the estimator option of the same name)."""
    p.add_argument(
        "--loss",
        choices=("huber", "tukey"),
        help="--method irls: the robust loss (default huber; tukey rejects gross outliers "
        "outright)",
    )
    p.add_argument(
        "--tuning",
        type=float,
        metavar="C",
        help="--method irls: the loss's tuning constant in robust standard deviations of each "
        "joint's residuals (default 1.345 for huber, 4.685 for tukey)",
    )
    p.add_argument(
        "--acceleration-noise",
        type=float,
        metavar="SIGMA",
        help="--method tls (required): standard deviation of the noise of the prepared "
        "accelerations, rad/s^2 (docs/identification.md, 'TLS')",
    )
    p.add_argument(
        "--essential-threshold",
        type=float,
        metavar="PERCENT",
        help="--method essential: remove coefficients whose relative standard deviation is "
        "above this, one at a time while the fit holds (default 10)",
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
