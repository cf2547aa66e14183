// Generalized-momentum observer (momentum_observer.hpp): one update costs a CRBA, the Christoffel
// Coriolis matrix, gravity and friction, all into buffers allocated by the constructor.
#include "dynid/momentum_observer.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dynid/coriolis_matrix.hpp"
#include "dynid/crba.hpp"
#include "dynid/friction.hpp"
#include "dynid/gravity.hpp"

namespace dynid {
namespace {

void require_size(const VectorIn& v, int n, const char* name) {
  if (v.size() != n)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(n) +
                                " values, got " + std::to_string(v.size()));
}

}  // namespace

MomentumObserver::MomentumObserver(const Model& model, const VectorIn& gain, double dt)
    : model_(model),
      ws_(model_),
      gain_(gain),
      dt_(dt),
      sigma_(VectorX::Zero(model.n())),
      beta_previous_(VectorX::Zero(model.n())),
      r_(VectorX::Zero(model.n())),
      M_(model.n(), model.n()),
      S_(model.n(), model.n()),
      g_(model.n()),
      friction_(model.n()),
      p_(model.n()),
      beta_(model.n()) {
  require_size(gain, model.n(), "gain");
  if (!gain.allFinite() || !(gain.minCoeff() > 0.0))
    throw std::invalid_argument("gain: expected finite values > 0 (1/s)");
  if (!std::isfinite(dt) || !(dt > 0.0))
    throw std::invalid_argument("dt: expected a finite sample period > 0 (s), got " +
                                std::to_string(dt));
}

MomentumObserver::MomentumObserver(const Model& model, double gain, double dt)
    : MomentumObserver(model, VectorX::Constant(model.n(), gain), dt) {}

void MomentumObserver::reset() {
  samples_ = 0;
  sigma_.setZero();
  beta_previous_.setZero();
  r_.setZero();
}

void MomentumObserver::update(const VectorIn& q, const VectorIn& qd, const VectorIn& tau,
                              VectorOut r) {
  const int n = model_.n();
  require_size(q, n, "q");
  require_size(qd, n, "qd");
  require_size(tau, n, "tau");
  require_size(r, n, "r");
  crba(model_, ws_, q, M_);
  coriolis_matrix(model_, ws_, q, qd, S_);
  gravity(model_, ws_, q, g_);
  friction(model_, qd, friction_);
  p_.noalias() = M_ * qd;
  beta_.noalias() = S_.transpose() * qd;
  beta_ += tau - g_ - friction_;
  if (samples_ == 0) {
    sigma_ = p_;  // p(0)
    r_.setZero();
  } else {
    const double h = 0.5 * dt_;
    for (int i = 0; i < n; ++i) {
      const double known = sigma_[i] + h * (beta_previous_[i] + beta_[i] + r_[i]);
      const double r_new = gain_[i] * (p_[i] - known) / (1.0 + gain_[i] * h);
      sigma_[i] = known + h * r_new;
      r_[i] = r_new;
    }
  }
  beta_previous_ = beta_;
  ++samples_;
  r = r_;
}

}  // namespace dynid
