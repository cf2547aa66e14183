// The motor equation of an elastic joint (Spong's reduced model, paper eqs. (2)-(3), notes p. 16),
// one joint per entry:
//   B thetadd + K (theta - q) + tau_F(thetad) = tau,   tau_F = Fv_m thetad + Fs_m s(thetad),
// with s(x) = tanh(x / coulomb_band), or sign(x) (sign(0) = 0) for coulomb_band = 0. Its one
// home: the elastic simulator (elastic_simulator.cpp) and dynid.ElasticRobot call these.
#pragma once

#include "dynid/types.hpp"

namespace dynid {

// Motor side of the drives, one entry per joint: stiffness K > 0, motor inertia B > 0, motor
// viscous Fv_m >= 0 and Coulomb Fs_m >= 0 friction.
struct ElasticDrives {
  VectorX stiffness, motor_inertia, motor_viscous, motor_coulomb;
};

// std::invalid_argument naming the drive (stiffness, motor_inertia, ...) unless each has n finite
// values in its range.
void check_elastic_drives(const ElasticDrives& drives, int n);

// tau_F = Fv_m thetad + Fs_m s(thetad), the motor-side friction.
void motor_friction(const ElasticDrives& drives, const VectorIn& thetad, double coulomb_band,
                    VectorOut tau_F);

// thetadd = B^-1 (tau - tau_J - tau_F(thetad)): the motor equation solved for the acceleration,
// tau_J = K (theta - q) the elastic torque (eq. (3)).
void motor_acceleration(const ElasticDrives& drives, const VectorIn& thetad, const VectorIn& tau,
                        const VectorIn& tau_J, double coulomb_band, VectorOut thetadd);

// tau = B thetadd + tau_J + tau_F(thetad): the motor equation solved for the motor torque.
void motor_torque(const ElasticDrives& drives, const VectorIn& thetad, const VectorIn& thetadd,
                  const VectorIn& tau_J, double coulomb_band, VectorOut tau);

// All three check the drives (check_elastic_drives), every vector's size (n = the drives' size;
// std::invalid_argument naming it) and coulomb_band (finite, >= 0).

}  // namespace dynid
