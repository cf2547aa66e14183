// The benchmark arm as a Pinocchio model, built programmatically from the DH table (no URDF,
// no dynid code), and the Pinocchio calls that are timed.
//
// Joint frame J_i is where joint i's variable enters; Pinocchio's revolute (prismatic) joint
// turns about (slides along) z of J_i, after a constant placement in J_{i-1}:
//   standard DH, A_{i-1,i} = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i):
//     J_i = F_{i-1} Rz(theta_i) Tz(d_i),  F_i = J_i Tx(a_i) Rx(alpha_i), so
//     placement_i = Tx(a_{i-1}) Rx(alpha_{i-1}) Rz(theta_off_i) Tz(d_off_i)  (base for i = 1);
//     Rz(q) commutes with Tz, so "placement, then Rz(q)" is Rz(theta_off + q) Tz(d).
//     Link i's standard parameters are about F_i, i.e. at Tx(a_i) Rx(alpha_i) in J_i.
//   modified DH, A_{i-1,i} = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i): F_i = J_i,
//     placement_i = the whole row at q = 0 (after the base for i = 1), body at the identity.
// The body inertias are moved to J_i by Pinocchio itself (appendBodyToJoint); the regressor
// check converts the parameters by hand (parameter_map), so the rnea and regressor comparisons
// with dynid check the two conversions against each other.
#include "pinocchio_side.hpp"

#include <stdexcept>

#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/crba.hpp"
#include "pinocchio/algorithm/regressor.hpp"
#include "pinocchio/algorithm/rnea-derivatives.hpp"
#include "pinocchio/algorithm/rnea.hpp"
#include "pinocchio/multibody.hpp"

namespace bench {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Matrix10 = Eigen::Matrix<double, 10, 10>;
using Vector10 = Eigen::Matrix<double, 10, 1>;

Matrix3d rot_x(double angle) { return Eigen::AngleAxisd(angle, Vector3d::UnitX()).matrix(); }
Matrix3d rot_z(double angle) { return Eigen::AngleAxisd(angle, Vector3d::UnitZ()).matrix(); }

// Joint i's placement in J_{i-1} at q = 0, and the pose of link i's DH frame F_i in J_i.
struct Placement {
  pinocchio::SE3 joint;
  pinocchio::SE3 body;
};

Placement placement(const ModelFile& arm, int i) {
  const ModelFile::Joint& row = arm.joints[i];
  const Matrix3d Rz = rot_z(row.theta);
  const Vector3d Tz(0.0, 0.0, row.d);
  const pinocchio::SE3 base(Matrix3d(arm.base.topLeftCorner<3, 3>()),
                            Vector3d(arm.base.topRightCorner<3, 1>()));
  Placement out;
  if (arm.standard) {
    // F_{i-1} in J_{i-1}: the previous row's Tx(a) Rx(alpha), or the base for joint 1
    const ModelFile::Joint* previous = i > 0 ? &arm.joints[i - 1] : nullptr;
    const pinocchio::SE3 F_previous =
        previous ? pinocchio::SE3(rot_x(previous->alpha), Vector3d(previous->a, 0.0, 0.0)) : base;
    out.joint = F_previous * pinocchio::SE3(Rz, Rz * Tz);
    out.body = pinocchio::SE3(rot_x(row.alpha), Vector3d(row.a, 0.0, 0.0));
  } else {
    const Matrix3d Rx = rot_x(row.alpha);
    const pinocchio::SE3 row_at_zero(Rx * Rz, Rx * Vector3d(row.a, 0.0, 0.0) + Rx * Rz * Tz);
    out.joint = i == 0 ? base * row_at_zero : row_at_zero;
    out.body = pinocchio::SE3::Identity();
  }
  return out;
}

// dynid's [m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz] -> Pinocchio's dynamic parameters
// [m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz], both about the frame origin.
Vector10 to_pinocchio_order(const Vector10& pi) {
  Vector10 out = pi;
  out[6] = pi[7];
  out[7] = pi[6];
  return out;
}

// Linear map T with pi_J = T pi_F: a body's dynid parameters about frame F to Pinocchio's about
// frame J, where F = J * (R, p). Written out by hand (a point mass at x_J = R x_F + p,
// integrated): h_J = R h + m p,  I_J = R I R^T - S(R h) S(p) - S(p) S(R h) - m S(p) S(p).
// Column k is the image of the k-th unit vector.
Matrix10 parameter_map(const pinocchio::SE3& F_in_J) {
  const Matrix3d& R = F_in_J.rotation();
  const Vector3d& p = F_in_J.translation();
  const Matrix3d Sp = pinocchio::skew(p);
  Matrix10 T;
  for (int k = 0; k < 10; ++k) {
    Vector10 e = Vector10::Zero();
    e[k] = 1.0;
    const double m = e[0];
    const Vector3d c = R * e.segment<3>(1);
    Matrix3d I;
    I << e[4], e[5], e[6], e[5], e[7], e[8], e[6], e[8], e[9];
    const Matrix3d Sc = pinocchio::skew(c);
    const Matrix3d IJ = R * I * R.transpose() - Sc * Sp - Sp * Sc - m * Sp * Sp;
    T.col(k) << m, c + m * p, IJ(0, 0), IJ(0, 1), IJ(1, 1), IJ(0, 2), IJ(1, 2), IJ(2, 2);
  }
  return T;
}

// One joint per DH row, the link's inertia appended in its DH frame, the world's gravity
// (the base is in joint 1's placement, so Pinocchio's universe is the world) and the rotor
// inertias as armature (Pinocchio's rnea, crba and aba add it as dynid adds Ia). Pinocchio has no
// joint friction, so the benchmark arm has Fv = Fs = 0.
pinocchio::Model build_model(const ModelFile& arm) {
  if (arm.Fv.cwiseAbs().maxCoeff() > 0.0 || arm.Fs.cwiseAbs().maxCoeff() > 0.0)
    throw std::runtime_error("Pinocchio has no joint friction: give the arm Fv = Fs = 0");
  pinocchio::Model model;
  pinocchio::JointIndex parent = 0;
  for (int i = 0; i < arm.n(); ++i) {
    const Placement frames = placement(arm, i);
    const std::string name = "joint" + std::to_string(i + 1);
    if (arm.joints[i].revolute)
      parent = model.addJoint(parent, pinocchio::JointModelRZ(), frames.joint, name);
    else
      parent = model.addJoint(parent, pinocchio::JointModelPZ(), frames.joint, name);
    if (!(arm.params[i][0] > 0.0))
      throw std::runtime_error("link " + std::to_string(i + 1) + ": Pinocchio's Inertia needs m > 0");
    model.appendBodyToJoint(
        parent, pinocchio::Inertia::FromDynamicParameters(to_pinocchio_order(arm.params[i])), frames.body);
  }
  model.gravity.linear(arm.gravity);
  model.gravity.angular().setZero();
  model.armature = arm.Ia;
  return model;
}

}  // namespace

// Default options throughout: LOCAL convention for crba and aba (Pinocchio's default).
struct PinocchioSide::Impl {
  Impl(const ModelFile& a, const States& s) : arm(a), model(build_model(a)), data(model), states(s) {}
  const ModelFile& arm;
  const pinocchio::Model model;
  pinocchio::Data data;
  const States& states;
};

PinocchioSide::PinocchioSide(const ModelFile& arm, const States& states)
    : impl_(std::make_unique<Impl>(arm, states)) {}
PinocchioSide::~PinocchioSide() = default;

double PinocchioSide::rnea(int k) {
  Impl& p = *impl_;
  return pinocchio::rnea(p.model, p.data, p.states.q.col(k), p.states.qd.col(k), p.states.qdd.col(k))[0];
}

// Pinocchio's crba fills the upper triangle only; dynid returns the full symmetric M, so the
// timed call includes the copy to the lower triangle (Pinocchio's documented idiom).
double PinocchioSide::crba(int k) {
  Impl& p = *impl_;
  pinocchio::crba(p.model, p.data, p.states.q.col(k));
  p.data.M.triangularView<Eigen::StrictlyLower>() = p.data.M.transpose().triangularView<Eigen::StrictlyLower>();
  return p.data.M(0, 0);
}

double PinocchioSide::gravity(int k) {
  Impl& p = *impl_;
  return pinocchio::computeGeneralizedGravity(p.model, p.data, p.states.q.col(k))[0];
}

double PinocchioSide::coriolis_matrix(int k) {
  Impl& p = *impl_;
  return pinocchio::computeCoriolisMatrix(p.model, p.data, p.states.q.col(k), p.states.qd.col(k))(0, 0);
}

double PinocchioSide::regressor(int k) {
  Impl& p = *impl_;
  return pinocchio::computeJointTorqueRegressor(p.model, p.data, p.states.q.col(k), p.states.qd.col(k),
                                                p.states.qdd.col(k))(0, 0);
}

double PinocchioSide::forward_dynamics(int k) {
  Impl& p = *impl_;
  return pinocchio::aba(p.model, p.data, p.states.q.col(k), p.states.qd.col(k), p.states.tau.col(k))[0];
}

// Pinocchio's routine also fills dtau/da (= M, upper triangle) on the way; dynid's leaves M to
// crba. Timed as the library offers it: the one call a user makes for the derivatives.
double PinocchioSide::rnea_derivatives(int k) {
  Impl& p = *impl_;
  pinocchio::computeRNEADerivatives(p.model, p.data, p.states.q.col(k), p.states.qd.col(k),
                                    p.states.qdd.col(k));
  return p.data.dtau_dq(0, 0);
}

const Eigen::VectorXd& PinocchioSide::tau() const { return impl_->data.tau; }
const Eigen::MatrixXd& PinocchioSide::M() const { return impl_->data.M; }
const Eigen::VectorXd& PinocchioSide::g() const { return impl_->data.g; }
const Eigen::MatrixXd& PinocchioSide::C() const { return impl_->data.C; }
const Eigen::MatrixXd& PinocchioSide::Y() const { return impl_->data.jointTorqueRegressor; }
const Eigen::VectorXd& PinocchioSide::qdd() const { return impl_->data.ddq; }
const PinocchioSide::RowMatrixXd& PinocchioSide::dtau_dq() const { return impl_->data.dtau_dq; }
const PinocchioSide::RowMatrixXd& PinocchioSide::dtau_dqd() const { return impl_->data.dtau_dv; }

Eigen::MatrixXd PinocchioSide::regressor_map() const {
  const int n = impl_->arm.n();
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(10 * n, 10 * n);
  for (int i = 0; i < n; ++i) T.block<10, 10>(10 * i, 10 * i) = parameter_map(placement(impl_->arm, i).body);
  return T;
}

std::string PinocchioSide::version() { return PINOCCHIO_VERSION; }

}  // namespace bench
