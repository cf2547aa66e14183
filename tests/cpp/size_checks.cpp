// Probe of the C++ size checks (docs/cpp.md, "Argument checks"): every public algorithm, called
// with each of its arguments the wrong size in turn, throws std::invalid_argument whose message
// starts with that argument's name (and names the function); called with the right sizes it works,
// and its result agrees with an independent route (rnea = M qdd + S qd + g + friction, Y pi = rnea,
// the gravity and inertia regressors against g and M, forward dynamics inverting rnea, 2 T = qd^T M
// qd, fkine's and the Jacobian's shapes), to 1e-9.
//
// Built with -fsanitize=address,undefined by tests/cpp/CMakeLists.txt (run by ctest and
// tests/test_cpp_sanitizers.py): before the checks existed, rnea with a 3-entry qd and a 2-entry
// tau on a 7-joint model wrote out of bounds (AddressSanitizer: heap-buffer-overflow).
//
// Exit status: 0 when every probe passed, 1 otherwise (each failure printed).
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/dynid.hpp"

namespace {

using dynid::MatrixX;
using dynid::RowMajorMatrixX;
using dynid::VectorX;

int failures = 0;
int probes = 0;

void fail(const std::string& what) {
  std::printf("FAIL %s\n", what.c_str());
  ++failures;
}

// call() must throw std::invalid_argument whose message begins "argument:" and names function
// (the algorithms' messages end "(in dynid::rnea)"; the Model's setters and the RLS's methods
// name only the argument: `function` is then the class, for the label).
void expect_rejected(const std::string& function, const std::string& argument,
                     const std::function<void()>& call, bool names_function = true) {
  ++probes;
  const std::string label = function + "(" + argument + " wrong)";
  try {
    call();
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    if (message.rfind(argument + ":", 0) != 0)
      fail(label + ": message does not start with '" + argument + ":': " + message);
    else if (names_function && message.find("dynid::" + function) == std::string::npos)
      fail(label + ": message does not name " + function + ": " + message);
    return;
  } catch (const std::exception& e) {
    fail(label + ": threw another exception: " + e.what());
    return;
  }
  fail(label + ": did not throw");
}

void expect_close(const std::string& what, double error, double tolerance = 1e-9) {
  ++probes;
  if (!(error <= tolerance)) fail(what + ": error " + std::to_string(error));
}

// A 3-joint arm, standard DH, revolute-prismatic-revolute, with physically consistent links and
// drive terms, so that every algorithm has something to compute.
dynid::Model make_arm() {
  std::vector<dynid::DHRow> rows(3);
  rows[0] = {0.1, M_PI / 2, 0.3, 0.2, dynid::JointType::Revolute};
  rows[1] = {0.0, -M_PI / 2, 0.2, 0.0, dynid::JointType::Prismatic};
  rows[2] = {0.25, 0.3, 0.0, -0.1, dynid::JointType::Revolute};
  dynid::Model model(rows, dynid::Convention::Standard);
  for (int i = 0; i < 3; ++i) {
    const dynid::Matrix3 inertia = dynid::Vector3(0.02 + 0.01 * i, 0.03, 0.025).asDiagonal();
    model.set_link(i, dynid::RigidBodyParameters::from_physical(
                          1.0 + i, dynid::Vector3(0.05, -0.02 * i, 0.1), inertia));
  }
  model.set_rotor_inertia(VectorX::Constant(3, 0.1));
  model.set_viscous_friction(VectorX::Constant(3, 0.5));
  model.set_coulomb_friction(VectorX::Constant(3, 0.2));
  return model;
}

}  // namespace

int main() {
  const dynid::Model model = make_arm();
  const int n = model.n();
  dynid::Workspace ws(model);
  std::vector<dynid::DHRow> two_rows(2);
  const dynid::Model other(two_rows, dynid::Convention::Modified);
  dynid::Workspace ws_other(other);  // made for 2 joints

  VectorX q(n), qd(n), qdd(n), tau(n), out(n);
  q << 0.3, 0.15, -0.7;
  qd << 0.5, -0.2, 1.1;
  qdd << -0.4, 0.8, 0.25;
  const VectorX short_vector = VectorX::Zero(n - 1), long_vector = VectorX::Zero(n + 4);
  VectorX short_out(n - 1), long_out(n + 1);
  MatrixX M(n, n), S(n, n), wrong_square(n + 1, n + 1), wrong_rows(n - 1, n);
  const int P = dynid::regressor_columns(n, true, true);
  RowMajorMatrixX Y(n, P), Yg(n, 10 * n), Ym(n * (n + 1) / 2, 10 * n + n);
  MatrixX T(4, 4), J(6, n);

  // ---- each argument wrong in turn ----
  expect_rejected("rnea", "ws", [&] { dynid::rnea(model, ws_other, q, qd, qdd, tau); });
  expect_rejected("rnea", "q", [&] { dynid::rnea(model, ws, short_vector, qd, qdd, tau); });
  expect_rejected("rnea", "qd", [&] { dynid::rnea(model, ws, q, short_vector, qdd, tau); });
  expect_rejected("rnea", "qdd", [&] { dynid::rnea(model, ws, q, qd, long_vector, tau); });
  expect_rejected("rnea", "tau", [&] { dynid::rnea(model, ws, q, qd, qdd, short_out); });
  expect_rejected("rnea", "tau", [&] { dynid::rnea(model, ws, q, qd, qdd, long_out); });

  expect_rejected("crba", "ws", [&] { dynid::crba(model, ws_other, q, M); });
  expect_rejected("crba", "q", [&] { dynid::crba(model, ws, long_vector, M); });
  expect_rejected("crba", "M", [&] { dynid::crba(model, ws, q, wrong_square); });
  expect_rejected("crba", "M", [&] { dynid::crba(model, ws, q, wrong_rows); });

  expect_rejected("gravity", "ws", [&] { dynid::gravity(model, ws_other, q, out); });
  expect_rejected("gravity", "q", [&] { dynid::gravity(model, ws, short_vector, out); });
  expect_rejected("gravity", "g", [&] { dynid::gravity(model, ws, q, short_out); });

  expect_rejected("coriolis", "ws", [&] { dynid::coriolis(model, ws_other, q, qd, out); });
  expect_rejected("coriolis", "q", [&] { dynid::coriolis(model, ws, short_vector, qd, out); });
  expect_rejected("coriolis", "qd", [&] { dynid::coriolis(model, ws, q, long_vector, out); });
  expect_rejected("coriolis", "c", [&] { dynid::coriolis(model, ws, q, qd, long_out); });

  expect_rejected("coriolis_matrix", "ws",
                  [&] { dynid::coriolis_matrix(model, ws_other, q, qd, S); });
  expect_rejected("coriolis_matrix", "q",
                  [&] { dynid::coriolis_matrix(model, ws, short_vector, qd, S); });
  expect_rejected("coriolis_matrix", "qd",
                  [&] { dynid::coriolis_matrix(model, ws, q, short_vector, S); });
  expect_rejected("coriolis_matrix", "S",
                  [&] { dynid::coriolis_matrix(model, ws, q, qd, wrong_rows); });

  expect_rejected("friction", "qd", [&] { dynid::friction(model, short_vector, out); });
  expect_rejected("friction", "tau", [&] { dynid::friction(model, qd, long_out); });

  VectorX qdd_out(n);
  expect_rejected("forward_dynamics", "ws",
                  [&] { dynid::forward_dynamics(model, ws_other, q, qd, tau, qdd_out); });
  expect_rejected("forward_dynamics", "q",
                  [&] { dynid::forward_dynamics(model, ws, short_vector, qd, tau, qdd_out); });
  expect_rejected("forward_dynamics", "qd",
                  [&] { dynid::forward_dynamics(model, ws, q, long_vector, tau, qdd_out); });
  expect_rejected("forward_dynamics", "tau",
                  [&] { dynid::forward_dynamics(model, ws, q, qd, short_vector, qdd_out); });
  expect_rejected("forward_dynamics", "qdd",
                  [&] { dynid::forward_dynamics(model, ws, q, qd, tau, short_out); });

  expect_rejected("kinetic_energy", "ws", [&] { dynid::kinetic_energy(model, ws_other, q, qd); });
  expect_rejected("kinetic_energy", "q",
                  [&] { dynid::kinetic_energy(model, ws, short_vector, qd); });
  expect_rejected("kinetic_energy", "qd",
                  [&] { dynid::kinetic_energy(model, ws, q, long_vector); });
  expect_rejected("potential_energy", "ws", [&] { dynid::potential_energy(model, ws_other, q); });
  expect_rejected("potential_energy", "q",
                  [&] { dynid::potential_energy(model, ws, long_vector); });

  MatrixX T_wrong(3, 4), J_wrong(6, n + 1);
  expect_rejected("fkine", "ws", [&] { dynid::fkine(model, ws_other, q, T); });
  expect_rejected("fkine", "q", [&] { dynid::fkine(model, ws, short_vector, T); });
  expect_rejected("fkine", "T", [&] { dynid::fkine(model, ws, q, T_wrong); });
  expect_rejected("jacobian", "ws", [&] { dynid::jacobian(model, ws_other, q, J); });
  expect_rejected("jacobian", "q", [&] { dynid::jacobian(model, ws, long_vector, J); });
  expect_rejected("jacobian", "J", [&] { dynid::jacobian(model, ws, q, J_wrong); });

  RowMajorMatrixX Y_without_friction(n, dynid::regressor_columns(n, true, false));
  expect_rejected("regressor", "ws",
                  [&] { dynid::regressor(model, ws_other, q, qd, qdd, true, true, Y); });
  expect_rejected("regressor", "q",
                  [&] { dynid::regressor(model, ws, short_vector, qd, qdd, true, true, Y); });
  expect_rejected("regressor", "qd",
                  [&] { dynid::regressor(model, ws, q, short_vector, qdd, true, true, Y); });
  expect_rejected("regressor", "qdd",
                  [&] { dynid::regressor(model, ws, q, qd, long_vector, true, true, Y); });
  expect_rejected("regressor", "Y",
                  [&] { dynid::regressor(model, ws, q, qd, qdd, true, true, Y_without_friction); });
  expect_rejected("regressor", "Y",
                  [&] { dynid::regressor(model, ws, q, qd, qdd, false, false, Y); });
  RowMajorMatrixX Yg_wrong(n, 10 * n - 1), Ym_wrong(n * (n + 1) / 2, 10 * n);
  expect_rejected("gravity_regressor", "ws",
                  [&] { dynid::gravity_regressor(model, ws_other, q, Yg); });
  expect_rejected("gravity_regressor", "q",
                  [&] { dynid::gravity_regressor(model, ws, short_vector, Yg); });
  expect_rejected("gravity_regressor", "Yg",
                  [&] { dynid::gravity_regressor(model, ws, q, Yg_wrong); });
  expect_rejected("inertia_regressor", "ws",
                  [&] { dynid::inertia_regressor(model, ws_other, q, true, Ym); });
  expect_rejected("inertia_regressor", "q",
                  [&] { dynid::inertia_regressor(model, ws, long_vector, true, Ym); });
  expect_rejected("inertia_regressor", "Ym",
                  [&] { dynid::inertia_regressor(model, ws, q, true, Ym_wrong); });

  // The model's setters and the RLS name their arguments too (the function is the class's).
  dynid::Model editable = model;
  expect_rejected("Model", "Ia", [&] { editable.set_rotor_inertia(short_vector); }, false);
  expect_rejected("Model", "Fv", [&] { editable.set_viscous_friction(long_vector); }, false);
  expect_rejected("Model", "Fs", [&] { editable.set_coulomb_friction(short_vector); }, false);
  expect_rejected("Model", "params", [&] { editable.set_parameters(MatrixX::Zero(n, 9)); }, false);
  expect_rejected("Model", "i", [&] { editable.set_link(n, dynid::RigidBodyParameters()); }, false);
  expect_rejected("Model", "i", [&] { (void)editable.link_inconsistency(-1); }, false);
  expect_rejected("Model", "qlim", [&] { editable.set_joint_limits(MatrixX::Zero(n, 3)); }, false);
  MatrixX reversed(n, 2);
  reversed.col(0).setOnes();
  reversed.col(1).setZero();
  expect_rejected("Model", "qlim", [&] { editable.set_joint_limits(reversed); }, false);
  expect_rejected("Model", "joint_names", [&] { editable.set_joint_names({"a"}); }, false);
  std::vector<std::string> names(static_cast<std::size_t>(n), "a");  // n alike
  expect_rejected("Model", "joint_names", [&] { editable.set_joint_names(names); }, false);
  for (std::size_t i = 0; i < names.size(); ++i) names[i] = "j" + std::to_string(i);
  names.back() = "";  // one empty
  expect_rejected("Model", "joint_names", [&] { editable.set_joint_names(names); }, false);
  expect_rejected("Model", "gear_ratios", [&] { editable.set_gear_ratios(short_vector); }, false);
  VectorX zero_ratio = VectorX::Ones(n);
  zero_ratio[1] = 0.0;  // R = diag(gear_ratios) T would be singular
  expect_rejected("Model", "gear_ratios", [&] { editable.set_gear_ratios(zero_ratio); }, false);
  expect_rejected(
      "Model", "joint_offsets", [&] { editable.set_joint_offsets(long_vector); }, false);
  dynid::RecursiveLeastSquares rls(4);
  const MatrixX block = MatrixX::Ones(2, 4);
  expect_rejected(
      "RecursiveLeastSquares", "Y_k", [&] { rls.update(MatrixX::Ones(2, 5), VectorX::Ones(2)); },
      false);
  expect_rejected(
      "RecursiveLeastSquares", "tau_k", [&] { rls.update(block, VectorX::Ones(3)); }, false);
  expect_rejected(
      "RecursiveLeastSquares", "P",
      [&] {
        MatrixX P(4, 3);
        rls.covariance(P);
      },
      false);
  expect_rejected(
      "RecursiveLeastSquares", "theta0",
      [&] { rls.reset(VectorX::Zero(3), MatrixX::Identity(4, 4)); }, false);
  expect_rejected(
      "RecursiveLeastSquares", "P0", [&] { rls.reset(VectorX::Zero(4), MatrixX::Identity(3, 3)); },
      false);

  MatrixX Jdot(6, n), Jdot_wrong(6, n - 1), dtau_dq(n, n), dtau_dqd(n, n);
  expect_rejected("jacobian_dot", "ws", [&] { dynid::jacobian_dot(model, ws_other, q, qd, Jdot); });
  expect_rejected("jacobian_dot", "q",
                  [&] { dynid::jacobian_dot(model, ws, short_vector, qd, Jdot); });
  expect_rejected("jacobian_dot", "qd",
                  [&] { dynid::jacobian_dot(model, ws, q, long_vector, Jdot); });
  expect_rejected("jacobian_dot", "Jdot",
                  [&] { dynid::jacobian_dot(model, ws, q, qd, Jdot_wrong); });
  expect_rejected("rnea_derivatives", "ws",
                  [&] { dynid::rnea_derivatives(model, ws_other, q, qd, qdd, dtau_dq, dtau_dqd); });
  expect_rejected("rnea_derivatives", "q", [&] {
    dynid::rnea_derivatives(model, ws, long_vector, qd, qdd, dtau_dq, dtau_dqd);
  });
  expect_rejected("rnea_derivatives", "qd", [&] {
    dynid::rnea_derivatives(model, ws, q, short_vector, qdd, dtau_dq, dtau_dqd);
  });
  expect_rejected("rnea_derivatives", "qdd", [&] {
    dynid::rnea_derivatives(model, ws, q, qd, short_vector, dtau_dq, dtau_dqd);
  });
  expect_rejected("rnea_derivatives", "dtau_dq",
                  [&] { dynid::rnea_derivatives(model, ws, q, qd, qdd, wrong_rows, dtau_dqd); });
  expect_rejected("rnea_derivatives", "dtau_dqd",
                  [&] { dynid::rnea_derivatives(model, ws, q, qd, qdd, dtau_dq, wrong_square); });

  dynid::Simulator simulator(model, dynid::SimulationSettings{});
  expect_rejected("Simulator::acceleration", "q",
                  [&] { simulator.acceleration(short_vector, qd, tau, qdd_out); });
  expect_rejected("Simulator::acceleration", "qd",
                  [&] { simulator.acceleration(q, long_vector, tau, qdd_out); });
  expect_rejected("Simulator::acceleration", "tau",
                  [&] { simulator.acceleration(q, qd, short_vector, qdd_out); });
  expect_rejected("Simulator::acceleration", "qdd",
                  [&] { simulator.acceleration(q, qd, tau, short_out); });

  // ---- the right sizes work, and agree with independent routes ----
  dynid::rnea(model, ws, q, qd, qdd, tau);
  dynid::crba(model, ws, q, M);
  dynid::coriolis_matrix(model, ws, q, qd, S);
  VectorX g(n), c(n), f(n);
  dynid::gravity(model, ws, q, g);
  dynid::coriolis(model, ws, q, qd, c);
  dynid::friction(model, qd, f);
  expect_close("rnea = M qdd + S qd + g + friction",
               (M * qdd + S * qd + g + f - tau).cwiseAbs().maxCoeff());
  expect_close("coriolis = S qd", (S * qd - c).cwiseAbs().maxCoeff());
  dynid::forward_dynamics(model, ws, q, qd, tau, qdd_out);
  expect_close("forward_dynamics(rnea) = qdd", (qdd_out - qdd).cwiseAbs().maxCoeff());
  dynid::SimulationSettings sign_friction;
  sign_friction.coulomb_band = 0.0;  // the exact sign(qd) of rnea
  dynid::Simulator exact(model, sign_friction);
  exact.acceleration(q, qd, tau, qdd_out);
  expect_close("Simulator::acceleration(rnea) = qdd", (qdd_out - qdd).cwiseAbs().maxCoeff());
  VectorX pi(P);
  for (int i = 0; i < n; ++i) pi.segment(10 * i, 10) = model.parameters().row(i).transpose();
  pi.segment(10 * n, n) = model.rotor_inertia();
  pi.segment(11 * n, n) = model.viscous_friction();
  pi.segment(12 * n, n) = model.coulomb_friction();
  dynid::regressor(model, ws, q, qd, qdd, true, true, Y);
  expect_close("regressor pi = rnea", (Y * pi - tau).cwiseAbs().maxCoeff());
  dynid::gravity_regressor(model, ws, q, Yg);
  expect_close("gravity_regressor pi = g", (Yg * pi.head(10 * n) - g).cwiseAbs().maxCoeff());
  dynid::inertia_regressor(model, ws, q, true, Ym);
  const VectorX m_stack = Ym * pi.head(11 * n);
  double inertia_error = 0.0;
  for (int i = 0, row = 0; i < n; ++i)
    for (int k = 0; k <= i; ++k, ++row)
      inertia_error = std::max(inertia_error, std::abs(m_stack[row] - M(i, k)));
  expect_close("inertia_regressor pi = tril(M)", inertia_error);
  const double kinetic = dynid::kinetic_energy(model, ws, q, qd);
  expect_close("2 T = qd^T M qd", std::abs(2.0 * kinetic - qd.dot(M * qd)));
  expect_close("potential energy finite",
               std::isfinite(dynid::potential_energy(model, ws, q)) ? 0.0 : 1.0);
  dynid::fkine(model, ws, q, T);
  expect_close("fkine: homogeneous last row",
               (T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff());
  dynid::jacobian(model, ws, q, J);
  expect_close("jacobian: the prismatic joint has no angular column",
               J.col(1).tail<3>().cwiseAbs().maxCoeff());
  rls.update(block, VectorX::Ones(2));
  MatrixX P_out(4, 4);
  rls.covariance(P_out);
  expect_close("RLS covariance symmetric", (P_out - P_out.transpose()).cwiseAbs().maxCoeff(), 0.0);
  expect_close("RLS state finite", rls.is_finite() ? 0.0 : 1.0, 0.0);
  expect_close("model links consistent", model.link_inconsistency(0).empty() ? 0.0 : 1.0, 0.0);

  // sos_filter: its state must match the sections and the signal's columns, every a0 be 1; a
  // two-tap average y[t] = (x[t] + x[t-1]) / 2 from rest, and its state carried across blocks.
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Rows average(1, 6), signal(5, 2), state = Rows::Zero(1, 4), bad_state = Rows::Zero(1, 3);
  average << 0.5, 0.5, 0.0, 1.0, 0.0, 0.0;
  signal << 1, 10, 2, 20, 3, 30, 4, 40, 5, 50;
  Rows unnormalised = average;
  unnormalised(0, 3) = 2.0;
  expect_rejected("sos_filter", "state", [&] { dynid::sos_filter(average, signal, bad_state); });
  expect_rejected("sos_filter", "sections",
                  [&] { dynid::sos_filter(unnormalised, signal, state); });
  Rows first = signal.topRows(2), rest = signal.bottomRows(3);
  dynid::sos_filter(average, first, state);
  dynid::sos_filter(average, rest, state);
  Rows filtered(5, 2), expected(5, 2);
  filtered << first, rest;
  expected << 0.5, 5, 1.5, 15, 2.5, 25, 3.5, 35, 4.5, 45;
  expect_close("sos_filter: two-tap average across blocks",
               (filtered - expected).cwiseAbs().maxCoeff(), 0.0);

  std::printf("size checks: %d probes, %d failures\n", probes, failures);
  return failures == 0 ? 0 : 1;
}
