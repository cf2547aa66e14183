"""dynid against Pinocchio on the KUKA LWR-IV: one command, one table.

    python bench/run.py [--native] [--runs R] [--batch T] [--skip-cpp] [--skip-python] ...

Builds and runs the C++ benchmark (cpp_level.py), times the Python API (python_level.py),
prints a table of microseconds per call with the ratio dynid / Pinocchio and the target of
issue 6 per row, and saves it as JSON (bench/results/latest.json by default). Pinocchio is
used when the ``pin`` wheel is installed (``pip install "dynid[bench]"``); without it only
dynid's numbers are shown. A benchmark, not a test: nothing here asserts on time.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import subprocess
from pathlib import Path
from typing import Any

import cpp_level  # sibling modules: bench/ is sys.path[0] when run as a script
import numpy as np
import pinocchio_arm
import python_level
from machine import describe_machine

import dynid

REPO = Path(__file__).resolve().parent.parent

# Issues 6 and 13's targets: ratio dynid / Pinocchio at most this, or ("abs", us) for an absolute
# bound (batch rows: one thread, us per state).
TARGETS: dict[tuple[str, str], tuple[str, float]] = {
    ("C++", "rnea"): ("ratio", 0.5),
    ("C++", "crba"): ("ratio", 0.7),
    ("C++", "gravity"): ("ratio", 1.0),
    ("C++", "coriolis_matrix"): ("ratio", 0.5),
    ("C++", "regressor"): ("ratio", 0.5),
    ("C++", "forward_dynamics"): ("ratio", 1.0),
    ("C++", "rnea_derivatives"): ("ratio", 0.7),  # issue 11
    ("Python", "rnea"): ("ratio", 0.6),
    ("Python", "mass_matrix"): ("ratio", 0.6),
    ("Python", "gravity"): ("ratio", 0.6),
    ("Python batch", "rnea"): ("abs", 0.10),
    ("Python batch", "gravity"): ("abs", 0.06),
    ("Python batch", "mass_matrix"): ("abs", 0.25),
    ("Python batch", "regressor"): ("abs", 0.5),
    ("Python batch", "regressor_out"): ("abs", 0.5),
}
# What each row times on the Pinocchio side, for the table.
PINOCCHIO_NAMES = {
    ("C++", "rnea"): "rnea",
    ("C++", "crba"): "crba + copy to lower triangle",
    ("C++", "gravity"): "computeGeneralizedGravity",
    ("C++", "coriolis_matrix"): "computeCoriolisMatrix",
    ("C++", "regressor"): "computeJointTorqueRegressor",
    ("C++", "forward_dynamics"): "aba",
    ("C++", "rnea_derivatives"): "computeRNEADerivatives",
    ("Python", "rnea"): "pin.rnea",
    ("Python", "mass_matrix"): "pin.crba",
    ("Python", "gravity"): "pin.computeGeneralizedGravity",
    ("Python batch", "rnea"): "Python loop of pin.rnea (no batch API)",
    ("Python batch", "gravity"): "Python loop of pin.computeGeneralizedGravity",
    ("Python batch", "mass_matrix"): "Python loop of pin.crba",
    ("Python batch", "regressor"): "Python loop of pin.computeJointTorqueRegressor",
    ("Python batch", "regressor_out"): "Python loop of pin.computeJointTorqueRegressor",
}


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--build-dir",
        type=Path,
        default=REPO / "bench" / "build",
        help="CMake build directory (default: bench/build)",
    )
    parser.add_argument("--output", type=Path, default=REPO / "bench" / "results" / "latest.json")
    parser.add_argument(
        "--runs",
        type=int,
        default=201,
        help="timed runs per function; the figure is their median (default 201)",
    )
    parser.add_argument(
        "--states",
        type=int,
        default=256,
        help="distinct states cycled in single-call timings (default 256)",
    )
    parser.add_argument("--batch", type=int, default=10_000, help="states in the batch (10^4)")
    parser.add_argument("--batch-runs", type=int, default=21, help="timed batch runs (21)")
    parser.add_argument(
        "--threads",
        type=int,
        default=os.cpu_count() or 1,
        help="also time dynid's batch rnea on N threads (dynid.set_threads)",
    )
    parser.add_argument(
        "--cpu",
        type=int,
        default=1,
        help="CPU for the C++ program (taskset) and the Python single calls (-1: no pinning)",
    )
    parser.add_argument(
        "--native", action="store_true", help="compile dynid and Pinocchio alike with -march=native"
    )
    parser.add_argument("--no-pinocchio", action="store_true", help="time dynid only")
    parser.add_argument("--skip-cpp", action="store_true", help="no C++ build and timings")
    parser.add_argument("--skip-python", action="store_true", help="no Python-level timings")
    return parser.parse_args()


def bench_robot() -> Any:
    """The LWR-IV of dynid.models with its rotor inertias (Pinocchio's armature) but no joint
    friction, which Pinocchio does not model. dynid still evaluates its (zero) friction terms."""
    robot = dynid.models.kuka_lwr4()
    robot.Fv = np.zeros(robot.n)
    robot.Fs = np.zeros(robot.n)
    return robot


def import_pinocchio(disabled: bool) -> Any | None:
    if disabled:
        return None
    try:
        import pinocchio
    except ImportError:
        return None
    return pinocchio


def machine(cpu_pinned: int | None) -> dict[str, Any]:
    return {**describe_machine(), "numpy": np.__version__, "cpp_pinned_cpu": cpu_pinned}


def git_state() -> dict[str, Any]:
    def git(*args: str) -> str:
        done = subprocess.run(
            ["git", "-C", str(REPO), *args], capture_output=True, text=True, check=False
        )
        return done.stdout.strip() if done.returncode == 0 else ""

    return {
        "commit": git("rev-parse", "HEAD") or None,
        "dirty": bool(git("status", "--porcelain", "--untracked-files=no")),
    }


Stat = dict[str, float]  # {"median": us, "min": us}


def make_row(
    level: str, function: str, dynid: Stat, pinocchio: Stat | None, unit: str = "us/call"
) -> dict[str, Any]:
    """One table row; ratios and targets use the medians."""
    kind, bound = TARGETS[(level, function)]
    ratio = dynid["median"] / pinocchio["median"] if pinocchio else None
    if kind == "abs":
        value, target = dynid["median"], f"<= {bound} us/state"
    else:
        value, target = ratio, f"ratio <= {bound}"
    status = "n/a" if value is None else ("met" if value <= bound else "not met")
    return {
        "level": level, "function": function, "unit": unit,
        "dynid_us": dynid["median"], "pinocchio_us": pinocchio["median"] if pinocchio else None,
        "ratio": ratio,
        "dynid_us_min": dynid["min"], "pinocchio_us_min": pinocchio["min"] if pinocchio else None,
        "pinocchio_call": PINOCCHIO_NAMES[(level, function)] if pinocchio else None,
        "target": target, "status": status,
        "off_by": None if value is None or status == "met" else value / bound,
    }  # fmt: skip


def print_table(rows: list[dict[str, Any]], header: str) -> None:
    def us(median: float | None, minimum: float | None) -> str:
        return "-" if median is None else f"{median:.3f} ({minimum:.3f})"

    print(header)
    head = (
        "level",
        "function",
        "dynid us (min)",
        "Pinocchio us (min)",
        "dynid/Pin",
        "target",
        "status",
        "Pinocchio call",
    )
    table = [head] + [
        (r["level"], r["function"] + (" /state" if r["unit"] == "us/state" else ""),
         us(r["dynid_us"], r["dynid_us_min"]), us(r["pinocchio_us"], r["pinocchio_us_min"]),
         "-" if r["ratio"] is None else f"{r['ratio']:.2f}", r["target"],
         r["status"] + (f" (x{r['off_by']:.2f})" if r["status"] == "not met" else ""),
         r["pinocchio_call"] or "")
        for r in rows
    ]  # fmt: skip
    widths = [max(len(line[c]) for line in table) for c in range(len(head))]
    for k, line in enumerate(table):
        cells = (
            cell.rjust(w) if c in (2, 3, 4) else cell.ljust(w)
            for c, (cell, w) in enumerate(zip(line, widths))
        )
        print("  ".join(cells).rstrip())
        if k == 0:
            print("  ".join("-" * w for w in widths))


def installed_dynid_is_stale() -> bool:
    """Whether the working tree's C++ or Python sources are newer than the dynid being imported.
    The C++ rows are built from the working tree, the Python rows time the installed package."""
    core = Path(getattr(dynid._core, "__file__", "") or "")
    if not core.is_file() or REPO in core.resolve().parents:
        return False
    built = core.stat().st_mtime
    sources = [*REPO.glob("cpp/**/*.[ch]pp"), *REPO.glob("python/dynid/**/*.py")]
    return any(path.stat().st_mtime > built for path in sources)


def main() -> None:
    args = parse_args()
    load = {"start": os.getloadavg()}
    robot = bench_robot()
    pin = import_pinocchio(args.no_pinocchio)
    result: dict[str, Any] = {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "robot": "KUKA LWR-IV (dynid.models.kuka_lwr4), Fv = Fs = 0, Ia as Pinocchio armature",
        "git": git_state(), "dynid_version": getattr(dynid, "__version__", None),
        "pinocchio_python": getattr(pin, "__version__", None),
    }  # fmt: skip
    rows: list[dict[str, Any]] = []
    cpu = None if args.cpu < 0 else args.cpu
    pinned: int | None = None
    python_pinned: int | None = None

    if not args.skip_cpp:
        with_pin_cpp = not args.no_pinocchio
        if with_pin_cpp and cpp_level.pinocchio_include_dir(cpp_level.cmeel_prefixes()) is None:
            print(
                "bench: Pinocchio's C++ headers not found (pip install pin): C++ timings of "
                "dynid only"
            )
        exe = cpp_level.build(args.build_dir, native=args.native, with_pinocchio=with_pin_cpp)
        model_file = args.build_dir / "lwr4_model.txt"
        cpp_level.write_model_file(robot, model_file)
        print(
            f"bench: C++ level ({args.runs} runs of {args.states} calls per function)...",
            flush=True,
        )
        cpp = cpp_level.run(
            exe,
            model_file,
            runs=args.runs,
            calls=args.states,
            states=args.states,
            cpu=cpu,
        )
        pinned = cpp["pinned_cpu"]
        result["cpp"] = cpp
        load["after_cpp"] = os.getloadavg()
        for name in cpp["dynid_us"]:
            dynid_stat = {"median": cpp["dynid_us"][name], "min": cpp["dynid_us_min"][name]}
            pin_stat = None
            if cpp["pinocchio_us"]:
                pin_stat = {"median": cpp["pinocchio_us"][name],
                            "min": cpp["pinocchio_us_min"][name]}  # fmt: skip
            rows.append(make_row("C++", name, dynid_stat, pin_stat))
        order = list(PINOCCHIO_NAMES)
        rows.sort(key=lambda r: order.index((r["level"], r["function"])))

    if not args.skip_python:
        print("bench: Python level...", flush=True)
        result["installed_dynid_stale"] = installed_dynid_is_stale()
        if result["installed_dynid_stale"]:
            print(
                "bench: note: the sources are newer than the installed dynid, which the Python "
                "rows time (refresh: pip install --no-build-isolation .)"
            )
        model = pinocchio_arm.build_model(robot, pin) if pin is not None else None
        data = model.createData() if model is not None else None
        Q, Qd, Qdd = python_level.make_states(robot.n, args.states, seed=1)
        states = list(zip(Q, Qd, Qdd))
        single: dict[str, Any] = {}
        # single calls on the C++ program's CPU; the batch unpinned, free to use its threads
        with python_level.pinned_to(cpu) as python_cpu:
            if pin is not None:
                single["max_abs_diff"] = python_level.check_single(robot, pin, model, data, states)
            single.update(python_level.time_single(robot, pin, model, data, states, args.runs))
        single["pinned_cpu"] = python_pinned = python_cpu
        Qb, Qdb, Qddb = python_level.make_states(robot.n, args.batch, seed=2)
        batch = python_level.batch(robot, pin, model, data, Qb, Qdb, Qddb, args.batch_runs)
        if args.threads > 1:
            batch["threads"] = python_level.batch_threaded(
                robot, Qb, Qdb, Qddb, args.batch_runs, args.threads
            )
        kernels = python_level.batch_kernels(
            robot, pin, model, data, Qb, Qdb, Qddb, args.batch_runs
        )
        result["python"] = {"single": single, "batch": batch, "batch_kernels": kernels}
        for name in ("rnea", "mass_matrix", "gravity"):
            rows.append(make_row("Python", name, single[name]["dynid"], single[name]["pinocchio"]))
        rows.append(
            make_row("Python batch", "rnea", batch["dynid"], batch["pinocchio"], unit="us/state")
        )
        for name in ("gravity", "mass_matrix", "regressor", "regressor_out"):
            k = kernels[name]
            rows.append(make_row("Python batch", name, k["dynid"], k["pinocchio"], unit="us/state"))

    load["end"] = os.getloadavg()
    result["load_average"] = load
    result["machine"] = machine(pinned)
    result["table"] = rows

    pin_version = (result.get("cpp") or {}).get("pinocchio_version") or result["pinocchio_python"]
    versus = f"Pinocchio {pin_version}" if pin_version else "Pinocchio not found: dynid only"
    flags = "; C++ " + result["cpp"]["flags"] if "cpp" in result else ""
    print()
    print_table(
        rows,
        f"dynid vs {versus} -- KUKA LWR-IV (n = 7), median us per call of {args.runs} runs{flags}",
    )
    if "python" in result:
        py = result["python"]
        print(
            f"Python rows include the Python loop's own cost, "
            f"{py['single']['loop_overhead_us']:.3f} us per call"
            + (", on both sides." if pin is not None else ".")
        )
        kernels = py["batch_kernels"]
        print(
            f"batch path: {kernels['isa']} (SIMD lanes, chosen at load time; "
            f"CPU {result['machine']['cpu']}); "
            "batch rnea per path, us/state: "
            + ", ".join(f"{isa} {st['median']:.3f}" for isa, st in kernels["rnea_per_path"].items())
        )
        if py["batch"]["threads"]:
            th = py["batch"]["threads"]
            print(
                f"dynid batch rnea with threads={th['count']}: {th['dynid']['median']:.3f} us/state"
            )
    if pin is None and not args.no_pinocchio:
        print("Pinocchio (Python package 'pin') was not found: ratios and ratio targets n/a.")
    cpus = os.cpu_count() or 1
    print(
        f"load average {load['start'][0]:.2f} at start, {load['end'][0]:.2f} at end, "
        f"on {cpus} CPUs"
        + (f"; C++ pinned to CPU {pinned}" if pinned is not None else "")
        + ("; Python single calls pinned too" if python_pinned is not None else "")
    )
    if max(load["start"][0], load["end"][0]) > cpus - 0.5:
        print("note: the machine was busy; timings are noisier than on an idle one.")

    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(json.dumps(result, indent=2) + "\n")
    print(f"saved {args.output}")


if __name__ == "__main__":
    main()
