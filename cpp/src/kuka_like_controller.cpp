// The KUKA-like joint torque controller (Albu-Schaeffer, Ott, Hirzinger, IJRR 2007; the header
// and docs/elastic.md give the law). A command evaluates the controller's gravity once or twice
// (a few fixed-point steps for the motor-side static gravity) in its own Workspace: no heap.
#include "dynid/kuka_like_controller.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/gravity.hpp"

namespace dynid {
namespace {

using ConstRow = Eigen::Map<const VectorX>;

void check_size(Eigen::Index size, Eigen::Index n, const char* name) {
  detail::check_size("KukaLikeController", name, size, n, "one per joint");
}

void check_gain(const VectorX& v, Eigen::Index n, const char* name) {
  check_size(v.size(), n, name);
  if (!v.allFinite() || (v.array() < 0.0).any())
    throw std::invalid_argument(std::string(name) + ": expected finite gains >= 0");
}

// The fixed point qbar = theta - K^-1 g(qbar) is solved to this relative accuracy, in at most
// kMaxIterations steps (each one contracts by |K^-1 dg/dq| < 1, ~0.1 or less on an LWR).
constexpr double kTolerance = 1e-13;
constexpr int kMaxIterations = 100;

}  // namespace

KukaLikeController::KukaLikeController(const Model& model, const VectorIn& stiffness,
                                       const KukaLikeGains& gains, GravityCompensation gravity,
                                       const ReferenceTrajectory& reference, const double* tau_user)
    : model_(model),
      stiffness_(stiffness),
      gains_(gains),
      gravity_(gravity),
      reference_(reference),
      tau_user_(tau_user),
      ws_(model) {
  const int n = model.n();
  check_size(stiffness.size(), n, "stiffness");
  if (!stiffness.allFinite() || (stiffness.array() <= 0.0).any())
    throw std::invalid_argument("stiffness: expected finite values > 0");
  check_gain(gains.kp, n, "kp");
  check_gain(gains.kd, n, "kd");
  check_gain(gains.torque_gain, n, "torque_gain");
  check_gain(gains.torque_damping, n, "torque_damping");
  if (reference.n != n || reference.samples < 1 || reference.q == nullptr ||
      reference.qd == nullptr)
    throw std::invalid_argument("reference: expected q, qd with at least 1 sample of " +
                                std::to_string(n) + " joints, got " +
                                std::to_string(reference.samples) + " samples of " +
                                std::to_string(reference.n));
  for (VectorX* v : {&g_, &g_desired_, &q_bar_, &next_, &u_}) v->setZero(n);
}

const VectorX& KukaLikeController::static_link_position(const VectorIn& theta) {
  check_size(theta.size(), model_.n(), "theta");
  if (!warm_) q_bar_ = theta;
  warm_ = true;
  const double scale = 1.0 + theta.cwiseAbs().maxCoeff();
  for (int i = 0; i < kMaxIterations; ++i) {
    gravity(model_, ws_, q_bar_, g_);
    next_ = theta - g_.cwiseQuotient(stiffness_);
    const double step = (next_ - q_bar_).cwiseAbs().maxCoeff();
    q_bar_ = next_;
    if (step <= kTolerance * scale) return q_bar_;
  }
  warm_ = false;
  throw std::runtime_error(
      "KukaLikeController: the static link position K (theta - qbar) = g(qbar) did not converge; "
      "the stiffness must dominate the gravity gradient");
}

void KukaLikeController::command(int k, double, const VectorIn& q, const VectorIn& qd,
                                 const VectorIn& theta, const VectorIn& thetad,
                                 const VectorIn& tau_J, VectorOut tau) {
  const int n = model_.n();
  if (k < 0 || k >= reference_.samples)
    throw std::out_of_range("reference: sample " + std::to_string(k) + " requested, it has " +
                            std::to_string(reference_.samples));
  check_size(q.size(), n, "q");
  check_size(qd.size(), n, "qd");
  check_size(theta.size(), n, "theta");
  check_size(thetad.size(), n, "thetad");
  check_size(tau_J.size(), n, "tau_J");
  check_size(tau.size(), n, "tau");
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(k) * n;
  const ConstRow q_d(reference_.q + row, n), qd_d(reference_.qd + row, n);
  // Outer law: u = Kp (theta_d - theta) + Kd (qd_d - thetad) + g_c, theta_d = q_d + g_c / K_c.
  gravity(model_, ws_, q_d, g_desired_);
  u_ = gains_.kp.cwiseProduct(q_d + g_desired_.cwiseQuotient(stiffness_) - theta) +
       gains_.kd.cwiseProduct(qd_d - thetad);
  if (gravity_ == GravityCompensation::Desired) {
    u_ += g_desired_;
  } else {
    static_link_position(theta);
    gravity(model_, ws_, q_bar_, g_);
    u_ += g_;
  }
  if (tau_user_ != nullptr) u_ += ConstRow(tau_user_ + row, n);
  // Inner torque loop: tau = u + K_T (u - tau_J) - D_T K_c (thetad - qd).
  tau = u_ + gains_.torque_gain.cwiseProduct(u_ - tau_J) -
        gains_.torque_damping.cwiseProduct(stiffness_.cwiseProduct(thetad - qd));
}

}  // namespace dynid
