#include "dynid/model.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace dynid {
namespace {

constexpr double kPi = 3.141592653589793;  // the double nearest pi (numpy.pi)

void require_homogeneous(const Matrix4& T, const char* name) {
  if (!T.allFinite()) throw std::invalid_argument(std::string(name) + ": non-finite value");
  const Matrix3 R = T.topLeftCorner<3, 3>();
  const bool orthonormal = (R.transpose() * R - Matrix3::Identity()).cwiseAbs().maxCoeff() < 1e-6;
  const bool last_row = (T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() == 0.0;
  if (!orthonormal || !last_row || R.determinant() < 0.0)
    throw std::invalid_argument(std::string(name) +
                                ": expected a homogeneous transform (rotation with det +1, last "
                                "row [0, 0, 0, 1])");
}

void require_length(const VectorIn& v, int n, const char* name) {
  if (v.size() != n)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(n) +
                                " values, got " + std::to_string(v.size()));
  if (!v.allFinite()) throw std::invalid_argument(std::string(name) + ": non-finite value");
}

}  // namespace

Model::Model(std::vector<DHRow> rows, Convention convention, const Vector3& gravity,
             const Matrix4& base, const Matrix4& tool)
    : n_(static_cast<int>(rows.size())),
      convention_(convention),
      rows_(std::move(rows)),
      gravity_(Vector3(0, 0, -9.81)),
      base_(Matrix4::Identity()),
      tool_(Matrix4::Identity()) {
  if (n_ < 1) throw std::invalid_argument("dh: a chain needs at least one joint");
  for (int i = 0; i < n_; ++i) {
    const DHRow& r = rows_[i];
    if (!std::isfinite(r.a) || !std::isfinite(r.alpha) || !std::isfinite(r.d) ||
        !std::isfinite(r.theta))
      throw std::invalid_argument("dh: row " + std::to_string(i) + " has a non-finite value");
  }
  set_gravity(gravity);
  set_base(base);
  set_tool(tool);
  name_ = std::to_string(n_) + "-dof arm";
  for (int i = 0; i < n_; ++i) joint_names_.push_back("q" + std::to_string(i + 1));
  for (int i = 0; i < n_; ++i) link_names_.push_back("link" + std::to_string(i + 1));
  qlim_.resize(n_, 2);
  for (int i = 0; i < n_; ++i) {
    const double limit = rows_[i].type == JointType::Revolute ? kPi : 1.0;
    qlim_.row(i) << -limit, limit;
  }
  velocity_limits_ = VectorX::Constant(n_, std::numeric_limits<double>::infinity());
  effort_limits_ = VectorX::Constant(n_, std::numeric_limits<double>::infinity());
  parameters_ = MatrixX::Zero(n_, 10);
  Ia_ = VectorX::Zero(n_);
  Fv_ = VectorX::Zero(n_);
  Fs_ = VectorX::Zero(n_);
  T_ = MatrixX::Identity(n_, n_);
  update_drive_matrices();
  gear_ratios_ = VectorX::Ones(n_);
  joint_offsets_ = VectorX::Zero(n_);

  // Bring both conventions to the modified form (joint_transform.hpp). For standard DH the
  // constant Tx(a_{i-1}) Rx(alpha_{i-1}) of the previous row precedes joint i, and link i's DH
  // frame sits at J_i * Tx(a_i) Rx(alpha_i).
  joints_.resize(n_);
  offsets_.assign(n_, detail::LinkOffset{});
  for (int i = 0; i < n_; ++i) {
    const DHRow& r = rows_[i];
    detail::JointGeometry& j = joints_[i];
    j.revolute = r.type == JointType::Revolute;
    j.theta = r.theta;
    j.d = r.d;
    double a = 0.0, alpha = 0.0;
    if (convention_ == Convention::Modified) {
      a = r.a;
      alpha = r.alpha;
    } else if (i > 0) {
      a = rows_[i - 1].a;
      alpha = rows_[i - 1].alpha;
    }
    j.a = a;
    j.cos_alpha = std::cos(alpha);
    j.sin_alpha = std::sin(alpha);
    if (convention_ == Convention::Standard) {
      offsets_[i] = detail::LinkOffset{false, std::cos(r.alpha), std::sin(r.alpha), r.a};
    }
  }
  update_frames();
  update_bodies();
}

void Model::set_gravity(const Vector3& gravity) {
  if (!gravity.allFinite()) throw std::invalid_argument("gravity: non-finite value");
  gravity_ = gravity;
  gravity_base_ = base_.topLeftCorner<3, 3>().transpose() * gravity_;
}

void Model::set_base(const Matrix4& base) {
  require_homogeneous(base, "base");
  base_ = base;
  gravity_base_ = base_.topLeftCorner<3, 3>().transpose() * gravity_;
}

void Model::set_tool(const Matrix4& tool) {
  require_homogeneous(tool, "tool");
  tool_ = tool;
  if (!offsets_.empty()) update_frames();
}

void Model::set_name(std::string name) { name_ = std::move(name); }

namespace {
// n names, none empty, no two alike (what `field` names: joints or links).
void require_names(const std::vector<std::string>& names, int n, const std::string& field,
                   const char* what) {
  if (static_cast<int>(names.size()) != n)
    throw std::invalid_argument(field + ": expected " + std::to_string(n) + " names, got " +
                                std::to_string(names.size()));
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i].empty())
      throw std::invalid_argument(field + ": name " + std::to_string(i) + " is empty");
    for (std::size_t k = 0; k < i; ++k)
      if (names[k] == names[i])
        throw std::invalid_argument(field + ": '" + names[i] + "' names " + what + " " +
                                    std::to_string(k) + " and " + std::to_string(i));
  }
}
}  // namespace

void Model::set_joint_names(std::vector<std::string> joint_names) {
  require_names(joint_names, n_, "joint_names", "joints");
  joint_names_ = std::move(joint_names);
}

void Model::set_link_names(std::vector<std::string> link_names) {
  require_names(link_names, n_, "link_names", "links");
  link_names_ = std::move(link_names);
}

void Model::set_joint_limits(const Eigen::Ref<const MatrixX>& qlim) {
  if (qlim.rows() != n_ || qlim.cols() != 2)
    throw std::invalid_argument("qlim: expected shape (" + std::to_string(n_) + ", 2), got (" +
                                std::to_string(qlim.rows()) + ", " + std::to_string(qlim.cols()) +
                                ")");
  if (!qlim.allFinite()) throw std::invalid_argument("qlim: non-finite value");
  if (!(qlim.col(0).array() < qlim.col(1).array()).all())
    throw std::invalid_argument("qlim: every lower limit must be below its upper limit");
  qlim_ = qlim;
}

void Model::update_frames() {
  Matrix4 offset = Matrix4::Identity();
  offset.topLeftCorner<3, 3>() = offsets_[n_ - 1].rotation();
  offset.topRightCorner<3, 1>() = offsets_[n_ - 1].translation();
  flange_to_tool_ = offset * tool_;
}

void Model::set_parameters(const Eigen::Ref<const MatrixX>& parameters) {
  if (parameters.rows() != n_ || parameters.cols() != 10)
    throw std::invalid_argument("params: expected shape (" + std::to_string(n_) + ", 10), got (" +
                                std::to_string(parameters.rows()) + ", " +
                                std::to_string(parameters.cols()) + ")");
  if (!parameters.allFinite()) throw std::invalid_argument("params: non-finite value");
  parameters_ = parameters;
  update_bodies();
}

void Model::set_link(int i, const RigidBodyParameters& body) {
  if (i < 0 || i >= n_)
    throw std::invalid_argument("i: link index " + std::to_string(i) + " out of range [0, " +
                                std::to_string(n_) + ")");
  double row[10];
  body.to_standard(row);
  for (int k = 0; k < 10; ++k) parameters_(i, k) = row[k];
  if (!parameters_.row(i).allFinite()) throw std::invalid_argument("params: non-finite value");
  update_bodies();
}

std::string Model::link_inconsistency(int i) const {
  if (i < 0 || i >= n_)
    throw std::invalid_argument("i: expected a link index in [0, " + std::to_string(n_) +
                                "), got " + std::to_string(i));
  double row[10];
  for (int k = 0; k < 10; ++k) row[k] = parameters_(i, k);
  return physical_inconsistency(RigidBodyParameters::from_standard(row));
}

void Model::set_rotor_inertia(const VectorIn& Ia) {
  require_length(Ia, n_, "Ia");
  Ia_ = Ia;
  update_drive_matrices();
}
void Model::set_viscous_friction(const VectorIn& Fv) {
  require_length(Fv, n_, "Fv");
  Fv_ = Fv;
  update_drive_matrices();
}
void Model::set_coulomb_friction(const VectorIn& Fs) {
  require_length(Fs, n_, "Fs");
  Fs_ = Fs;
}

void Model::set_transmission(const Eigen::Ref<const MatrixX>& T) {
  if (T.rows() != n_ || T.cols() != n_)
    throw std::invalid_argument("transmission: expected shape (" + std::to_string(n_) + ", " +
                                std::to_string(n_) + "), got (" + std::to_string(T.rows()) + ", " +
                                std::to_string(T.cols()) + ")");
  if (!T.allFinite()) throw std::invalid_argument("transmission: non-finite value");
  // Invertible: every joint velocity follows from the motor velocities (q_dot = T^-1 theta_dot).
  // T is square, so the two-sided Jacobi SVD needs no QR preconditioner (the default one would
  // compile three QR decompositions for the rectangular cases: 6 s of build time for nothing).
  const VectorX sigma = Eigen::JacobiSVD<MatrixX, Eigen::NoQRPreconditioner>(T).singularValues();
  const double rcond = sigma[0] > 0.0 ? sigma[n_ - 1] / sigma[0] : 0.0;
  if (!(rcond > kTransmissionMinRcond))
    throw std::invalid_argument(
        "transmission: expected an invertible matrix (sigma_min / sigma_max > 1e-12), got "
        "sigma_min / sigma_max = " +
        std::to_string(rcond));
  T_ = T;
  transmission_identity_ = T_ == MatrixX::Identity(n_, n_);
  update_drive_matrices();
}

namespace {
// n positive limits, +infinity allowed (not limited); NaN, zero and negative values refused.
void require_limits(const VectorIn& limits, int n, const char* name) {
  if (limits.size() != n)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(n) +
                                " values, got " + std::to_string(limits.size()));
  for (int i = 0; i < n; ++i)
    if (!(limits[i] > 0.0))  // also NaN
      throw std::invalid_argument(std::string(name) + ": joint " + std::to_string(i + 1) + " has " +
                                  std::to_string(limits[i]) +
                                  " (expected a value > 0, or infinity for no limit)");
}
}  // namespace

void Model::set_velocity_limits(const VectorIn& limits) {
  require_limits(limits, n_, "velocity_limits");
  velocity_limits_ = limits;
}

void Model::set_effort_limits(const VectorIn& limits) {
  require_limits(limits, n_, "effort_limits");
  effort_limits_ = limits;
}

void Model::set_gear_ratios(const VectorIn& gear_ratios) {
  require_length(gear_ratios, n_, "gear_ratios");
  // A zero ratio would make R = diag(gear_ratios) T singular: no joint angle from the motors.
  for (int i = 0; i < n_; ++i)
    if (gear_ratios[i] == 0.0)
      throw std::invalid_argument("gear_ratios: joint " + std::to_string(i + 1) +
                                  " has a zero gear ratio (expected non-zero values)");
  gear_ratios_ = gear_ratios;
}

void Model::set_joint_offsets(const VectorIn& joint_offsets) {
  require_length(joint_offsets, n_, "joint_offsets");
  joint_offsets_ = joint_offsets;
}

void Model::update_drive_matrices() {
  if (transmission_identity_) {
    drive_inertia_ = Ia_.asDiagonal();
    drive_damping_ = Fv_.asDiagonal();
    return;
  }
  drive_inertia_ = T_.transpose() * Ia_.asDiagonal() * T_;
  drive_damping_ = T_.transpose() * Fv_.asDiagonal() * T_;
}

void Model::update_bodies() {
  bodies_.resize(n_);
  for (int i = 0; i < n_; ++i) {
    double row[10];
    for (int k = 0; k < 10; ++k) row[k] = parameters_(i, k);
    bodies_[i] = RigidBodyParameters::from_standard(row).expressed_in_parent(
        offsets_[i].rotation(), offsets_[i].translation());
  }
}

}  // namespace dynid
