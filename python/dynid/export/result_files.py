"""Identification results on disk: ``result.json`` and the PNG plots of ``dynid identify``.

``result.json`` holds everything needed to apply the model to another log with no other input:
the model (DH table, joint types, convention, gravity, base/tool, limits), the regressor options,
the base-parameter structure (independent columns and beta over the standard parameter names),
the coefficients with their expressions and standard deviations, the condition number and rank,
and the training log's preparation and per-joint fit. Non-finite numbers (a relative standard
deviation of a coefficient that is exactly 0) are written as null. A physically consistent
result (``identify_log(physical=True)``) also holds the identified parameters in ``model`` and
the solver's report in ``physical``; ``load_result(...).robot`` is then the identified robot.
``options.friction`` says whether the symmetric friction columns Fv, Fs are regressor columns
(``base_parameters.parameter_names``), ``options.friction_model`` which friction model the
result has ("none", "symmetric", "asymmetric"; :mod:`dynid.identification.friction_models`).
The coefficients after the base parameters belong to column blocks
(:mod:`dynid.identification.blocks`); each block writes and reads its own ``options`` entries
(``offset``, ``friction_model``, ``position_torque_joints``, ...), and the number of
coefficients follows from them.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from .._version import dynid_version
from ..identification.blocks.drive_gains import DriveGains
from ..identification.blocks.model import IdentificationModel
from ..identification.blocks.registry import blocks_from_record, friction_models
from ..identification.blocks.rigid_body import RigidBody
from ..identification.log_identification import LogIdentification, LogValidation
from ..logs.log_files import Log
from ..model.model_files import dumps_json, load_model, model_from_dict, model_text
from ..model.robot import Robot
from .output_folder import output_folder

PathLike = Union[str, Path]

FORMAT = "dynid-identification"
#: Newest format version; the loader reads versions 1 (no covariance) to VERSION. A result is
#: written with the lowest version that holds it, so that an older dynid reads every result it
#: can apply and refuses, naming the version, the others: 2 (covariance, position torque) unless
#: it has asymmetric friction (``options.friction_model``, version 3).
VERSION = 3
#: The version of results without asymmetric friction.
VERSION_SYMMETRIC = 2
#: Units of what a result holds (written into result.json for readers other than dynid).
UNITS = {
    "length": "m",
    "angle": "rad",
    "mass": "kg",
    "time": "s",
    "torque": "N m",
    "coefficients": "SI, as their expressions over the standard parameters",
}
RESULT_FILE = "result.json"
VALIDATION_FORMAT = "dynid-validation"
#: Format version of validation.json (unchanged by the result's version 3).
VALIDATION_VERSION = 2
VALIDATION_FILE = "validation.json"


def save_result(
    result: LogIdentification,
    folder: PathLike,
    log: Log | None = None,
    plots: bool = True,
    overwrite: bool = False,
    inputs: Iterable[PathLike | None] = (),
    files: Mapping[str, str] | None = None,
    report: bool = False,
    report_warnings: Sequence[str] = (),
) -> Path:
    """Write ``folder/result.json`` and, when ``plots``, ``torques.png`` and ``residuals.png`` of
    the fit on ``log`` (default: the training log, when the result kept it; of several training
    logs the first, the others' plots as ``torques_2.png``, ``residuals_2.png``, ...); returns
    the JSON path. ``files`` are more text files to write into the folder (name: content, e.g.
    ``dynid identify``'s ``run.yaml``). ``folder`` must be new or empty unless ``overwrite``,
    and ``overwrite`` replaces only a folder dynid wrote that holds none of ``inputs`` nor the
    logs' files; it is written as a whole or not at all (:mod:`dynid.export.output_folder`).
    With ``report``, ``report.html`` too (:func:`dynid.export.report.write_report`: the fit on
    ``log`` or the training logs kept, the coefficients, ``report_warnings``), in the same
    folder written whole."""
    given = log is not None
    log = log if log is not None else result.log
    more = result.logs[1:] if not given else ()
    inputs = [*inputs, log.source if log is not None else None, *(m.source for m in more)]
    _check_file_names(files, RESULT_FILE)
    with output_folder(folder, overwrite, inputs=inputs) as staging:
        (staging / RESULT_FILE).write_text(dumps_json(result_to_dict(result)) + "\n")
        for name, text in (files or {}).items():
            (staging / name).write_text(text)
        if plots and log is not None:
            # The training log's prediction from the fit (its regressor computed once per run).
            fitted = result.fitted if log is result.log else None
            predicted = fitted if fitted is not None else result.predict(log)
            save_plots(staging, log, predicted, "training log")
            for k, (other, part) in enumerate(zip(more, result.fitted_logs[1:]), start=2):
                save_plots(staging, other, part, f"training log {k}", suffix=f"_{k}")
        if report:
            from .report import write_report  # matplotlib: imported when reporting

            write_report(result, staging, log=log if given else None, warnings=report_warnings)
    return Path(folder) / RESULT_FILE


def save_validation(
    validation: LogValidation,
    folder: PathLike,
    *,
    result_source: str = "",
    log_source: str = "",
    plots: bool = True,
    overwrite: bool = False,
    files: Mapping[str, str] | None = None,
    report: bool = False,
    result: LogIdentification | None = None,
    report_warnings: Sequence[str] = (),
) -> Path:
    """Write ``folder/validation.json`` (per-joint metrics, preparation, sources) and, when
    ``plots``, the torque and residual plots of the validation log; returns the JSON path.
    ``files`` are more text files to write into the folder (name: content). With ``report``,
    ``report.html`` too (:func:`dynid.export.report.write_report`; with ``result``, the result
    applied, its coefficients and training errors; ``report_warnings`` listed).
    ``overwrite`` never replaces a folder that holds ``result_source`` or the log's file
    (:mod:`dynid.export.output_folder`)."""
    record = {
        "format": VALIDATION_FORMAT,
        "version": VALIDATION_VERSION,
        "dynid_version": dynid_version(),
        "result": result_source,
        "log": log_source,
        "log_format": validation.log.format,  # the reader that recognised the log's file
        "samples": validation.log.T,
        "preparation": validation.preparation,
        "notes": validation.log.notes,
        "metrics": metrics_to_dict(validation.metrics),
    }
    inputs = [result_source, log_source, validation.log.source]
    _check_file_names(files, VALIDATION_FILE)
    with output_folder(folder, overwrite, inputs=inputs) as staging:
        (staging / VALIDATION_FILE).write_text(dumps_json(record) + "\n")
        for name, text in (files or {}).items():
            (staging / name).write_text(text)
        if plots:
            save_plots(staging, validation.log, validation.predicted, "validation log")
        if report:
            from .report import write_report  # matplotlib: imported when reporting

            write_report(
                validation,
                staging,
                result=result,
                warnings=report_warnings,
                sources={"result": result_source, "log": log_source},
            )
    return Path(folder) / VALIDATION_FILE


def _check_file_names(files: Mapping[str, str] | None, main: str) -> None:
    """The extra files of a folder: plain names (no folders), not the folder's main file."""
    for name in files or {}:
        if not name or Path(name).name != name or name == main:
            raise ValueError(f"files: expected plain file names besides {main}, got {name!r}")


def save_plots(
    folder: Path, log: Log, predicted: NDArray[np.float64], what: str, suffix: str = ""
) -> list[Path]:
    """``torques.png`` (measured and predicted torque per joint) and ``residuals.png`` (their
    names followed by ``suffix``)."""
    from .plots import plot_residuals, plot_torques  # matplotlib: imported when plotting

    t = log.t - log.t[0]
    name = Path(log.source).name or what
    return [
        plot_torques(
            t,
            log.tau,
            predicted,
            folder / f"torques{suffix}.png",
            title=f"Measured and predicted joint torques ({what}: {name})",
        ),
        plot_residuals(
            t,
            predicted - log.tau,
            folder / f"residuals{suffix}.png",
            title=f"Torque residuals, predicted - measured ({what}: {name})",
        ),
    ]


def load_result(path: PathLike) -> LogIdentification:
    """Read a result folder (or its JSON file). FileNotFoundError when absent; ValueError naming
    the file and the field that is missing or malformed."""
    path = Path(path)
    if path.is_dir():
        path = path / RESULT_FILE
    if not path.is_file():
        raise FileNotFoundError(f"result: no such file: {path}")
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: not valid JSON: {exc.msg} at line {exc.lineno}") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file") from None
    try:
        return result_from_dict(data)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def result_to_dict(result: LogIdentification) -> dict[str, Any]:
    """The content of ``result.json`` (JSON-ready)."""
    coefficients = [
        {
            "name": name,
            "value": _num(value),
            "std": _num(std),
            "relative_std_percent": _num(rel),
            "expression": expr,
        }
        for name, value, std, rel, expr in zip(
            result.names, result.theta, result.std, result.relative_std, result.expressions
        )
    ]
    training = dict(result.training)
    training["metrics"] = {k: _nums(v) for k, v in training.get("metrics", {}).items()}
    if "logs" in training:  # several training logs: each one's metrics
        training["logs"] = [
            dict(run, metrics={k: _nums(v) for k, v in run.get("metrics", {}).items()})
            for run in training["logs"]
        ]
    options = {
        "rotor": result.rotor,
        "friction": result.friction,
        "friction_model": result.friction_model,
        "offset": result.offset,
        "method": result.method,
        "exclude_joints": list(result.excluded),
        "position_torque_joints": [j + 1 for j in result.position_joints],
    }
    for block in result.blocks:  # each block's own entries (a new block's new keys)
        options.update(block.record())
    data = {
        "format": FORMAT,
        "version": result.identification_model.version(VERSION_SYMMETRIC),
        "dynid_version": dynid_version(),
        "units": UNITS,
        "model": result.model,
        "options": options,
        "condition_number": _num(result.condition_number),
        "rank": result.rank,
        "coefficients": coefficients,
        "training": training,
        "covariance": _nums(result.covariance) if result.covariance is not None else None,
        "base_parameters": {
            "count": result.count,
            "parameter_names": result.parameter_names,
            "independent": result.independent.tolist(),
            "beta": _nums(result.beta),
        },
    }
    if result.physical is not None:
        data["physical"] = result.physical
    if result.drive_gains is not None:  # the drive-gain block's report (its own entry)
        data.update(DriveGains(result.n).record(result.drive_gains))
    if result.estimator is not None:  # a registered estimator's report (method not ols/wls)
        data["estimator"] = result.estimator
    return data


def result_from_dict(data: Any) -> LogIdentification:
    """A LogIdentification from the content of ``result.json``."""
    data = _object(data, "result")
    if data.get("format") != FORMAT:
        raise ValueError(
            f"format: expected {FORMAT!r} (a dynid identify result), got {data.get('format')!r}"
        )
    version = data.get("version")
    if not (isinstance(version, int) and not isinstance(version, bool) and 1 <= version <= VERSION):
        raise ValueError(
            f"version: expected a format version 1..{VERSION} (written by dynid "
            f"{data.get('dynid_version', '?')}; this is dynid {dynid_version()}), "
            f"got {version!r}"
        )
    model = _object(_get(data, "model"), "model")
    try:
        robot = model_from_dict(model)
    except ValueError as exc:
        raise ValueError(f"model: {exc}") from None
    options = _object(_get(data, "options"), "options")
    flags = {k: _get(options, k, "options") for k in ("rotor", "friction", "offset")}
    for key, value in flags.items():
        if not isinstance(value, bool):
            raise ValueError(f"options.{key}: expected true or false, got {value!r}")
    base = _object(_get(data, "base_parameters"), "base_parameters")
    names_std = _get(base, "parameter_names", "base_parameters")
    expected = robot.parameter_names(flags["rotor"], flags["friction"])
    if names_std != expected:
        raise ValueError(
            f"base_parameters.parameter_names: do not match the model's regressor columns "
            f"({len(expected)} expected for rotor={flags['rotor']}, friction={flags['friction']})"
        )
    independent = _array(
        _get(base, "independent", "base_parameters"), "base_parameters.independent", 1
    ).astype(np.int64)
    count = independent.size
    if np.any(independent < 0) or np.any(independent >= len(expected)):
        raise ValueError("base_parameters.independent: column index out of range")
    beta = _array(_get(base, "beta", "base_parameters"), "base_parameters.beta", 2)
    if beta.shape != (count, len(expected)):
        raise ValueError(
            f"base_parameters.beta: expected shape {(count, len(expected))}, got {beta.shape}"
        )
    _check_friction_model(options.get("friction_model"), flags["friction"])
    blocks = tuple(blocks_from_record(options, robot.n))
    model_of_result = IdentificationModel(
        RigidBody(robot, flags["rotor"], flags["friction"], independent), blocks
    )
    p = model_of_result.size
    rows = _get(data, "coefficients")
    if not isinstance(rows, list) or len(rows) != p:
        raise ValueError(f"coefficients: expected a list of {p} entries")
    records = [_object(row, f"coefficients[{k}]") for k, row in enumerate(rows)]
    column = {
        key: [_get(row, key, f"coefficients[{k}]") for k, row in enumerate(records)]
        for key in ("name", "value", "std", "relative_std_percent", "expression")
    }
    training = _object(data.get("training", {}), "training")
    metrics = _object(training.get("metrics", {}), "training.metrics")
    training["metrics"] = {
        k: _array(v, f"training.metrics.{k}", 1, nullable=True) for k, v in metrics.items()
    }
    if "logs" in training:  # several training logs: each one's metrics as arrays too
        runs = training["logs"]
        if not isinstance(runs, list):
            raise ValueError(f"training.logs: expected a list, got {type(runs).__name__}")
        training["logs"] = [
            _log_record(_object(run, f"training.logs[{i}]"), f"training.logs[{i}]")
            for i, run in enumerate(runs)
        ]
    method = _get(options, "method", "options")
    physical = data.get("physical")
    if physical is not None:
        physical = _object(physical, "physical")
        if not robot.is_physically_consistent():
            raise ValueError(
                "model: a physically consistent result whose parameters are not "
                "physically consistent (edited file?)"
            )
    return LogIdentification(
        model=dict(model),
        rotor=flags["rotor"],
        friction=flags["friction"],
        method=str(method),
        parameter_names=list(names_std),
        independent=independent,
        beta=beta,
        names=[str(x) for x in column["name"]],
        expressions=[str(x) for x in column["expression"]],
        theta=_array(column["value"], "coefficients[].value", 1),
        std=_array(column["std"], "coefficients[].std", 1, nullable=True),
        relative_std=_array(
            column["relative_std_percent"], "coefficients[].relative_std_percent", 1, nullable=True
        ),
        condition_number=float(
            _array(_get(data, "condition_number"), "condition_number", 0, nullable=True)
        ),
        rank=int(_array(_get(data, "rank"), "rank", 0)),
        excluded=tuple(int(j) for j in options.get("exclude_joints", [])),
        training=training,
        covariance=_covariance(data.get("covariance"), p),
        physical=physical,
        blocks=blocks,
        drive_gains=DriveGains.from_record(data, robot.n),
        estimator=_estimator_record(data.get("estimator"), str(method)),
        _robot=robot,
    )


def _estimator_record(value: Any, method: str) -> dict[str, Any] | None:
    """result.json's ``estimator`` (the report of a registered estimator): an object whose
    ``method`` is ``options.method``, or absent."""
    if value is None:
        return None
    record = _object(value, "estimator")
    if record.get("method") != method:
        raise ValueError(
            f"estimator.method: expected {method!r} (options.method), got {record.get('method')!r}"
        )
    return record


def _log_record(run: dict[str, Any], where: str) -> dict[str, Any]:
    """One training log's entry of ``training.logs``, its metrics as arrays."""
    metrics = _object(run.get("metrics", {}), f"{where}.metrics")
    run["metrics"] = {
        k: _array(v, f"{where}.metrics.{k}", 1, nullable=True) for k, v in metrics.items()
    }
    return run


def _check_friction_model(model: Any, friction: bool) -> None:
    """options.friction_model (absent before format version 3: from options.friction, which
    says whether the symmetric Fv, Fs are regressor columns) is a known friction model, the
    symmetric one exactly when options.friction is true (the friction blocks read it)."""
    if model is None:
        return
    models = friction_models()
    if model not in models or (model == "symmetric") != friction:
        raise ValueError(
            f"options.friction_model: expected {', '.join(map(repr, models))} "
            f"matching options.friction = {str(friction).lower()}, got {model!r}"
        )


def _covariance(value: Any, size: int) -> NDArray[np.float64] | None:
    if value is None:
        return None
    covariance = _array(value, "covariance", 2, nullable=True)
    if covariance.shape != (size, size):
        raise ValueError(f"covariance: expected shape ({size}, {size}), got {covariance.shape}")
    return covariance


def metrics_to_dict(metrics: dict[str, NDArray[np.float64]]) -> dict[str, list]:
    """Per-joint metric arrays as JSON-ready lists (non-finite as null)."""
    return {k: _nums(v) for k, v in metrics.items()}


# --------------------------------------------------------------------------- helpers


def _num(value: Any) -> float | None:
    value = float(value)
    return value if np.isfinite(value) else None


def _nums(value: Any) -> Any:
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return _num(array)
    return [_nums(v) for v in array]


def _object(value: Any, where: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise ValueError(f"{where}: expected an object, got {type(value).__name__}")
    return dict(value)


def _get(data: dict[str, Any], key: str, where: str = "") -> Any:
    if key not in data:
        raise ValueError(f"{where + '.' if where else ''}{key}: missing")
    return data[key]


def _array(value: Any, where: str, ndim: int, nullable: bool = False) -> NDArray[np.float64]:
    """Numbers (nested lists) of ``ndim`` dimensions; null is inf where ``nullable``."""
    if nullable:
        value = _null_to_inf(value)
    try:
        if _has_bool(value):
            raise TypeError
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: expected numbers, got {str(value)[:60]}") from None
    if array.ndim != ndim:
        raise ValueError(f"{where}: expected {ndim} dimension(s), got shape {array.shape}")
    if not nullable and not np.all(np.isfinite(array)):
        raise ValueError(f"{where}: contains null, NaN or inf")
    return array


def _null_to_inf(value: Any) -> Any:
    if value is None:
        return np.inf
    return [_null_to_inf(v) for v in value] if isinstance(value, list) else value


def _has_bool(value: Any) -> bool:
    if isinstance(value, bool):
        return True
    return isinstance(value, list) and any(_has_bool(v) for v in value)


def load_model_or_result(
    source: PathLike, *, tip_link: str | None = None, base_link: str | None = None
) -> Robot | LogIdentification:
    """A result folder or ``result.json`` as a :class:`LogIdentification`, anything else as
    :func:`~dynid.model.model_files.load_model` reads it (built-in name, model file, URDF; the
    URDF's chain from ``base_link`` to ``tip_link``, which only a URDF may be given)."""
    path = Path(source)
    if path.is_dir() or path.name == RESULT_FILE:
        if tip_link is not None or base_link is not None:
            raise ValueError(f"tip_link, base_link: only for a URDF model, not for {source}")
        return load_result(path)
    return load_model(source, tip_link=tip_link, base_link=base_link)


def export_robot(
    source: PathLike,
    urdf: PathLike | None = None,
    *,
    mjcf: PathLike | None = None,
    into: PathLike | None = None,
    base_link: str | None = None,
    tip_link: str | None = None,
    name: str | None = None,
    overwrite: bool = False,
    model_file: PathLike | None = None,
) -> list[Path]:
    """Write the robot of ``source`` as URDF (``urdf``) and/or MuJoCo MJCF (``mjcf``; at least
    one) for ``dynid export``: ``source`` is a result folder or ``result.json`` of a physically
    consistent identification, or anything :func:`~dynid.model.model_files.load_model` reads (a
    built-in name, a model file, a URDF: its chain from ``base_link`` to ``tip_link``). With
    ``into`` (the user's own URDF of the arm, its chain from ``base_link`` to ``tip_link``),
    ``urdf`` is that file with the robot's inertials and drive terms in place of its own and
    everything else kept (:mod:`.urdf_into`); without, a fresh URDF of the DH model. A
    least-squares result is exported as the physically consistent robot with its base
    parameters (:func:`dynid.identification.realize.consistent_robot`); a ValueError says when
    there is none (then identify with --physical). Returns
    the files written. Both files are checked before either is written (an existing file
    without ``overwrite``, a robot the format refuses)."""
    from ..identification.realize import consistent_robot
    from ..model.urdf.writing import write_urdf
    from .mjcf import mjcf_text, write_mjcf
    from .urdf_into import urdf_into_text

    if into is not None and urdf is None:
        raise ValueError("into: the user's URDF to update needs --urdf OUT, the file to write")
    if urdf is None and mjcf is None and model_file is None:
        raise ValueError(
            "urdf, mjcf, model_file: give at least one file to write (--urdf FILE, --mjcf FILE, "
            "--model-file FILE)"
        )
    if model_file is not None and Path(model_file).suffix.lower() not in (".json", ".yaml", ".yml"):
        raise ValueError(
            f"model_file: expected a .json, .yaml or .yml file (C++: .json), got {model_file}"
        )
    # The links choose the chain of a URDF source too (a DH model or a result has none).
    urdf_source = str(source).lower().endswith(".urdf")
    links = {"tip_link": tip_link, "base_link": base_link} if urdf_source else {}
    loaded = load_model_or_result(source, **links)
    if isinstance(loaded, LogIdentification):
        try:  # a least-squares result: the consistent robot with its base parameters
            robot = consistent_robot(loaded)
        except ValueError as exc:
            raise ValueError(f"{source}: {exc}") from None
    else:
        robot = loaded
    name = name or robot.name
    targets = [Path(p) for p in (urdf, mjcf, model_file) if p is not None]
    for target in targets:
        if target.exists() and not overwrite:
            raise ValueError(
                f"path: {target} exists; pass overwrite=True (--overwrite) to replace it"
            )
    if mjcf is not None:
        mjcf_text(robot, name)  # refused before anything is written
    updated = (
        urdf_into_text(robot, into, base_link=base_link, tip_link=tip_link)
        if into is not None
        else None
    )
    written = []
    if updated is not None:
        assert urdf is not None
        written.append(write_urdf(updated, urdf, overwrite=overwrite))
    elif urdf is not None:
        robot.to_urdf(name=name, path=urdf, overwrite=overwrite)
        written.append(Path(urdf))
    if mjcf is not None:
        written.append(write_mjcf(robot, mjcf, name=name, overwrite=overwrite))
    if model_file is not None:  # what dynid::load_model reads in C++ (a .json one)
        named = robot.copy()
        named.name = name
        text = model_text(named, model_file)
        written.append(write_urdf(text, model_file, overwrite=overwrite))  # atomic, any text
    return written
