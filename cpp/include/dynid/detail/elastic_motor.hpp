// Internal (dynid::detail, not API): the motor equation of elastic joint i (paper eq. (2); public
// calls in dynid/elastic_motor.hpp), per joint and without checks, for the elastic simulator's
// rate and the public batch calls. The friction is the drives' law (drive_terms.hpp).
#pragma once

#include "dynid/detail/drive_terms.hpp"
#include "dynid/elastic_motor.hpp"

namespace dynid::detail {

// tau_F,i = Fv_m,i w + Fs_m,i s(w).
inline double motor_friction(const ElasticDrives& d, int i, double w, double band) {
  return friction_law(d.motor_viscous[i], d.motor_coulomb[i], w, coulomb_shape(w, band));
}

// thetadd_i = (tau_i - tau_J,i - tau_F,i) / B_i; the viscous and Coulomb parts are subtracted one
// after the other, the rounding of the simulator since its first version.
inline double motor_acceleration(const ElasticDrives& d, int i, double w, double tau, double tau_J,
                                 double band) {
  const double viscous = friction_law(d.motor_viscous[i], 0.0, w, 0.0);
  const double coulomb = friction_law(0.0, d.motor_coulomb[i], w, coulomb_shape(w, band));
  return (tau - tau_J - viscous - coulomb) / d.motor_inertia[i];
}

// tau_i = B_i thetadd_i + tau_J,i + tau_F,i (term by term, as dynid.ElasticRobot always summed).
inline double motor_torque(const ElasticDrives& d, int i, double w, double thetadd, double tau_J,
                           double band) {
  const double viscous = friction_law(d.motor_viscous[i], 0.0, w, 0.0);
  const double coulomb = friction_law(0.0, d.motor_coulomb[i], w, coulomb_shape(w, band));
  return d.motor_inertia[i] * thetadd + tau_J + viscous + coulomb;
}

}  // namespace dynid::detail
