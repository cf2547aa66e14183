// Collision detection by the generalized-momentum residual (De Luca & Mattone, ICRA 2005; notes,
// "Uses of the dynamic model"; paper, conclusion):
//   r(t) = K_O ( p(t) - p(0) - int_0^t (tau + S^T(q, qd) qd - g(q) - F(qd) + r) ds ),  p = M(q) qd,
// with S the Christoffel Coriolis matrix (M' = S + S^T) and F the joint friction. Since
// p' = tau + S^T qd - g - F + tau_ext, the residual obeys r' = K_O (tau_ext - r): each joint's r
// is tau_ext seen through a first-order filter of time constant 1 / K_O,i, and zero without
// contact.
//
// Discretised with the trapezoidal rule, the r inside the integral taken implicitly (Tustin):
//   sigma_k = sigma_{k-1} + dt/2 (beta_{k-1} + beta_k + r_{k-1} + r_k),  r_k = K (p_k - sigma_k),
//   beta = tau + S^T qd - g - F, solved for r_k in closed form (K diagonal); stable for any K dt
// and second-order accurate in dt. sigma_0 = p_0, r_0 = 0.
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

class MomentumObserver {
 public:
  // gain: K_O, one value per joint (> 0, 1/s); dt: the sample period (> 0, s). The model is
  // copied: later changes to the caller's model do not reach the observer. Throws
  // std::invalid_argument naming gain or dt.
  MomentumObserver(const Model& model, const VectorIn& gain, double dt);
  MomentumObserver(const Model& model, double gain, double dt);

  // One sample of the measured (q, qd, tau): writes r (n). The first sample after construction
  // or reset() fixes p(0) and gives r = 0. No heap allocation.
  void update(const VectorIn& q, const VectorIn& qd, const VectorIn& tau, VectorOut r);
  // Forget the history: the next update starts a new integral.
  void reset();

  const Model& model() const { return model_; }
  const VectorX& gain() const { return gain_; }
  double dt() const { return dt_; }
  const VectorX& residual() const { return r_; }
  long samples() const { return samples_; }

 private:
  Model model_;
  Workspace ws_;
  VectorX gain_;
  double dt_;
  long samples_ = 0;
  // State: the integral sigma, the previous beta and r. Scratch: M, S, g, friction, p, beta.
  VectorX sigma_, beta_previous_, r_;
  MatrixX M_, S_;
  VectorX g_, friction_, p_, beta_;
};

}  // namespace dynid
