#include "dynid/controllers.hpp"

#include <stdexcept>
#include <string>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/gravity.hpp"
#include "dynid/rnea.hpp"

namespace dynid {
namespace {

using ConstRow = Eigen::Map<const VectorX>;

void check_size(Eigen::Index size, Eigen::Index n, const char* name) {
  detail::check_size("controller", name, size, n, "one per joint");
}

void check_reference(const ReferenceTrajectory& r, int n) {
  if (r.n != n || r.samples < 1 || r.q == nullptr || r.qd == nullptr || r.qdd == nullptr)
    throw std::invalid_argument("reference: expected q, qd, qdd with at least 1 sample of " +
                                std::to_string(n) + " joints, got " + std::to_string(r.samples) +
                                " samples of " + std::to_string(r.n));
}

void check_model(const Model& model, Eigen::Index n) {
  if (model.n() != n)
    throw std::invalid_argument("model: expected a controller model of " + std::to_string(n) +
                                " joints, got " + std::to_string(model.n()));
}

}  // namespace

PDController::PDController(const VectorIn& kp, const VectorIn& kd,
                           const ReferenceTrajectory& reference)
    : kp_(kp), kd_(kd), e_(kp.size()), ed_(kp.size()), reference_(reference) {
  check_size(kd.size(), kp.size(), "kd");
  check_reference(reference, static_cast<int>(kp.size()));
}

void PDController::errors(int k, const VectorIn& q, const VectorIn& qd, Eigen::Index tau_size) {
  const int n = reference_.n;
  if (k < 0 || k >= reference_.samples)
    throw std::out_of_range("reference: sample " + std::to_string(k) + " requested, it has " +
                            std::to_string(reference_.samples));
  check_size(q.size(), n, "q");
  check_size(qd.size(), n, "qd");
  check_size(tau_size, n, "tau");
  e_ = ConstRow(reference_.q + static_cast<std::ptrdiff_t>(k) * n, n) - q;
  ed_ = ConstRow(reference_.qd + static_cast<std::ptrdiff_t>(k) * n, n) - qd;
}

void PDController::command(int k, double, const VectorIn& q, const VectorIn& qd, VectorOut tau) {
  errors(k, q, qd, tau.size());
  tau = kp_.cwiseProduct(e_) + kd_.cwiseProduct(ed_);
}

PDGravityController::PDGravityController(const Model& model, const VectorIn& kp, const VectorIn& kd,
                                         const ReferenceTrajectory& reference)
    : PDController(kp, kd, reference), model_(model), ws_(model), g_(kp.size()) {
  check_model(model, kp.size());
}

void PDGravityController::command(int k, double, const VectorIn& q, const VectorIn& qd,
                                  VectorOut tau) {
  errors(k, q, qd, tau.size());
  gravity(model_, ws_, q, g_);
  tau = kp_.cwiseProduct(e_) + kd_.cwiseProduct(ed_) + g_;
}

ComputedTorqueController::ComputedTorqueController(const Model& model, const VectorIn& kp,
                                                   const VectorIn& kd,
                                                   const ReferenceTrajectory& reference)
    : PDController(kp, kd, reference), model_(model), ws_(model), v_(kp.size()) {
  check_model(model, kp.size());
}

void ComputedTorqueController::command(int k, double, const VectorIn& q, const VectorIn& qd,
                                       VectorOut tau) {
  errors(k, q, qd, tau.size());
  const int n = reference_.n;
  // The outer loop's acceleration command, then inverse dynamics of the model at (q, qd, v).
  v_ = ConstRow(reference_.qdd + static_cast<std::ptrdiff_t>(k) * n, n) + kd_.cwiseProduct(ed_) +
       kp_.cwiseProduct(e_);
  rnea(model_, ws_, q, qd, v_, tau);
}

}  // namespace dynid
