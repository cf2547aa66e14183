// Model's dynamics calls, one entry each (the form: calls.hpp): name, per-sample inputs, result
// shape per sample, the per-sample kernel, the batch kernel and the docstring. The pybind11
// method, its fast path, text signature and docstring are generated from the entry (calls.cpp);
// a new call is one entry here.
#pragma once

#include <string>
#include <tuple>
#include <vector>

#include "calls.hpp"

namespace dynid::binding {

// regressor's options: the rotor and friction columns, and a selection of columns (e.g. the base
// parameters').
struct RegressorOptions {
  bool rotor = false, friction = false;
  std::vector<int> columns;  // empty: all
  static constexpr std::array<OptionArg, 3> args{
      {{"rotor", "False"}, {"friction", "False"}, {"columns", "None"}}};
  static RegressorOptions parse(const py::handle* arg, int n) {
    RegressorOptions o;
    o.rotor = parse_flag(arg[0], "rotor");
    o.friction = parse_flag(arg[1], "friction");
    if (!arg[2].is_none()) o.columns = parse_columns(arg[2], o.all_columns(n));
    return o;
  }
  int all_columns(int n) const { return regressor_columns(n, rotor, friction); }
  int width(int n) const {
    return columns.empty() ? all_columns(n) : static_cast<int>(columns.size());
  }
};

// inertia_regressor's option: the rotor columns.
struct RotorOption {
  bool rotor = false;
  static constexpr std::array<OptionArg, 1> args{{{"rotor", "False"}}};
  static RotorOption parse(const py::handle* arg, int) { return {parse_flag(arg[0], "rotor")}; }
};

inline constexpr auto kCalls = std::make_tuple(
    call<ReturnsArrayOrOut>(
        "rnea", {"q", "qd", "qdd"}, per_joint,
        [](const auto& s, double* tau) {
          rnea(s.model, s.ws, s[0], s[1], s[2], OutVec(tau, s.n()));
        },
        [](const auto& b, batch::Results tau) {
          return batch::rnea(b.model, b.ws, b[0], b[1], b[2], tau);
        },
        "Joint torques tau = M qdd + c + g + Fv qd + Fs sign(qd) (recursive Newton-Euler); with a "
        "transmission T the friction is T^T (Fv T qd + Fs sign(T qd))."),
    call<ReturnsArrayOrOut>(
        "mass_matrix", {"q"}, joint_by_joint,
        [](const auto& s, double* M) { crba(s.model, s.ws, s[0], row_major(M, s.n(), s.n())); },
        [](const auto& b, batch::Results M) { return batch::mass_matrix(b.model, b.ws, b[0], M); },
        "Joint-space inertia matrix M(q) = B(q) + diag(Ia) (CRBA); T^T diag(Ia) T with a "
        "transmission T."),
    call<ReturnsArrayOrOut>(
        "gravity", {"q"}, per_joint,
        [](const auto& s, double* g) { gravity(s.model, s.ws, s[0], OutVec(g, s.n())); },
        [](const auto& b, batch::Results g) { return batch::gravity(b.model, b.ws, b[0], g); },
        "Gravity torques g(q)."),
    call<ReturnsArrayOrOut>(
        "coriolis", {"q", "qd"}, per_joint,
        [](const auto& s, double* c) { coriolis(s.model, s.ws, s[0], s[1], OutVec(c, s.n())); },
        [](const auto& b, batch::Results c) {
          return batch::coriolis(b.model, b.ws, b[0], b[1], c);
        },
        "Coriolis and centrifugal torques c(q, qd)."),
    call<ReturnsArrayOrOut>(
        "coriolis_matrix", {"q", "qd"}, joint_by_joint,
        [](const auto& s, double* S) {
          coriolis_matrix(s.model, s.ws, s[0], s[1], row_major(S, s.n(), s.n()));
        },
        [](const auto& b, batch::Results S) {
          return batch::coriolis_matrix(b.model, b.ws, b[0], b[1], S);
        },
        "Coriolis matrix S(q, qd) from the Christoffel symbols: c = S qd, Mdot - 2S "
        "skew-symmetric."),
    call<ReturnsArrayOrOut>(
        "friction", {"qd"}, per_joint,
        [](const auto& s, double* tau) { friction(s.model, s[0], OutVec(tau, s.n())); },
        [](const auto& b, batch::Results tau) { return batch::friction(b.model, b.ws, b[0], tau); },
        "Joint friction Fv qd + Fs sign(qd); T^T (Fv T qd + Fs sign(T qd)) with a transmission "
        "T."),
    call<ReturnsArrayOrOut>(
        "forward_dynamics", {"q", "qd", "tau"}, per_joint,
        [](const auto& s, double* qdd) {
          forward_dynamics(s.model, s.ws, s[0], s[1], s[2], OutVec(qdd, s.n()));
        },
        [](const auto& b, batch::Results qdd) {
          return batch::forward_dynamics(b.model, b.ws, b[0], b[1], b[2], qdd);
        },
        "Joint accelerations for the torques tau.", /*params_error=*/true),
    call<ReturnsFloat>(
        "kinetic_energy", {"q", "qd"}, scalar,
        [](const auto& s) { return kinetic_energy(s.model, s.ws, s[0], s[1]); },
        [](const auto& b, batch::Results E) {
          return batch::kinetic_energy(b.model, b.ws, b[0], b[1], E);
        },
        "Kinetic energy 1/2 qd^T M(q) qd (rotors included)."),
    call<ReturnsFloat>(
        "potential_energy", {"q"}, scalar,
        [](const auto& s) { return potential_energy(s.model, s.ws, s[0]); },
        [](const auto& b, batch::Results E) {
          return batch::potential_energy(b.model, b.ws, b[0], E);
        },
        "Gravity potential energy -sum m_i g^T p_ci (zero at the world origin)."),
    call<ReturnsArrayOrOut>(
        "fkine", {"q"}, [](int, const auto&) { return Shape{2, {4, 4}}; },
        [](const auto& s, double* T) { fkine(s.model, s.ws, s[0], row_major(T, 4, 4)); },
        [](const auto& b, batch::Results T) { return batch::fkine(b.model, b.ws, b[0], T); },
        "World pose (4, 4) of the tool: base A_1 ... A_n tool."),
    call<ReturnsArrayOrOut>(
        "jacobian", {"q"}, [](int n, const auto&) { return Shape{2, {6, n}}; },
        [](const auto& s, double* J) { jacobian(s.model, s.ws, s[0], row_major(J, 6, s.n())); },
        [](const auto& b, batch::Results J) { return batch::jacobian(b.model, b.ws, b[0], J); },
        "Geometric Jacobian (6, n) of the tool point in world axes, rows [v; omega]."),
    call<ReturnsArray>(
        "jacobian_dot", {"q", "qd"}, [](int n, const auto&) { return Shape{2, {6, n}}; },
        [](const auto& s, double* Jdot) {
          jacobian_dot(s.model, s.ws, s[0], s[1], row_major(Jdot, 6, s.n()));
        },
        [](const auto& b, batch::Results Jdot) {
          return batch::jacobian_dot(b.model, b.ws, b[0], b[1], Jdot);
        },
        "Time derivative (6, n) of jacobian(q) along qd: tool point, world axes, rows [v; "
        "omega]."),
    call<ReturnsArrayOrOut, RegressorOptions>(
        "regressor", {"q", "qd", "qdd"},
        [](int n, const RegressorOptions& o) { return Shape{2, {n, o.width(n)}}; },
        [](const auto& s, double* Y) {
          const int n = s.n(), P = s.options.all_columns(n);
          if (s.options.columns.empty()) {
            regressor(s.model, s.ws, s[0], s[1], s[2], s.options.rotor, s.options.friction,
                      RowMajorMap(Y, n, P));
            return;
          }
          // Only the selected columns: the full regressor goes to a buffer, the columns out.
          thread_local std::vector<double> full;
          full.resize(static_cast<std::size_t>(n) * P);
          regressor(s.model, s.ws, s[0], s[1], s[2], s.options.rotor, s.options.friction,
                    RowMajorMap(full.data(), n, P));
          const std::vector<int>& columns = s.options.columns;
          const int C = static_cast<int>(columns.size());
          for (int i = 0; i < n; ++i)
            for (int k = 0; k < C; ++k)
              Y[i * C + k] = full[static_cast<std::size_t>(i) * P + columns[k]];
        },
        [](const auto& b, batch::Results Y) {
          const RegressorOptions& o = b.options;
          if (o.columns.empty())
            return batch::regressor(b.model, b.ws, b[0], b[1], b[2], o.rotor, o.friction, Y);
          return batch::regressor(b.model, b.ws, b[0], b[1], b[2], o.rotor, o.friction, o.columns,
                                  Y);
        },
        "Joint-torque regressor Y (n, P) with Y @ parameter_vector(rotor, friction) == rnea; "
        "with "
        "columns (indices into the P columns, e.g. base_parameters(...).independent) only those, "
        "(n, len(columns)); out: a preallocated float64 result array of the exact shape."),
    call<ReturnsArrayOrOut>(
        "gravity_regressor", {"q"}, [](int n, const auto&) { return Shape{2, {n, 10 * n}}; },
        [](const auto& s, double* Y) {
          gravity_regressor(s.model, s.ws, s[0], RowMajorMap(Y, s.n(), 10 * s.n()));
        },
        [](const auto& b, batch::Results Y) {
          return batch::gravity_regressor(b.model, b.ws, b[0], Y);
        },
        "Gravity regressor Y_g (n, 10n) with Y_g @ pi == gravity(q) (paper eq. (17))."),
    call<ReturnsArrayOrOut, RotorOption>(
        "inertia_regressor", {"q"},
        [](int n, const RotorOption& o) {
          return Shape{2, {n * (n + 1) / 2, 10 * n + (o.rotor ? n : 0)}};
        },
        [](const auto& s, double* Y) {
          const int n = s.n();
          inertia_regressor(s.model, s.ws, s[0], s.options.rotor,
                            RowMajorMap(Y, n * (n + 1) / 2, 10 * n + (s.options.rotor ? n : 0)));
        },
        [](const auto& b, batch::Results Y) {
          return batch::inertia_regressor(b.model, b.ws, b[0], b.options.rotor, Y);
        },
        "Inertia-stack regressor Y_m (n(n+1)/2, 10n [+n]): Y_m @ pi == M[np.tril_indices(n)] "
        "(links only, or with the rotor columns the full M) (paper eq. (18))."),
    // Both matrices of a sample side by side: [..., 0, :, :] = dtau/dq, [..., 1, :, :] = dtau/dqd.
    call<ReturnsParts<2>>(
        "rnea_derivatives", {"q", "qd", "qdd"},
        [](int n, const auto&) { return Shape{3, {2, n, n}}; },
        [](const auto& s, double* out) {
          const int n = s.n();
          rnea_derivatives(s.model, s.ws, s[0], s[1], s[2], row_major(out, n, n),
                           row_major(out + n * n, n, n));
        },
        [](const auto& b, batch::Results dtau) {
          return batch::rnea_derivatives(b.model, b.ws, b[0], b[1], b[2], dtau);
        },
        "Analytic partial derivatives (dtau_dq, dtau_dqd) of the joint torques (n, n) each, or "
        "(T, "
        "n, n) each for T samples (Carpentier & Mansard 2018); dtau_dqd includes diag(Fv), "
        "dtau/dqdd "
        "is mass_matrix(q). Both are views into one (2, n, n) or (T, 2, n, n) array."),
    // The three vectors of a sample in one block: [..., 0, :] = tau, 1: tau_dot, 2: tau_ddot.
    call<ReturnsParts<3>>(
        "rnea_time_derivatives", {"q", "qd", "qdd", "qddd", "qdddd"},
        [](int n, const auto&) { return Shape{2, {3, n}}; },
        [](const auto& s, double* out) {
          const int n = s.n();
          OutVec tau(out, n), tau_dot(out + n, n), tau_ddot(out + 2 * n, n);
          rnea_time_derivatives(s.model, s.ws, s[0], s[1], s[2], s[3], s[4], tau, tau_dot,
                                tau_ddot);
        },
        [](const auto& b, batch::Results out) {
          return batch::rnea_time_derivatives(b.model, b.ws, b[0], b[1], b[2], b[3], b[4], out);
        },
        "Inverse dynamics and its exact first and second time derivatives (tau, tau_dot, "
        "tau_ddot) "
        "along a motion with joint derivatives qd, qdd, qddd (jerk) and qdddd (snap): (n,) each, "
        "or "
        "(T, n) each for T samples (views into one (3, n) or (T, 3, n) array). tau equals rnea(q, "
        "qd, "
        "qdd) (links, gravity and drive terms); tau_dot = dtau/dq qd + dtau/dqd qdd + M qddd, "
        "tau_ddot its time derivative. Drive terms are included (Ia qddd + Fv qdd and Ia qdddd + "
        "Fv "
        "qddd); Coulomb friction is flat away from qd = 0. Use robot.rigid_body() for the links "
        "alone (the link side of ElasticRobot)."));

static_assert(check_table(kCalls, std::make_index_sequence<std::tuple_size_v<decltype(kCalls)>>()),
              "call_table.hpp: an entry without a name, an input name or a docstring, or two "
              "entries with one name");

}  // namespace dynid::binding
