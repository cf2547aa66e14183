"""Closed-loop data: WLS against IDIM-IV and DIDIM (docs/identification.md, "Closed-loop data").

A planar 2R arm with viscous friction tracks a 3-harmonic reference under a PD controller at
1 kHz that sees its positions with 1 mrad of white noise; the log holds those positions and the
commanded torque with 1 N m of measurement noise. The noise fed back by the controller and the
noisy regressor bias WLS; IV and DIDIM, given the controller (law, gains, reference), do not.
Prints each estimate's error in its own standard deviations and the wall time.

    python examples/closed_loop_identification.py
"""

from __future__ import annotations

import time

import numpy as np

import dynid
from dynid.logs import Log
from dynid.sim import simulate

KP, KD = np.array([400.0, 200.0]), np.array([40.0, 20.0])
HARMONICS = np.array([[0.8, -0.5, 0.3], [0.9, 0.4, -0.3]])  # joint x harmonic, rad/s
W0 = 2 * np.pi * 0.25


def reference(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The controller's q_d, qd_d, qdd_d on the log's clock."""
    s = np.asarray(t, dtype=float)[:, None]
    q, qd, qdd = (np.zeros((s.shape[0], 2)) for _ in range(3))
    for k in range(1, 4):
        a = HARMONICS[:, k - 1]
        q += a * np.sin(k * W0 * s) / k
        qd += a * W0 * np.cos(k * W0 * s)
        qdd -= a * k * W0**2 * np.sin(k * W0 * s)
    return q, qd, qdd


def experiment(robot: dynid.Robot, seconds: float = 16.0, dt: float = 1e-3) -> Log:
    rng = np.random.default_rng(0)
    steps = round(seconds / dt)
    noise = rng.normal(scale=1e-3, size=(steps + 1, 2))
    q_d, qd_d, _ = reference(np.arange(steps + 1) * dt)

    def pd(t, q, qd):  # the robot's controller, fed the noisy positions
        k = round(t / dt)
        velocity = qd + (noise[k] - noise[k - 1]) / dt if k else qd
        return KP * (q_d[k] - q - noise[k]) + KD * (qd_d[k] - velocity)

    run = simulate(robot, q_d[0], qd_d[0], seconds, pd, dt=dt)
    tau = run.tau + rng.normal(scale=1.0, size=run.tau.shape)
    return Log(t=run.t, q=run.q + noise, tau=tau, source="PD with noisy positions")


def main() -> None:
    robot = dynid.models.planar_2r()
    robot.Fv = np.array([0.8, 0.5])
    truth = dynid.base_parameters(robot, friction=True).values(robot)
    log = experiment(robot)
    controller = {"controller": "pd", "kp": KP, "kd": KD, "reference": reference}
    controller["control_period"] = 1e-3  # the log is decimated below; the controller is not
    for method in ("wls", "iv", "didim"):
        began = time.perf_counter()
        result = dynid.identify_log(
            log,
            robot,
            friction=True,
            method=method,
            preparation={"cutoff": 10.0, "decimate": 40},
            estimator_options=None if method == "wls" else controller,
        )
        seconds = time.perf_counter() - began
        z = (result.theta - truth) / result.std
        iterations = "" if result.estimator is None else f"{result.estimator['iterations']} it."
        print(
            f"{method:6s} {seconds:5.2f} s {iterations:6s} (estimate - truth) / std: "
            + " ".join(f"{name}={value:+.1f}" for name, value in zip(result.names, z))
        )


if __name__ == "__main__":
    main()
