// Joint friction (notes, "Adding dynamic terms"; docs/conventions.md,
// "Drive terms and the torque model"): the public calls of the law in detail/drive_terms.hpp.
#include "dynid/friction.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/drive_terms.hpp"

namespace dynid {
namespace {

void check_band(double coulomb_band, const char* function) {
  if (!(std::isfinite(coulomb_band) && coulomb_band >= 0.0))
    throw std::invalid_argument("coulomb_band: expected a finite value >= 0, got " +
                                std::to_string(coulomb_band) + " (in dynid::" + function + ")");
}

}  // namespace

void friction(const Model& model, const VectorIn& qd, VectorOut tau) {
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(tau, model);
  tau.setZero();
  detail::add_drive_friction(model, qd, tau);
}

void friction(const Model& model, const VectorIn& qd, double coulomb_band, VectorOut tau) {
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(tau, model);
  check_band(coulomb_band, __func__);
  tau.setZero();
  detail::add_drive_friction(
      model, qd, tau, [coulomb_band](double w) { return detail::coulomb_shape(w, coulomb_band); });
}

void friction_terms(const Model& model, const VectorIn& qd, double coulomb_band, VectorOut viscous,
                    VectorOut coulomb) {
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(viscous, model);
  DYNID_CHECK_JOINT_VECTOR(coulomb, model);
  check_band(coulomb_band, __func__);
  viscous.setZero();
  coulomb.setZero();
  detail::add_drive_friction_terms(model, qd, coulomb_band, viscous, coulomb);
}

int asymmetric_friction_columns(int n, bool offset) { return (offset ? 3 : 4) * n; }

void asymmetric_friction_regressor(const VectorIn& qd, bool offset, RowMajorOut Y) {
  const int n = static_cast<int>(qd.size());
  DYNID_CHECK_SHAPE(Y, n, asymmetric_friction_columns(n, offset));
  Y.setZero();
  double entries[4];
  for (int j = 0; j < n; ++j) {
    detail::asymmetric_friction_entries(qd[j], offset, entries);
    for (int block = 0; block < (offset ? 3 : 4); ++block) Y(j, block * n + j) = entries[block];
  }
}

}  // namespace dynid
