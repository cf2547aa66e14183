"""trajectory.hpp: an experiment's trajectory as a header-only C++17 function for a real-time loop.

The coefficients are ``constexpr`` arrays written with Python's shortest round-trip repr (the
compiler reads each back to the same double), and ``evaluate(t, q, qd, qdd)`` sums the series of
docs/excitation.md with std::sin / std::cos: no allocation, no exception, no state, so it may
run in a 1 kHz loop. Times are clamped to [0, duration] as
:meth:`dynid.excitation.trajectory_files.ExperimentTrajectory.evaluate` does (at rest outside).
"""

from __future__ import annotations

import json

import numpy as np
from numpy.typing import NDArray

from .._version import dynid_version
from ..excitation.trajectory_files import ExperimentTrajectory

#: The C++ namespace of the header's names.
NAMESPACE = "dynid_trajectory"

_EVALUATE = """\
// q, qd, qdd: kJoints values each [rad, rad/s, rad/s^2; m, m/s, m/s^2 for a prismatic joint].
// t [s] from the start; clamped to [0, kDuration], where the arm is at rest (q(0) = q(kDuration)).
inline void evaluate(double t, double* q, double* qd, double* qdd) noexcept {
  if (!(t > 0.0)) t = 0.0;  // also a NaN
  if (t > kDuration) t = kDuration;
  for (std::size_t i = 0; i < kJoints; ++i) {
    q[i] = kQ0[i];
    qd[i] = 0.0;
    qdd[i] = 0.0;
  }
  for (std::size_t l = 0; l < kHarmonics; ++l) {
    const double w = kBaseFrequency * static_cast<double>(l + 1);  // wf l
    const double s = std::sin(w * t);
    const double c = std::cos(w * t);
    for (std::size_t i = 0; i < kJoints; ++i) {
      q[i] += kA[i][l] / w * s - kB[i][l] / w * c;
      qd[i] += kA[i][l] * c + kB[i][l] * s;
      qdd[i] += w * (kB[i][l] * c - kA[i][l] * s);
    }
  }
}

inline void evaluate(double t, std::array<double, kJoints>& q, std::array<double, kJoints>& qd,
                     std::array<double, kJoints>& qdd) noexcept {
  evaluate(t, q.data(), qd.data(), qdd.data());
}
"""


def cpp_header(plan: ExperimentTrajectory) -> str:
    """The text of trajectory.hpp for ``plan``."""
    traj = plan.trajectory
    names = ", ".join(json.dumps(name) for name in plan.joint_names)  # a JSON string is a C one
    lines = [
        f"// trajectory.hpp: written by dynid excite (dynid {dynid_version()}); do not edit.",
        f"// Model {json.dumps(plan.model)}: {traj.n} joints, {traj.harmonics} harmonics, "
        f"{plan.periods} period(s) of {traj.period!r} s, ramp {plan.ramp}.",
        "// q_i(t) = q0_i + sum_l a_il/(wf l) sin(wf l t) - b_il/(wf l) cos(wf l t)",
        "// (Swevers et al. 1997; dynid docs/excitation.md). Header-only C++17, no allocation.",
        "#pragma once",
        "",
        "#include <array>",
        "#include <cmath>",
        "#include <cstddef>",
        "",
        f"namespace {NAMESPACE} {{",
        "",
        f"constexpr std::size_t kJoints = {traj.n};",
        f"constexpr std::size_t kHarmonics = {traj.harmonics};",
        f"constexpr double kBaseFrequency = {_double(traj.base_frequency)};  // wf [rad/s]",
        f"constexpr double kPeriod = {_double(traj.period)};  // 2 pi / wf [s]",
        f"constexpr double kDuration = {_double(plan.duration)};  // {plan.periods} period(s) [s]",
        f"constexpr const char* kJointNames[kJoints] = {{{names}}};",
        "// velocity amplitudes a_il, b_il [rad/s] and mean positions q0_i [rad]",
        f"constexpr double kA[kJoints][kHarmonics] = {_matrix(traj.a)};",
        f"constexpr double kB[kJoints][kHarmonics] = {_matrix(traj.b)};",
        f"constexpr double kQ0[kJoints] = {_row(traj.q0)};",
        "",
        _EVALUATE,
        f"}}  // namespace {NAMESPACE}",
    ]
    return "\n".join(lines) + "\n"


def _double(value: float) -> str:
    text = repr(float(value))  # the shortest text that reads back as the same double
    return text if any(c in text for c in ".en") else text + ".0"


def _row(values: NDArray[np.float64]) -> str:
    return "{" + ", ".join(_double(v) for v in values) + "}"


def _matrix(values: NDArray[np.float64]) -> str:
    return "{" + ", ".join(_row(row) for row in values) + "}"
