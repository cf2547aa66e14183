"""`dynid demo`: the paper's pipeline end to end on a simulated KUKA LWR-IV.

1. A virtual controller (dynid.sim) stands in for the LWR's interface: it returns the numeric
   g(q) and M(q) of its model at random configurations, and measured positions and joint torques
   along a motion tracked in closed loop (1 kHz PD + gravity compensation, friction in the
   joints, a quarter of it on the link side of the torque sensors).
2. The gravity and inertia coefficients are identified from 1000 training configurations
   (paper Sect. V), joint 1's gravity row left out, zero elements of M detected (Sect. VI).
3. Errors on the training and a 200-configuration validation set, in the layout of Tables II-III.
4. A second arm carries a 250 g tip on the flange; the payload mass is estimated from the change
   of the two coefficients that hold d1 (m3+...+m7) and d2 (m5+m6+m7) (eqs. (31)-(32)).
5. The torque validation experiment of eq. (33), positions differentiated numerically and
   filtered by a 4th-order zero-phase Butterworth at 1 Hz, and the final validation experiment
   (Sect. VI, Fig. 5: sinusoids on every joint for a minute, g(q) and M(q) read every 120 ms
   and compared element by element); plots like Figs. 3, 4, 5 and 6. The
   identified model has no friction, so its torques miss the link-side friction in tau_J, as on
   the real robot (paper Sect. VI: "unmodeled dynamics, especially static friction").
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .._checks import count
from .._threads import blas_single_threaded
from ..export.output_folder import check_output_path, output_folder
from ..identification.from_controller import (
    IdentifiedModel,
    identify_from_controller,
    payload_mass_estimates,
)
from ..identification.validation import error_metrics, paper_table
from ..logs.signal import differentiate, lowpass
from ..model import models
from ..model.robot import Robot
from ..sim import StaticReadings, TorqueRecording, VirtualController, paper_validation_trajectory
from ..sim.virtual_controller import (
    FIG5_DURATION,
    FIG5_SAMPLE_TIME,
    paper_final_validation_trajectory,
)

#: Fewest training configurations `dynid demo` accepts. The LWR-IV's 12 gravity coefficients are
#: fitted on 6 rows per configuration (joint 1's gravity row is left out), so 2 configurations
#: determine them exactly and a third leaves residual degrees of freedom for the noise estimate
#: (the 39 inertia coefficients get 28 rows per configuration and are covered by then).
DEMO_MIN_TRAIN = 3
#: Fewest validation configurations: the errors need at least one sample.
DEMO_MIN_VALIDATION = 1

#: Fraction of the joint friction (the model's Fv, Fs) acting between the torque sensor and the
#: link: it appears in tau_J but not in the identified link model. A quarter of the LWR model's
#: friction gives TVE maximum errors of 0.08-0.43 N m (0.39 N m on J2), the size of the paper's
#: Table III (0.37 N m on J2).
LINK_FRICTION = 0.25

TIP_MASS = 0.25  # kg, the paper's symmetric steel tip
TIP_COM = (0.0, 0.0, 0.11)  # m in frame 7 (at the wrist centre): flange plus half the tip
TIP_INERTIA = np.diag([1.5e-4, 1.5e-4, 2.0e-5])  # kg m^2 about its centre: a 9 cm steel rod


def check_demo_sizes(train: object, validation: object) -> tuple[int, int]:
    """The demo's configuration counts, checked (``ValueError`` naming the argument)."""
    train = count(
        train,
        "train",
        DEMO_MIN_TRAIN,
        "the LWR-IV's 12 gravity coefficients get 6 rows per configuration; 3 configurations "
        "leave degrees of freedom for the noise estimate",
    )
    validation = count(
        validation,
        "validation",
        DEMO_MIN_VALIDATION,
        "the validation errors need at least one configuration",
    )
    return train, validation


def controller_model() -> Robot:
    """The LWR-IV model inside the virtual controller: dynid's kuka_lwr4() with the property the
    paper found in the real controller's model, M_76 = 0, i.e. eq. (27): link 7's products of
    inertia Ixz and Iyz about its frame origin vanish."""
    robot = models.kuka_lwr4()
    params = robot.params.copy()
    # link 7's Ixz and Iyz: entries 6 and 8 of [m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz]
    # (docs/conventions.md, "Inertial parameters")
    params[-1, [6, 8]] = 0.0
    robot.params = params
    return robot


@blas_single_threaded  # small dense work throughout (_threads.py)
def run_demo(
    output: str | Path = "dynid-demo",
    train: int = 1000,
    validation: int = 200,
    model_noise: float = 1e-5,
    torque_noise: float = 0.05,
    position_noise: float = 1e-5,
    link_friction: float = LINK_FRICTION,
    seed: int = 0,
    progress: Callable[[str], None] = print,
    overwrite: bool = False,
) -> dict:
    """Run the demo, write JSON and PNGs into ``output`` and return the JSON content.

    ``output`` must not exist or be empty unless ``overwrite`` is True; its files are written
    into a temporary folder that replaces it at the end (:mod:`dynid.export.output_folder`), so an
    earlier demo's results are never mixed with or lost to a run that fails."""
    train, validation = check_demo_sizes(train, validation)
    check_output_path(output, overwrite)  # before the work, not after
    start = time.perf_counter()
    steps = 6

    def step(k: int, text: str) -> None:
        progress(f"[{k}/{steps}] {text}  ({time.perf_counter() - start:.1f} s)")

    # 1. Data from the virtual controller.
    truth = controller_model()
    controller = VirtualController(
        truth,
        seed=seed,
        link_friction=link_friction,
        model_noise=model_noise,
        torque_noise=torque_noise,
        position_noise=position_noise,
    )
    training = controller.read_static(controller.random_configurations(train))
    checking = controller.read_static(controller.random_configurations(validation))
    step(
        1, f"virtual LWR-IV controller: {train} training and {validation} validation configurations"
    )

    # 2. Identification from g and M.
    structure = models.kuka_lwr4()
    ident = identify_from_controller(structure, training.q, training.g, training.M)
    step(
        2,
        f"identified {ident.gravity_base.count} gravity and {ident.inertia_base.count} "
        "inertia coefficients",
    )
    progress(_coefficient_table(ident))
    for zero in ident.zero_elements:
        progress(
            f"  M[{zero.row + 1},{zero.column + 1}] is zero in all the data; implies: "
            + "; ".join(zero.constraints)
        )

    # 3. Training / validation errors.
    g_ts = error_metrics(training.g, ident.gravity(training.q))
    g_vs = error_metrics(checking.g, ident.gravity(checking.q))
    m_ts = _inertia_errors(training, ident)
    m_vs = _inertia_errors(checking, ident)
    step(3, "errors on the training (TS) and validation (VS) sets")

    # 4. The torque validation experiment, eq. (33), tracked in closed loop.
    recording = controller.track(lambda t: paper_validation_trajectory(t, truth.n), 14.0, 1000.0)
    q, qd, qdd, tau, tau_hat = torque_validation(recording, ident)
    tve = error_metrics(tau, tau_hat)
    tracking = np.abs(recording.motion.q - recording.q_desired).max(axis=0)
    step(4, "torque validation experiment q_des(t) = pi/2 cos(pi t / 7), T = 14 s")
    progress(
        "  closed-loop tracking error max [mrad]: " + " ".join(f"{1000 * e:.2f}" for e in tracking)
    )
    excluded = (0,)
    progress(
        paper_table(
            "Table II  mean square error of the gravity estimate (TVE: of tau_J)",
            {"TS": g_ts["mse"], "VS": g_vs["mse"], "TVE": tve["mse"]},
            excluded,
        )
    )
    progress(
        paper_table(
            "Table III  maximum absolute error (TVE: of tau_J)",
            {"TS": g_ts["max_abs"], "VS": g_vs["max_abs"], "TVE": tve["max_abs"]},
            excluded,
            fmt="{:.4g}",
        )
    )
    progress(
        f"  inertia stack: max |error| {m_ts['max_abs']:.3g} (TS), {m_vs['max_abs']:.3g} (VS)"
        f" over {len(ident.inertia_base.names)} coefficients"
    )

    # The final validation experiment (Sect. VI, Fig. 5): sinusoids on every joint for a
    # minute, the controller's g(q) and M(q) read every 120 ms against the identified model's.
    t_fig5 = np.arange(round(FIG5_DURATION / FIG5_SAMPLE_TIME)) * FIG5_SAMPLE_TIME
    final = controller.read_static(paper_final_validation_trajectory(t_fig5)[0])
    g_final, M_final = ident.gravity(final.q), ident.mass_matrix(final.q)
    rows, columns = np.tril_indices(truth.n)  # the 7 + 28 distinct elements of g and M
    gravity_final = np.abs(final.g - g_final).max(axis=0)
    inertia_final = float(np.abs(final.M[:, rows, columns] - M_final[:, rows, columns]).max())
    final_errors = {
        "samples": int(t_fig5.size),
        "gravity_max_abs": [float(e) for e in gravity_final],
        "inertia_max_abs": inertia_final,
    }
    progress(
        f"  final validation (Fig. 5): {t_fig5.size} readings over {FIG5_DURATION:g} s of "
        f"sinusoids, max |error| over the 35 elements: g {gravity_final.max():.3g} N m, "
        f"M {inertia_final:.3g} kg m^2"
    )

    # 5. A second arm with the 250 g tip.
    tip_controller = VirtualController(
        truth.with_payload(TIP_MASS, TIP_COM, TIP_INERTIA),
        seed=seed + 1,
        model_noise=model_noise,
        torque_noise=torque_noise,
        position_noise=position_noise,
    )
    tip = tip_controller.read_static(tip_controller.random_configurations(train))
    tip_ident = identify_from_controller(structure, tip.q, tip.g, tip.M)
    estimates = payload_mass_estimates(ident.gravity_base, ident.pi_g, tip_ident.pi_g)
    step(5, f"payload: a {1000 * TIP_MASS:.0f} g tip on the flange, identified again")
    for e in estimates:
        progress(
            f"  m_tip = delta({e['coefficient']}) / {e['factor']:g} = {e['mass']:.5f} kg"
            f"   [{e['coefficient']} = {e['expression']}]"
        )

    # 6. Files.
    from ..export import plots  # matplotlib: imported when plotting

    with output_folder(output, overwrite) as staging:
        files = [
            plots.plot_joint_signals(
                recording.t,
                q,
                qd,
                qdd,
                staging / "fig3_joint_motion.png",
                "Filtered joint positions, velocities and accelerations (eq. 33)",
            ),
            plots.plot_torques(
                recording.t,
                tau,
                tau_hat,
                staging / "fig4_torques.png",
                "Sensed joint torques (filtered) and estimated torques, eq. (26)",
            ),
            plots.plot_joint_signals(
                t_fig5,
                *paper_final_validation_trajectory(t_fig5),
                staging / "fig5_final_validation_motion.png",
                "Final validation experiment: sinusoids on every joint (Fig. 5)",
            ),
            plots.plot_element_comparison(
                {
                    "g_2(q) [N m]": (final.g[:, 1], g_final[:, 1]),
                    "M_11(q) [kg m^2]": (final.M[:, 0, 0], M_final[:, 0, 0]),
                },
                staging / "fig6_g2_M11.png",
                "Final validation (Fig. 5 motion): controller values and identified model",
            ),
        ]
        report = {
            "robot": structure.name,
            "settings": {
                "train": train,
                "validation": validation,
                "seed": seed,
                "link_friction": link_friction,
                "model_noise": model_noise,
                "torque_noise": torque_noise,
                "position_noise": position_noise,
            },
            "tracking_error_max": [float(e) for e in tracking],
            "coefficients": ident.coefficients(),
            "zero_elements": [vars(z) for z in ident.zero_elements],
            "gravity_errors": {"TS": _lists(g_ts), "VS": _lists(g_vs), "TVE": _lists(tve)},
            "inertia_errors": {"TS": m_ts, "VS": m_vs},
            "final_validation": final_errors,
            "condition_numbers": {
                "gravity": ident.gravity_fit.condition_number,
                "inertia": ident.inertia_fit.condition_number,
            },
            "payload": {"true_mass": TIP_MASS, "estimates": estimates},
            "plots": [p.name for p in files],
            "seconds": round(time.perf_counter() - start, 2),
        }
        (staging / "demo.json").write_text(json.dumps(report, indent=1))
    step(6, f"wrote {Path(output) / 'demo.json'} and {len(files)} plots")
    return report


def torque_validation(
    recording: TorqueRecording, ident: IdentifiedModel, fs: float = 1000.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The torque validation of paper eq. (33) on a recording at ``fs`` Hz: (q, qd, qdd, tau,
    tau_hat), the filtered positions and their derivatives, the filtered measured tau_J and the
    identified model's torques ``ident.rnea(q, qd, qdd)``."""

    def smooth(x: np.ndarray) -> np.ndarray:
        # The motion starts and ends at rest, so the signals are extended evenly at both ends.
        return lowpass(x, fs, 1.0, order=4, padtype="even", settle=True)

    # Filtering q before differentiating equals the paper's differentiate-then-filter (the two
    # commute) except at the ends, where it avoids filtering from a noisy end value.
    q = smooth(recording.q)
    qd = differentiate(q, fs=fs)
    qdd = differentiate(qd, fs=fs)
    tau = smooth(recording.tau)
    return q, qd, qdd, tau, ident.rnea(q, qd, qdd)


def _coefficient_table(ident: IdentifiedModel) -> str:
    fit, base = ident.gravity_fit, ident.gravity_base
    lines = [
        "  gravity coefficients pi_g [kg m] (paper eq. (28)-(29)):",
        f"  {'name':<7}{'value':>12}{'std':>11}  expression",
    ]
    for name, expr, value, std in zip(base.names, base.expressions, fit.theta, fit.std):
        lines.append(f"  {name:<7}{value:>12.5g}{std:>11.2g}  {expr}")
    return "\n".join(lines)


def _inertia_errors(data: StaticReadings, ident: IdentifiedModel) -> dict[str, float]:
    error = ident.mass_matrix(data.q) - data.M
    return {"mse": float(np.mean(error**2)), "max_abs": float(np.max(np.abs(error)))}


def _lists(metrics: dict[str, np.ndarray]) -> dict[str, list[float]]:
    return {key: [float(v) for v in value] for key, value in metrics.items()}
