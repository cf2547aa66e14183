// The integration loop of the closed-loop simulation (notes, "Dynamic simulation": initial state,
// the model terms, a numerical integration method). The whole M(q) is factorised at each
// evaluation ("... an incorrect realization" inverts only its diagonal).
#include "dynid/simulator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/composite_rigid_body.hpp"
#include "dynid/detail/drive_terms.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/newton_euler.hpp"

namespace dynid {
namespace {

constexpr double kTwoPi = 6.283185307179586;

std::string num(double x) { return std::to_string(x); }

// The message is built only on failure, so that a run allocates nothing once constructed.
template <class Message>
void require(bool ok, Message message) {
  if (!ok) throw std::invalid_argument(message());
}

void check_rows(const RowMajorOut& block, Eigen::Index rows, int n, const char* name) {
  require(block.rows() == rows && block.cols() == n, [&] {
    return std::string(name) + ": expected an output block of " + std::to_string(rows) + " x " +
           std::to_string(n) + ", got " + std::to_string(block.rows()) + " x " +
           std::to_string(block.cols());
  });
}

}  // namespace

Simulator::Simulator(const Model& plant, const SimulationSettings& settings)
    : plant_(plant), settings_(settings), ws_(plant), rng_(settings.seed) {
  const SimulationSettings& s = settings;
  require(std::isfinite(s.dt) && s.dt > 0.0,
          [&] { return "dt: expected a positive control period, got " + std::to_string(s.dt); });
  require(s.substeps >= 1,
          [&] { return "substeps: expected >= 1, got " + std::to_string(s.substeps); });
  require(std::isfinite(s.coulomb_band) && s.coulomb_band >= 0.0,
          [&] { return "coulomb_band: expected a finite value >= 0, got " + num(s.coulomb_band); });
  require(std::isfinite(s.torque_noise) && s.torque_noise >= 0.0,
          [&] { return "torque_noise: expected a finite value >= 0, got " + num(s.torque_noise); });
  // Fewer than one count per revolution (per metre) makes a quantum larger than the motion: the
  // controller would see a constant position and fly blind (issue 22: 1e-300 was accepted).
  require(std::isfinite(s.encoder_counts) && (s.encoder_counts == 0.0 || s.encoder_counts >= 1.0),
          [&] {
            return "encoder_counts: expected 0 (no encoder) or at least 1 count per revolution "
                   "(per metre), got " +
                   num(s.encoder_counts);
          });
  resolution_[0] = s.encoder_counts > 0.0 ? kTwoPi / s.encoder_counts : 0.0;
  resolution_[1] = s.encoder_counts > 0.0 ? 1.0 / s.encoder_counts : 0.0;
  const int n = plant.n();
  for (VectorX* v : {&q_, &qd_, &tau_, &tau_applied_, &q_meas_, &q_meas_prev_, &qd_meas_, &a1_,
                     &a2_, &a3_, &a4_, &q_stage_, &qd_stage_, &v_sum_})
    v->setZero(n);
}

void Simulator::acceleration(const VectorIn& q, const VectorIn& qd, const VectorIn& tau,
                             VectorOut qdd) {
  const int n = plant_.n();
  const char* function = "Simulator::acceleration";  // the checks build no message per call
  detail::WorkspaceBuffers& ws = detail::checked_buffers(function, plant_, ws_);
  detail::check_size(function, "q", q.size(), n, "one per joint");
  detail::check_size(function, "qd", qd.size(), n, "one per joint");
  detail::check_size(function, "tau", tau.size(), n, "one per joint");
  detail::check_size(function, "qdd", qdd.size(), n, "one per joint");
  detail::update_joint_transforms(plant_, ws, q);
  // c(q, qd) + g(q) of the links (Newton-Euler with qdd = 0), then the drive terms.
  detail::newton_euler(plant_, ws, qd, ws.zeros, -plant_.gravity_base(), ws.bias);
  if (settings_.friction) {
    const double band = settings_.coulomb_band;
    detail::add_drive_friction(plant_, qd, ws.bias,
                               [band](double w) { return detail::coulomb_shape(w, band); });
  }
  detail::composite_rigid_body(plant_, ws, ws.M);
  detail::add_drive_inertia(plant_, ws.M);
  ws.cholesky.compute(ws.M);
  if (ws.cholesky.info() != Eigen::Success)
    throw std::domain_error(
        "simulate: the plant's mass matrix is not positive definite at this q (are its "
        "parameters physically consistent?)");
  qdd = tau - ws.bias;
  ws.cholesky.solveInPlace(qdd);
}

// One classical Runge-Kutta step of x = (q, qd) with the torque held; a1_ already holds
// qdd(q, qd) (the controller sample's acceleration or the previous step's evaluation). The stage
// velocities are v1 = qd, v2 = qd + h/2 a1, v3 = qd + h/2 a2, v4 = qd + h a3; v_sum_ collects
// v1 + 2 v2 + 2 v3 + v4 for the position update.
void Simulator::step_rk4(double h) {
  const double half = 0.5 * h;
  qd_stage_ = qd_ + half * a1_;  // v2
  q_stage_ = q_ + half * qd_;
  acceleration(q_stage_, qd_stage_, tau_applied_, a2_);
  v_sum_ = qd_ + 2.0 * qd_stage_;
  q_stage_ = q_ + half * qd_stage_;
  qd_stage_ = qd_ + half * a2_;  // v3
  acceleration(q_stage_, qd_stage_, tau_applied_, a3_);
  v_sum_ += 2.0 * qd_stage_;
  q_stage_ = q_ + h * qd_stage_;
  qd_stage_ = qd_ + h * a3_;  // v4
  acceleration(q_stage_, qd_stage_, tau_applied_, a4_);
  v_sum_ += qd_stage_;
  q_ += (h / 6.0) * v_sum_;
  qd_ += (h / 6.0) * (a1_ + 2.0 * a2_ + 2.0 * a3_ + a4_);
}

// Symplectic Euler: the velocity first, with the acceleration of the current state (a1_), then
// the position with the new velocity.
void Simulator::step_semi_implicit_euler(double h) {
  qd_ += h * a1_;
  q_ += h * qd_;
}

void Simulator::measure(int k) {
  if (settings_.encoder_counts == 0.0) {
    q_meas_ = q_;
    qd_meas_ = qd_;
    return;
  }
  for (int i = 0; i < plant_.n(); ++i) {
    const double step = resolution_[plant_.joint(i).revolute ? 0 : 1];
    q_meas_[i] = step * std::round(q_[i] / step);
  }
  // Velocity: backward difference of the quantised positions over the control period; at k = 0,
  // where no earlier sample exists, the controller starts from the known initial velocity.
  if (k == 0)
    qd_meas_ = qd_;
  else
    qd_meas_ = (q_meas_ - q_meas_prev_) / settings_.dt;
  q_meas_prev_ = q_meas_;
}

void Simulator::run(Controller& controller, const VectorIn& q0, const VectorIn& qd0, int periods,
                    SimulationOutput& out) {
  const int n = plant_.n();
  require(q0.size() == n, [&] {
    return "q0: expected " + std::to_string(n) + " values, got " + std::to_string(q0.size());
  });
  require(qd0.size() == n, [&] {
    return "qd0: expected " + std::to_string(n) + " values, got " + std::to_string(qd0.size());
  });
  require(periods >= 1, [&] { return "periods: expected >= 1, got " + std::to_string(periods); });
  const Eigen::Index rows = static_cast<Eigen::Index>(periods) + 1;
  check_rows(out.q, rows, n, "q");
  check_rows(out.qd, rows, n, "qd");
  check_rows(out.qdd, rows, n, "qdd");
  check_rows(out.tau, rows, n, "tau");
  const bool record_measured = out.q_measured.rows() > 0;
  if (record_measured) check_rows(out.q_measured, rows, n, "q_measured");

  q_ = q0;
  qd_ = qd0;
  rng_.seed(settings_.seed);
  normal_.reset();
  const double dt = settings_.dt;
  const double h = dt / settings_.substeps;
  for (int k = 0; k <= periods; ++k) {
    const double t = k * dt;
    measure(k);
    controller.command(k, t, q_meas_, qd_meas_, tau_);
    if (!tau_.allFinite())
      throw std::runtime_error(
          "controller: returned a non-finite torque at t = " + std::to_string(t) + " s");
    tau_applied_ = tau_;
    if (settings_.torque_noise > 0.0)
      for (int i = 0; i < n; ++i) tau_applied_[i] += settings_.torque_noise * normal_(rng_);
    acceleration(q_, qd_, tau_applied_, a1_);
    out.q.row(k) = q_.transpose();
    out.qd.row(k) = qd_.transpose();
    out.qdd.row(k) = a1_.transpose();
    out.tau.row(k) = tau_.transpose();
    if (record_measured) out.q_measured.row(k) = q_meas_.transpose();
    if (k == periods) break;
    for (int s = 0; s < settings_.substeps; ++s) {
      if (s > 0) acceleration(q_, qd_, tau_applied_, a1_);
      if (settings_.integrator == Integrator::RungeKutta4)
        step_rk4(h);
      else
        step_semi_implicit_euler(h);
    }
    if (!q_.allFinite() || !qd_.allFinite())
      throw std::runtime_error(
          "simulate: the state stopped being finite at t = " + std::to_string(t + dt) +
          " s; the integration step dt / substeps is too large for the gains or the friction "
          "band (coulomb_band)");
  }
}

}  // namespace dynid
