// A "KUKA-like" controller for the elastic-joint simulator: the joint-torque-feedback structure of
// the DLR/KUKA light-weight robots (Albu-Schaeffer, Ott, Hirzinger, "A unified passivity-based
// control framework for position, torque and impedance control of flexible joint robots", IJRR
// 26(1), 2007): an outer joint impedance law gives a desired joint torque u, an inner torque loop
// turns it into the motor torque (docs/elastic.md, "The KUKA-like controller"):
//
//   u   = Kp e + Kd ed + g_c + tau_user                              outer law
//   tau = u + K_T (u - tau_J) - D_T tau_J'                            inner torque loop
//       = B B_theta^-1 u + (I - B B_theta^-1) tau_J - D_T tau_J',   B_theta = B (I + K_T)^-1
//
// With D_T = 0 the motor equation becomes B_theta thetadd + tau_J + B_theta B^-1 tau_F = u: the
// torque loop scales the motor inertia (and its friction) down by 1 + K_T. tau_J' = K_c (thetad -
// qd) with the controller's stiffness K_c. The position feedback is collocated (motor side), which
// keeps the loop passive (Albu-Schaeffer 2007; a link-side PD through the spring is not):
//   e = theta_d - theta,  ed = qd_d - thetad,  theta_d = q_d + K_c^-1 g_c(q_d),
//   g_c = g_c(qbar(theta)) (static: qbar solves K_c (theta - qbar) = g_c(qbar)) or g_c(q_d)
//   (desired: for a set-point this is the motor PD of MotorPDController), of the controller's
//   model.
#pragma once

#include "dynid/controllers.hpp"
#include "dynid/elastic_simulator.hpp"
#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

enum class GravityCompensation { Desired, Static };

// One entry per joint: Kp, Kd >= 0 (outer law), K_T >= 0 and D_T >= 0 (torque loop).
struct KukaLikeGains {
  VectorX kp, kd, torque_gain, torque_damping;
};

class KukaLikeController : public ElasticController {
 public:
  // `model` (the controller's links) and `reference` are kept by reference and must outlive the
  // controller; `tau_user` is null or (reference.samples x n) row-major, kept likewise.
  // std::invalid_argument naming stiffness, a gain or reference on a size or sign error (the
  // binding checks that the model has the plant's joints).
  KukaLikeController(const Model& model, const VectorIn& stiffness, const KukaLikeGains& gains,
                     GravityCompensation gravity, const ReferenceTrajectory& reference,
                     const double* tau_user = nullptr);
  void command(int k, double t, const VectorIn& q, const VectorIn& qd, const VectorIn& theta,
               const VectorIn& thetad, const VectorIn& tau_J, VectorOut tau) override;

  // qbar(theta): the link position at which the spring K_c holds the controller's gravity,
  // K_c (theta - qbar) = g_c(qbar), by the fixed-point iteration qbar <- theta - K_c^-1 g_c(qbar)
  // (a contraction when K_c dominates the gravity gradient), warm-started from the last result.
  // std::runtime_error when it does not converge.
  const VectorX& static_link_position(const VectorIn& theta);

 private:
  const Model& model_;
  VectorX stiffness_;
  KukaLikeGains gains_;
  GravityCompensation gravity_;
  ReferenceTrajectory reference_;
  const double* tau_user_;
  Workspace ws_;
  VectorX g_, g_desired_, q_bar_, next_, u_;
  bool warm_ = false;
};

}  // namespace dynid
