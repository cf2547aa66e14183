// Time derivatives of the recursive Newton-Euler algorithm ("jerk/snap RNEA"), in world axes
// about the world origin with spatial vectors [angular; linear] (Featherstone, "Rigid Body
// Dynamics Algorithms", ch. 2; the notation of rnea_derivatives.cpp).
//
// With S_k the world axis of joint k, a motion vector fixed to link k, its derivatives follow
// from d/dt S = v_k x S:
//   S' = v_k x S,  S'' = a_k x S + v_k x S',  S''' = j_k x S + 2 a_k x S' + v_k x S''.
// Link i's velocity v_i = sum_{k<=i} S_k qd_k gives, by the product rule, the outward recursion
//   v_i = v_{i-1} + S qd
//   a_i = a_{i-1} + S qdd + S' qd                                  (acceleration)
//   j_i = j_{i-1} + S qddd + 2 S' qdd + S'' qd                      (jerk)
//   s_i = s_{i-1} + S qdddd + 3 S' qddd + 3 S'' qdd + S''' qd       (snap)
// Link i's world spatial inertia I_i moves with it: I' = D_v(I) = v x* I - I v x (bilinear in
// v and I), so I'' = D_a(I) + D_v(I'), I''' = D_j(I) + 2 D_a(I') + D_v(I''). Its wrench is the
// rate of its momentum h = I v plus the weight, written with the constant fictitious base
// acceleration a_g = [0; -g]:
//   f   = I' v + I a + I a_g
//   f'  = I'' v + 2 I' a + I j + I' a_g
//   f'' = I''' v + 3 I'' a + 3 I' j + I s + I'' a_g.
// Summed inwards (F_j = sum_{i>=j} f_i) and projected, tau_j = S_j . F_j:
//   tau'  = S' . F + S . F',   tau'' = S'' . F + 2 S' . F' + S . F''.
// The drive terms of docs/conventions.md, "Drive terms and the torque model" are added last (notes
// p. 13): Ia qdd + Fv qd + Fs sign(qd) and their derivatives Ia qddd + Fv qdd, Ia qdddd + Fv qddd
// (Coulomb: flat away from qd = 0); with a transmission T each through T^T (. T ...)
// (detail/drive_terms.hpp, notes p. 11-13).
#include "dynid/rnea_time_derivatives.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/drive_terms.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/spatial.hpp"

namespace dynid {
namespace {

// 6x6 spatial inertia [[I, h^], [-h^, m E]] of a body given by (m, h = m c, I about the origin),
// the matrix of detail::inertia_times.
Matrix6 inertia_matrix(const RigidBodyParameters& b) {
  Matrix6 out;
  out << b.I, skew(b.h), -skew(b.h), b.m * Matrix3::Identity();
  return out;
}

// D_v(I) = v x* I - I v x: the rate of change of a world spatial inertia carried by velocity v.
Matrix6 inertia_rate(const Vector6& v, const Matrix6& I) {
  const Matrix3 w = skew(v.head<3>()), u = skew(v.tail<3>());
  Matrix6 motion_cross;  // v x = [[w^, 0], [u^, w^]]; v x* = -(v x)^T
  motion_cross << w, Matrix3::Zero(), u, w;
  const Matrix6 I_cross = I * motion_cross;
  return -(I_cross.transpose()) - I_cross;  // I symmetric: (v x*) I = -(I v x)^T
}

}  // namespace

void rnea_time_derivatives(const Model& model, Workspace& workspace, const VectorIn& q,
                           const VectorIn& qd, const VectorIn& qdd, const VectorIn& qddd,
                           const VectorIn& qdddd, VectorOut tau, VectorOut tau_dot,
                           VectorOut tau_ddot) {
  using detail::motion_cross;
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  const int n = model.n();
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(qdd, model);
  DYNID_CHECK_JOINT_VECTOR(qddd, model);
  DYNID_CHECK_JOINT_VECTOR(qdddd, model);
  DYNID_CHECK_JOINT_VECTOR(tau, model);
  DYNID_CHECK_JOINT_VECTOR(tau_dot, model);
  DYNID_CHECK_JOINT_VECTOR(tau_ddot, model);
  detail::update_joint_transforms(model, ws, q);
  detail::update_world_frames(model, ws);
  detail::TimeDerivativeBuffers& d = ws.time_derivatives;

  Vector6 a_g = Vector6::Zero();
  a_g.tail<3>() = -model.gravity();
  // Outward pass: velocity, acceleration, jerk and snap of each link; its wrench and derivatives.
  Vector6 v = Vector6::Zero(), a = Vector6::Zero(), j = Vector6::Zero(), s = Vector6::Zero();
  for (int i = 1; i <= n; ++i) {
    const Vector3 z = ws.R_world[i].col(2);
    Vector6& S = d.S[i];
    if (model.joint(i - 1).revolute)
      S << z, ws.p_world[i].cross(z);
    else
      S << Vector3::Zero(), z;
    const double qd_i = qd[i - 1], qdd_i = qdd[i - 1], qddd_i = qddd[i - 1], qdddd_i = qdddd[i - 1];
    Vector6& S1 = d.S_dot[i];
    Vector6& S2 = d.S_ddot[i];
    S1 = motion_cross(v, S);  // v_{i-1} x S = v_i x S
    v += S * qd_i;
    a += S * qdd_i + S1 * qd_i;
    S2 = motion_cross(a, S) + motion_cross(v, S1);
    j += S * qddd_i + 2.0 * S1 * qdd_i + S2 * qd_i;
    const Vector6 S3 = motion_cross(j, S) + 2.0 * motion_cross(a, S1) + motion_cross(v, S2);
    s += S * qdddd_i + 3.0 * S1 * qddd_i + 3.0 * S2 * qdd_i + S3 * qd_i;

    const Matrix6 I0 =
        inertia_matrix(model.body(i - 1).expressed_in_parent(ws.R_world[i], ws.p_world[i]));
    const Matrix6 I1 = inertia_rate(v, I0);
    const Matrix6 I2 = inertia_rate(a, I0) + inertia_rate(v, I1);
    const Matrix6 I3 = inertia_rate(j, I0) + 2.0 * inertia_rate(a, I1) + inertia_rate(v, I2);
    d.force[i] = I1 * v + I0 * (a + a_g);
    d.force_dot[i] = I2 * v + I1 * (2.0 * a + a_g) + I0 * j;
    d.force_ddot[i] = I3 * v + I2 * (3.0 * a + a_g) + 3.0 * (I1 * j) + I0 * s;
  }

  // Inward pass: composite wrenches and their projections on the joint axes.
  // Decoupled drive terms joint by joint (as before the transmission existed), coupled ones
  // through T after the pass (detail/drive_terms.hpp).
  const bool decoupled = model.transmission_is_identity();
  for (int i = n; i >= 1; --i) {
    if (i < n) {
      d.force[i] += d.force[i + 1];
      d.force_dot[i] += d.force_dot[i + 1];
      d.force_ddot[i] += d.force_ddot[i + 1];
    }
    const Vector6 &S = d.S[i], &S1 = d.S_dot[i], &S2 = d.S_ddot[i];
    const Vector6 &F = d.force[i], &F1 = d.force_dot[i], &F2 = d.force_ddot[i];
    const int k = i - 1;
    if (decoupled) {
      tau[k] = S.dot(F) + detail::drive_torque(model, k, qd[k], qdd[k]);
      tau_dot[k] = S1.dot(F) + S.dot(F1) + detail::drive_linear_torque(model, k, qdd[k], qddd[k]);
      tau_ddot[k] = S2.dot(F) + 2.0 * S1.dot(F1) + S.dot(F2) +
                    detail::drive_linear_torque(model, k, qddd[k], qdddd[k]);
    } else {
      tau[k] = S.dot(F);
      tau_dot[k] = S1.dot(F) + S.dot(F1);
      tau_ddot[k] = S2.dot(F) + 2.0 * S1.dot(F1) + S.dot(F2);
    }
  }
  if (!decoupled) {
    detail::add_drive_torque(model, qd, qdd, tau);
    detail::add_drive_linear(model, qdd, qddd, tau_dot);
    detail::add_drive_linear(model, qddd, qdddd, tau_ddot);
  }
}

}  // namespace dynid
