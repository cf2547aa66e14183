"""Identify the lecture's parallelogram robot (notes pp. 7-10) from a log of its two motors.

A closed chain's controller records only the actuated joints: here a simulated recording of q
and tau at 500 Hz (an exciting sum of sinusoids, the torques of the true model with 0.05 N m of
noise, quantised encoders), written as dynid's CSV and read back as any log would be. The base
parameters -- the loop's own groupings B11, B22, B12 / l2 and the gravity coefficients of p. 9-10,
with viscous and Coulomb friction on the motors -- are identified with velocities and
accelerations differentiated from the positions, and compared with the truth.

Two choices matter, both printed below: the 8 Hz low-pass smooths the torque's Coulomb steps
while the model's sign(qd) stays a step, so the samples where a joint moves slower than
0.5 rad/s are left out (``min_velocity``; without it Fv1 and Fs1 come out 5-6 standard deviations
off, docs/data.md "Near-zero velocity"); and the filtered residuals are correlated in time, so the
standard deviations are the correlation-robust ones (5-7 times the independent-samples ones
here, noted in ``fit.notes``).

    python examples/closed_chain_identification.py [OUTPUT_DIR]
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

import dynid


def simulated_recording(
    chain: dynid.ClosedChain, seconds: float = 60.0, rate: float = 500.0
) -> dynid.Log:
    rng = np.random.default_rng(0)
    t = np.arange(0.0, seconds, 1.0 / rate)
    w = 2 * np.pi * np.array([0.1, 0.23, 0.37, 0.51])  # Hz -> rad/s
    amplitude = rng.uniform(0.2, 0.5, (2, 4))
    phase = rng.uniform(0, 2 * np.pi, (2, 4))
    arg = w * t[:, None, None] + phase
    q = np.array([0.6, 2.0]) + np.sum(amplitude * np.sin(arg), axis=2)  # |q2 - q1| stays > 0.3
    qd = np.sum(amplitude * w * np.cos(arg), axis=2)
    qdd = -np.sum(amplitude * w**2 * np.sin(arg), axis=2)
    tau = chain.rnea(q, qd, qdd) + 0.05 * rng.normal(size=q.shape)
    encoder = 2 * np.pi / 2**20  # a 20-bit encoder
    return dynid.Log(t=t, q=np.round(q / encoder) * encoder, tau=tau, source="simulated motors")


def main(folder: Path) -> None:
    chain = dynid.models.planar_parallelogram(
        masses=(2.0, 1.5, 1.2, 0.8),
        inertias=(0.10, 0.08, 0.05, 0.03),
        com_distances=(0.3, 0.25, 0.4, 0.1),
        l1=0.7,
        l2=0.5,
    )
    chain.Fv, chain.Fs = [0.3, 0.2], [0.6, 0.4]

    path = folder / "parallelogram_motors.csv"
    dynid.save_log(simulated_recording(chain), path)
    log = dynid.load_log(path)  # t, q1, q2, tau1, tau2: no velocities

    fit = dynid.identify_closed_chain(log, chain, friction=True, cutoff=8.0, min_velocity=0.5)
    truth = fit.base.values(chain)
    z = (fit.theta - truth) / fit.std
    print(f"{log.t.size} samples from {path.name}; {fit.base.count} base parameters")
    print(*(f"- {note}" for note in fit.notes), sep="\n")
    print(f"\n{'parameter':<8} {'identified':>11} {'std':>9} {'true':>9} {'z':>6}   expression")
    for name, value, std, true, score, text in zip(
        fit.base.names, fit.theta, fit.std, truth, z, fit.base.expressions
    ):
        print(f"{name:<8} {value:>11.5f} {std:>9.5f} {true:>9.5f} {score:>6.2f}   {text}")
    worst = np.max(np.abs(fit.theta - truth) / np.maximum(np.abs(truth), 0.1))
    print(
        f"\nlargest error: {worst:.2%} of max(|true value|, 0.1); largest |z| {np.abs(z).max():.2f}"
    )


if __name__ == "__main__":
    if len(sys.argv) > 1:
        main(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            main(Path(tmp))
