"""The table of docs/payload.md, "Why the inertia was 5 standard deviations off": RMS of the
payload's z-scores (estimate - truth) / std over seeds on a simulated UR5, for four ways of
computing them, without a filter and low-passed at 50 and 10 Hz. A measurement, not a test
(tests/test_payload_command.py holds the checks). About 3 minutes.

    python bench/payload_zscores.py [--seeds 20]
"""

from __future__ import annotations

import argparse

import numpy as np

import dynid
from dynid.identification.payload import PayloadEstimate, _physical
from dynid.identification.payload_logs import estimate_payload_from_logs

MASS, COM = 2.0, np.array([0.01, -0.02, 0.05])
INERTIA = np.diag([4e-3, 5e-3, 3e-3])
NOISE = np.array([0.3, 0.3, 0.2, 0.05, 0.05, 0.05])  # N m per joint
FS, SECONDS = 500.0, 20.0


def log_of(robot: dynid.Robot, seed: int, rng: np.random.Generator) -> dynid.Log:
    """A Fourier trajectory (0.1 Hz, 5 harmonics) of ``seed``, torques with NOISE."""
    r = np.random.default_rng(seed)
    trajectory = dynid.FourierTrajectory(
        2 * np.pi * 0.1, 0.25 * r.standard_normal((6, 5)), 0.25 * r.standard_normal((6, 5)),
        np.zeros(6),
    )  # fmt: skip
    t = np.arange(0.0, SECONDS, 1.0 / FS)
    q, qd, qdd = trajectory.evaluate(t)
    return dynid.Log(t=t, q=q, tau=robot.rnea(q, qd, qdd) + NOISE * rng.standard_normal(q.shape))


def z_scores(estimate: PayloadEstimate) -> np.ndarray:
    assert estimate.com_std is not None and estimate.inertia_std is not None
    assert estimate.com is not None and estimate.inertia is not None
    return np.concatenate(
        [
            [(estimate.mass - MASS) / estimate.mass_std],
            (estimate.com - COM) / estimate.com_std,
            ((estimate.inertia - INERTIA) / estimate.inertia_std)[np.triu_indices(3)],
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=20)
    args = parser.parse_args()
    robot = dynid.models.ur5()
    loaded_arm = robot.with_payload(MASS, COM, INERTIA)
    for cutoff in (0.0, 50.0, 10.0):
        preparation = {"cutoff": cutoff} if cutoff > 0 else {}
        rows: dict[str, list[np.ndarray]] = {
            "two-step, result as exact": [],
            "two-step, true unloaded model": [],
            "joint fit, white std": [],
            "joint fit, std of dynid payload": [],
        }
        for seed in range(args.seeds):
            rng = np.random.default_rng(seed)
            unloaded = log_of(robot, 1000 + seed, rng)
            loaded = log_of(loaded_arm, 2000 + seed, rng)
            result = dynid.identify_log(unloaded, robot, preparation=preparation)
            p = dynid.prepare_log(loaded, **preparation)
            arrays = (robot, p.q, p.qd, p.qdd, p.tau)
            rows["two-step, result as exact"].append(
                z_scores(
                    dynid.estimate_payload(*arrays, tau_unloaded=result.predict(p), method="wls")
                )
            )
            rows["two-step, true unloaded model"].append(
                z_scores(dynid.estimate_payload(*arrays, method="wls"))
            )
            joint = estimate_payload_from_logs(unloaded, loaded, robot, preparation=preparation)
            assert joint.fit is not None
            k = joint.fit.theta.size - 10
            white = _physical(
                joint.fit.theta[k:], joint.fit.covariance[k:, k:], robot, "flange", None
            )
            rows["joint fit, white std"].append(z_scores(white))
            rows["joint fit, std of dynid payload"].append(z_scores(joint))
        print(
            f"cutoff {cutoff:g} Hz at {FS:g} Hz, RMS of z over {args.seeds} seeds "
            "[m cx cy cz | Ixx Ixy Ixz Iyy Iyz Izz]"
        )
        for name, z in rows.items():
            print(f"  {name:32s}", np.sqrt((np.array(z) ** 2).mean(axis=0)).round(2))


if __name__ == "__main__":
    main()
