"""Identify many logs in parallel on Dask's local cluster (docs/parallel.md).

Every object crossing to a worker is pickled: the robot model (``dynid.Robot``), the logs and the
identification results all pickle, so each worker runs ``identify_log`` on its own log and sends
the result back. Dask is an optional extra (``pip install "dynid[dask]"``), not a dependency.

    python examples/dask_identify_logs.py \\
        tests/data/measurements_1.npz tests/data/measurements_2.npz
"""

from __future__ import annotations

import sys

import dynid


def identify_one(path: str, robot: dynid.Robot) -> dynid.LogIdentification:
    # Runs in a worker process: load, identify, return the (picklable) result.
    log = dynid.load_log(path, skip=500)
    return dynid.identify_log(log, robot, rotor=True, friction=True, offset=True)


def main(paths: list[str]) -> None:
    from dask.distributed import Client, LocalCluster

    robot = dynid.models.kuka_lwr4()
    # One thread per worker: the C++ batch calls and BLAS already use the core they run on.
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster,
        Client(cluster) as client,
    ):
        futures = [client.submit(identify_one, path, robot) for path in paths]
        for path, result in zip(paths, client.gather(futures)):
            rel = result.training["metrics"]["relative_rms"]
            print(
                f"{path}: {result.count} base parameters, rel. RMS per joint "
                + " ".join(f"{100 * r:.2f}%" for r in rel)
            )


if __name__ == "__main__":
    main(sys.argv[1:] or ["tests/data/measurements_1.npz", "tests/data/measurements_2.npz"])
