// The motor equation of elastic joints (paper eq. (2), notes p. 16): the checked public calls of
// detail/elastic_motor.hpp, one joint after the other.
#include "dynid/elastic_motor.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/elastic_motor.hpp"

namespace dynid {
namespace {

void check_drive(const VectorX& v, int n, bool positive, const char* name) {
  if (v.size() != n)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(n) +
                                " values, got " + std::to_string(v.size()));
  if (!(v.allFinite() && (positive ? (v.array() > 0.0).all() : (v.array() >= 0.0).all())))
    throw std::invalid_argument(std::string(name) + (positive ? ": expected finite values > 0"
                                                              : ": expected finite values >= 0"));
}

// The drives, the band and one vector per joint, for the call `function`.
int checked_joints(const ElasticDrives& drives, double band, const char* function,
                   std::initializer_list<std::pair<const char*, Eigen::Index>> vectors) {
  const int n = static_cast<int>(drives.stiffness.size());
  check_elastic_drives(drives, n);
  if (!(std::isfinite(band) && band >= 0.0))
    throw std::invalid_argument("coulomb_band: expected a finite value >= 0, got " +
                                std::to_string(band));
  for (const auto& [name, size] : vectors)
    detail::check_size(function, name, size, n, "one per joint");
  return n;
}

}  // namespace

void check_elastic_drives(const ElasticDrives& drives, int n) {
  check_drive(drives.stiffness, n, true, "stiffness");
  check_drive(drives.motor_inertia, n, true, "motor_inertia");
  check_drive(drives.motor_viscous, n, false, "motor_viscous");
  check_drive(drives.motor_coulomb, n, false, "motor_coulomb");
}

void motor_friction(const ElasticDrives& drives, const VectorIn& thetad, double coulomb_band,
                    VectorOut tau_F) {
  const int n = checked_joints(drives, coulomb_band, __func__,
                               {{"thetad", thetad.size()}, {"tau_F", tau_F.size()}});
  for (int i = 0; i < n; ++i) tau_F[i] = detail::motor_friction(drives, i, thetad[i], coulomb_band);
}

void motor_acceleration(const ElasticDrives& drives, const VectorIn& thetad, const VectorIn& tau,
                        const VectorIn& tau_J, double coulomb_band, VectorOut thetadd) {
  const int n = checked_joints(drives, coulomb_band, __func__,
                               {{"thetad", thetad.size()},
                                {"tau", tau.size()},
                                {"tau_J", tau_J.size()},
                                {"thetadd", thetadd.size()}});
  for (int i = 0; i < n; ++i)
    thetadd[i] = detail::motor_acceleration(drives, i, thetad[i], tau[i], tau_J[i], coulomb_band);
}

void motor_torque(const ElasticDrives& drives, const VectorIn& thetad, const VectorIn& thetadd,
                  const VectorIn& tau_J, double coulomb_band, VectorOut tau) {
  const int n = checked_joints(drives, coulomb_band, __func__,
                               {{"thetad", thetad.size()},
                                {"thetadd", thetadd.size()},
                                {"tau_J", tau_J.size()},
                                {"tau", tau.size()}});
  for (int i = 0; i < n; ++i)
    tau[i] = detail::motor_torque(drives, i, thetad[i], thetadd[i], tau_J[i], coulomb_band);
}

}  // namespace dynid
