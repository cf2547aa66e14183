// The integration loop of the elastic-joint simulation (notes p. 16 and "Dynamic simulation";
// paper eqs. (1)-(3)): classical RK4 on x = (q, theta, qd, thetad) with the torque held.
#include "dynid/elastic_simulator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/composite_rigid_body.hpp"
#include "dynid/detail/elastic_motor.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/newton_euler.hpp"
#include "dynid/gravity.hpp"

namespace dynid {
namespace {

template <class Message>
void require(bool ok, Message message) {
  if (!ok) throw std::invalid_argument(message());
}

void check_size(const VectorIn& v, int n, const char* name) {
  require(v.size() == n, [&] {
    return std::string(name) + ": expected " + std::to_string(n) + " values, got " +
           std::to_string(v.size());
  });
}

void check_block(const RowMajorOut& block, Eigen::Index rows, int n, const char* name) {
  require(block.rows() == rows && block.cols() == n, [&] {
    return std::string(name) + ": expected an output block of " + std::to_string(rows) + " x " +
           std::to_string(n) + ", got " + std::to_string(block.rows()) + " x " +
           std::to_string(block.cols());
  });
}

}  // namespace

MotorPDController::MotorPDController(const Model& links, const ElasticDrives& drives,
                                     const VectorIn& kp, const VectorIn& kd, const VectorIn& q_d)
    : kp_(kp), kd_(kd), theta_d_(q_d.size()), gravity_(q_d.size()) {
  const int n = links.n();
  check_size(kp, n, "kp");
  check_size(kd, n, "kd");
  check_size(q_d, n, "q_d");
  Workspace ws(links);
  gravity(links, ws, q_d, gravity_);
  theta_d_ = q_d + gravity_.cwiseQuotient(drives.stiffness);
}

void MotorPDController::command(int, double, const VectorIn&, const VectorIn&,
                                const VectorIn& theta, const VectorIn& thetad, const VectorIn&,
                                VectorOut tau) {
  tau = kp_.cwiseProduct(theta_d_ - theta) - kd_.cwiseProduct(thetad) + gravity_;
}

ElasticSimulator::ElasticSimulator(const Model& links, const ElasticDrives& drives, double dt,
                                   int substeps, double coulomb_band)
    : links_(links),
      drives_(drives),
      dt_(dt),
      coulomb_band_(coulomb_band),
      substeps_(substeps),
      workspace_(links) {
  const int n = links.n();
  check_elastic_drives(drives, n);
  require(std::isfinite(dt) && dt > 0.0,
          [&] { return "dt: expected a positive control period, got " + std::to_string(dt); });
  require(substeps >= 1,
          [&] { return "substeps: expected >= 1, got " + std::to_string(substeps); });
  require(std::isfinite(coulomb_band) && coulomb_band >= 0.0, [&] {
    return "coulomb_band: expected a finite value >= 0, got " + std::to_string(coulomb_band);
  });
  for (VectorX* v : {&x_, &k1_, &k2_, &k3_, &k4_, &stage_}) v->setZero(4 * n);
  tau_.setZero(n);
  tau_J_.setZero(n);
}

void ElasticSimulator::rate(const VectorIn& x, const VectorIn& tau, VectorOut xd) {
  const int n = links_.n();
  const char* function = "ElasticSimulator::rate";  // the checks build no message per call
  detail::WorkspaceBuffers& ws = detail::checked_buffers(function, links_, workspace_);
  detail::check_size(function, "x", x.size(), 4 * n, "(q, theta, qd, thetad)");
  detail::check_size(function, "tau", tau.size(), n, "one per joint");
  detail::check_size(function, "xd", xd.size(), 4 * n, "(q, theta, qd, thetad)");
  const auto q = x.segment(0, n), theta = x.segment(n, n);
  const auto qd = x.segment(2 * n, n), thetad = x.segment(3 * n, n);
  xd.segment(0, n) = qd;
  xd.segment(n, n) = thetad;
  // Link equation (paper eq. (1)): M qdd = tau_J - c - g, links only (no Ia, Fv, Fs).
  detail::update_joint_transforms(links_, ws, q);
  detail::newton_euler(links_, ws, qd, ws.zeros, -links_.gravity_base(), ws.bias);
  detail::composite_rigid_body(links_, ws, ws.M);
  ws.cholesky.compute(ws.M);
  if (ws.cholesky.info() != Eigen::Success)
    throw std::domain_error("simulate: the links' mass matrix is not positive definite at this q");
  auto qdd = xd.segment(2 * n, n);
  auto thetadd = xd.segment(3 * n, n);
  for (int i = 0; i < n; ++i) {
    const double tau_J = drives_.stiffness[i] * (theta[i] - q[i]);
    qdd[i] = tau_J - ws.bias[i];
    // Motor equation (paper eq. (2)): B thetadd = tau - tau_J - tau_F (detail/elastic_motor.hpp).
    thetadd[i] = detail::motor_acceleration(drives_, i, thetad[i], tau[i], tau_J, coulomb_band_);
  }
  ws.cholesky.solveInPlace(qdd);
}

void ElasticSimulator::run(ElasticController& controller, const VectorIn& q0, const VectorIn& qd0,
                           const VectorIn& theta0, const VectorIn& thetad0, int periods,
                           ElasticSimulationOutput& out) {
  const int n = links_.n();
  check_size(q0, n, "q0");
  check_size(qd0, n, "qd0");
  check_size(theta0, n, "theta0");
  check_size(thetad0, n, "thetad0");
  require(periods >= 1, [&] { return "periods: expected >= 1, got " + std::to_string(periods); });
  const Eigen::Index rows = static_cast<Eigen::Index>(periods) + 1;
  check_block(out.q, rows, n, "q");
  check_block(out.qd, rows, n, "qd");
  check_block(out.theta, rows, n, "theta");
  check_block(out.thetad, rows, n, "thetad");
  check_block(out.tau, rows, n, "tau");
  check_block(out.tau_J, rows, n, "tau_J");

  x_ << q0, theta0, qd0, thetad0;
  const double h = dt_ / substeps_;
  for (int k = 0; k <= periods; ++k) {
    const double t = k * dt_;
    const auto q = x_.segment(0, n), theta = x_.segment(n, n);
    const auto qd = x_.segment(2 * n, n), thetad = x_.segment(3 * n, n);
    tau_J_ = drives_.stiffness.cwiseProduct(theta - q);
    controller.command(k, t, q, qd, theta, thetad, tau_J_, tau_);
    if (!tau_.allFinite())
      throw std::runtime_error(
          "controller: returned a non-finite torque at t = " + std::to_string(t) + " s");
    out.q.row(k) = q.transpose();
    out.qd.row(k) = qd.transpose();
    out.theta.row(k) = theta.transpose();
    out.thetad.row(k) = thetad.transpose();
    out.tau.row(k) = tau_.transpose();
    out.tau_J.row(k) = tau_J_.transpose();
    if (k == periods) break;
    for (int s = 0; s < substeps_; ++s) {  // classical Runge-Kutta 4, torque held
      rate(x_, tau_, k1_);
      stage_ = x_ + (0.5 * h) * k1_;
      rate(stage_, tau_, k2_);
      stage_ = x_ + (0.5 * h) * k2_;
      rate(stage_, tau_, k3_);
      stage_ = x_ + h * k3_;
      rate(stage_, tau_, k4_);
      x_ += (h / 6.0) * (k1_ + 2.0 * k2_ + 2.0 * k3_ + k4_);
    }
    if (!x_.allFinite())
      throw std::runtime_error(
          "simulate: the state stopped being finite at t = " + std::to_string(t + dt_) +
          " s; the step dt / substeps is too large for the stiffness "
          "(h must resolve sqrt(K / B) and sqrt(K / M))");
  }
}

}  // namespace dynid
