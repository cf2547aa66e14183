// Internal (dynid::detail, not API): the drive terms of docs/conventions.md,
// "Drive terms and the torque model" (rotor inertia, viscous and Coulomb friction) in one place,
// for every algorithm that adds them (rnea, crba, forward dynamics, energy, friction, the
// derivatives, the simulator, the regressors), and the friction law itself (friction_law,
// coulomb_shape), which the elastic joints' motor equation (detail/elastic_motor.hpp) uses too. The
// SIMD lane kernels (cpp/src/batch/) keep their own per-lane copy: they may share no inline
// function with the baseline code (batch_model.hpp).
//
// Transmission coupling (notes p. 11-13): the motors turn at theta_dot = T qd (after the gears),
// so the rotor kinetic energy 1/2 theta_dot^T diag(Ia) theta_dot adds T^T diag(Ia) T to M(q)
// (constant T: no Coriolis term) and the motor friction tau_F,m = Fv . theta_dot +
// Fs . sign(theta_dot) reaches the joints by virtual work as T^T tau_F,m. With T = I
// (Model::transmission_is_identity) every helper runs the per-joint arithmetic of the decoupled
// model, operation for operation as before T existed, so its results are unchanged to the bit.
// Nothing here allocates.
#pragma once

#include <cmath>

#include "dynid/model.hpp"

namespace dynid::detail {

// sign(0) = 0 (notes, "Adding dynamic terms").
inline double sign(double x) { return (x > 0.0) - (x < 0.0); }

// The Coulomb term's shape s(w): sign(w) for band = 0 (docs/conventions.md), else tanh(w / band),
// the simulators' smoothing of the jump at w = 0 (an explicit integrator chatters on the exact
// sign).
inline double coulomb_shape(double w, double band) {
  return band > 0.0 ? std::tanh(w / band) : sign(w);
}

// The friction law of one drive (notes, "Adding dynamic terms"; paper eq. (2) for the motor side
// of an elastic joint): Fv w + Fs s, with s = sign(w) or coulomb_shape(w, band).
inline double friction_law(double Fv, double Fs, double w, double s) { return Fv * w + Fs * s; }

// The asymmetric law of one joint (python/dynid/friction_models.py; FloBaRoID's asymmetric viscous
// friction): Fv+ max(w, 0) + Fv- min(w, 0) + Fs+ [w > 0] - Fs- [w < 0], as its regressor entries
// {max(w, 0), min(w, 0), [w > 0], -[w < 0]}; with `offset` the Coulomb pair is one symmetric
// entry sign(w) (the offset carries the asymmetry). Writes 4 entries, or 3 with `offset`.
inline void asymmetric_friction_entries(double w, bool offset, double* entries) {
  entries[0] = w > 0.0 ? w : 0.0;
  entries[1] = w < 0.0 ? w : 0.0;
  if (offset) {
    entries[2] = sign(w);
  } else {
    entries[2] = w > 0.0 ? 1.0 : 0.0;
    entries[3] = w < 0.0 ? -1.0 : 0.0;
  }
}

// Decoupled joint i: Fv_i qd + Fs_i sign(qd).
inline double friction_torque(const Model& model, int i, double qd) {
  return friction_law(model.viscous_friction()[i], model.coulomb_friction()[i], qd, sign(qd));
}

// Decoupled joint i: Ia_i qdd + Fv_i qd + Fs_i sign(qd), all its drive terms.
inline double drive_torque(const Model& model, int i, double qd, double qdd) {
  return model.rotor_inertia()[i] * qdd + friction_torque(model, i, qd);
}

// Decoupled joint i: Ia_i acc + Fv_i vel, the drive terms without Coulomb (their time
// derivatives: Coulomb is flat away from zero velocity).
inline double drive_linear_torque(const Model& model, int i, double vel, double acc) {
  return model.rotor_inertia()[i] * acc + model.viscous_friction()[i] * vel;
}

// Decoupled joint i: 1/2 Ia_i qd^2, its rotor's kinetic energy.
inline double rotor_energy(const Model& model, int i, double qd) {
  return 0.5 * model.rotor_inertia()[i] * qd * qd;
}

// Motor k's share of a joint-space vector: (T v)_k (theta_dot_k for v = qd).
template <class V>
inline double motor_value(const Model& model, int k, const V& v) {
  const MatrixX& T = model.transmission();
  double s = 0.0;
  for (int j = 0; j < model.n(); ++j) s += T(k, j) * v[j];
  return s;
}

// tau += T^T e_k f: a torque f of motor k seen at the joints (virtual work).
template <class Tau>
inline void add_motor_torque(const Model& model, int k, double f, Tau& tau) {
  const MatrixX& T = model.transmission();
  for (int j = 0; j < model.n(); ++j) tau[j] += T(k, j) * f;
}

// tau += T^T (Fv . w + Fs . coulomb(w)), w = T qd. `coulomb` is sign, or the simulator's
// smoothing.
template <class Qd, class Tau, class Coulomb>
inline void add_drive_friction(const Model& model, const Qd& qd, Tau& tau, Coulomb coulomb) {
  const VectorX& Fv = model.viscous_friction();
  const VectorX& Fs = model.coulomb_friction();
  if (model.transmission_is_identity()) {
    for (int i = 0; i < model.n(); ++i) tau[i] += friction_law(Fv[i], Fs[i], qd[i], coulomb(qd[i]));
    return;
  }
  for (int k = 0; k < model.n(); ++k) {
    const double w = motor_value(model, k, qd);
    add_motor_torque(model, k, friction_law(Fv[k], Fs[k], w, coulomb(w)), tau);
  }
}

// The same friction split by term: viscous += T^T (Fv . w), coulomb += T^T (Fs . s(w)), w = T qd,
// s = coulomb_shape(., band) (what scales with the speed and what does not: time scaling).
template <class Qd, class Out>
inline void add_drive_friction_terms(const Model& model, const Qd& qd, double band, Out& viscous,
                                     Out& coulomb) {
  const VectorX& Fv = model.viscous_friction();
  const VectorX& Fs = model.coulomb_friction();
  if (model.transmission_is_identity()) {
    for (int i = 0; i < model.n(); ++i) {
      viscous[i] += friction_law(Fv[i], 0.0, qd[i], 0.0);
      coulomb[i] += friction_law(0.0, Fs[i], qd[i], coulomb_shape(qd[i], band));
    }
    return;
  }
  for (int k = 0; k < model.n(); ++k) {
    const double w = motor_value(model, k, qd);
    add_motor_torque(model, k, friction_law(Fv[k], 0.0, w, 0.0), viscous);
    add_motor_torque(model, k, friction_law(0.0, Fs[k], w, coulomb_shape(w, band)), coulomb);
  }
}

template <class Qd, class Tau>
inline void add_drive_friction(const Model& model, const Qd& qd, Tau& tau) {
  add_drive_friction(model, qd, tau, [](double x) { return sign(x); });
}

// tau += T^T (Ia . T qdd + Fv . T qd + Fs . sign(T qd)): all drive terms of the torque.
template <class Qd, class Qdd, class Tau>
inline void add_drive_torque(const Model& model, const Qd& qd, const Qdd& qdd, Tau& tau) {
  const VectorX& Ia = model.rotor_inertia();
  if (model.transmission_is_identity()) {
    for (int i = 0; i < model.n(); ++i) tau[i] += drive_torque(model, i, qd[i], qdd[i]);
    return;
  }
  const VectorX& Fv = model.viscous_friction();
  const VectorX& Fs = model.coulomb_friction();
  for (int k = 0; k < model.n(); ++k) {
    const double a = motor_value(model, k, qdd), w = motor_value(model, k, qd);
    add_motor_torque(model, k, Ia[k] * a + friction_law(Fv[k], Fs[k], w, sign(w)), tau);
  }
}

// out += T^T (Ia . T acc + Fv . T vel) = drive_inertia acc + drive_damping vel: the drive terms
// without Coulomb (their time derivatives, Coulomb being flat away from zero velocity).
template <class Vel, class Acc, class Out>
inline void add_drive_linear(const Model& model, const Vel& vel, const Acc& acc, Out& out) {
  const VectorX& Ia = model.rotor_inertia();
  const VectorX& Fv = model.viscous_friction();
  if (model.transmission_is_identity()) {
    for (int i = 0; i < model.n(); ++i) out[i] += drive_linear_torque(model, i, vel[i], acc[i]);
    return;
  }
  for (int k = 0; k < model.n(); ++k)
    add_motor_torque(model, k,
                     Ia[k] * motor_value(model, k, acc) + Fv[k] * motor_value(model, k, vel), out);
}

// M += T^T diag(Ia) T: the rotors' part of the mass matrix.
template <class Matrix>
inline void add_drive_inertia(const Model& model, Matrix& M) {
  if (model.transmission_is_identity())
    M.diagonal() += model.rotor_inertia();
  else
    M += model.drive_inertia();
}

// D += T^T diag(Fv) T: d(friction)/d(qd) away from zero motor velocity.
template <class Matrix>
inline void add_drive_damping(const Model& model, Matrix& D) {
  if (model.transmission_is_identity())
    D.diagonal() += model.viscous_friction();
  else
    D += model.drive_damping();
}

// 1/2 (T qd)^T diag(Ia) (T qd): the rotors' kinetic energy.
template <class Qd>
inline double rotor_kinetic_energy(const Model& model, const Qd& qd) {
  double E = 0.0;
  for (int k = 0; k < model.n(); ++k) {
    const double w = model.transmission_is_identity() ? qd[k] : motor_value(model, k, qd);
    E += rotor_energy(model, k, w);
  }
  return E;
}

}  // namespace dynid::detail
