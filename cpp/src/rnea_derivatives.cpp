// Analytic derivatives of the recursive Newton-Euler algorithm, in world axes about the world
// origin (Carpentier & Mansard, RSS 2018, Alg. 1 and eqs. (6)-(12); the notation of
// coriolis_matrix.cpp). With S_k the world axis of joint k, link i's spatial velocity
// v_i = sum_{k<=i} S_k qd_k, acceleration a_i = a_0 + sum_{k<=i} (S_k qdd_k + (v_k x S_k) qd_k)
// (a_0 = [0; -g]), force f_i = I_i a_i + v_i x* I_i v_i and tau_j = S_j . sum_{i>=j} f_i.
//
// A change of q_k moves every quantity outboard of joint k rigidly (d/dq_k X = S_k x X) and, on
// top, changes the velocities and accelerations by the non-rigid parts
//   dV_k = v_{k-1} x S_k,   dA_k = a_{k-1} x S_k + v_{k-1} x dV_k           (paper eq. (8)),
// so that for i >= k, with D_i = v_i x* I_i - I_i v_i x + (I_i v_i) xbar (twice the Coriolis
// factor B_i of coriolis_matrix.cpp, whose block form [[T, 0], [-P^, 0]] it shares):
//   d f_i / dq_k  = S_k x* f_i + I_i dA_k + D_i dV_k,
//   d f_i / dqd_k = I_i (2 dV_k) + D_i S_k.
// The rigid part cancels in S_j . F_j when S_j moves too (k <= j, motion/force duality), hence
//   dtau_j/dq_k  = S_j . (Ic_j dA_k + Dc_j dV_k)                      k <= j
//                = S_j . (S_k x* F_k + Ic_k dA_k + Dc_k dV_k)         k >  j
//   dtau_j/dqd_k = S_j . (Ic_m 2 dV_k + Dc_m S_k),  m = max(j, k)
// with Ic, Dc, F the sums over links m..n. Below the diagonal an entry is a row vector of j
// (Ic_j S_j and Dc_j^T S_j) dotted with column data of k; above it S_j dotted with a column
// wrench of k: O(n^2) dot products after one O(n) forward and one backward pass.
#include "dynid/rnea_derivatives.hpp"

#include <stdexcept>
#include <string>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/drive_terms.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/spatial.hpp"

namespace dynid {
namespace {}  // namespace

void rnea_derivatives(const Model& model, Workspace& workspace, const VectorIn& q,
                      const VectorIn& qd, const VectorIn& qdd, MatrixOut dtau_dq,
                      MatrixOut dtau_dqd) {
  using detail::force_cross;
  using detail::inertia_times;
  using detail::motion_cross;
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  const int n = model.n();
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(qdd, model);
  DYNID_CHECK_SHAPE(dtau_dq, n, n);
  DYNID_CHECK_SHAPE(dtau_dqd, n, n);
  detail::update_joint_transforms(model, ws, q);
  detail::update_world_frames(model, ws);
  detail::DerivativeBuffers& d = ws.derivatives;

  // Forward pass: axes, velocity/acceleration variations, each link's inertia, force and D.
  Vector6 v = Vector6::Zero(), a = Vector6::Zero();
  a.tail<3>() = -model.gravity();  // the fictitious upward acceleration of the base
  for (int i = 1; i <= n; ++i) {
    const Vector3 z = ws.R_world[i].col(2);
    Vector6& S = d.S[i];
    if (model.joint(i - 1).revolute)
      S << z, ws.p_world[i].cross(z);
    else
      S << Vector3::Zero(), z;
    d.dVdq[i] = motion_cross(v, S);
    d.dAdq[i] = motion_cross(a, S) + motion_cross(v, d.dVdq[i]);
    v += S * qd[i - 1];
    a += S * qdd[i - 1] + d.dVdq[i] * qd[i - 1];  // v_i x S_i = v_{i-1} x S_i

    const RigidBodyParameters b =
        model.body(i - 1).expressed_in_parent(ws.R_world[i], ws.p_world[i]);
    const Vector6 momentum = inertia_times(b, v);  // [angular n; linear p]
    d.force[i] = inertia_times(b, a) + force_cross(v, momentum);
    // D = [[T, 0], [-P^, 0]]: T = A + A^T - (h u^T + u h^T) + 2 (u.h) E - n^, A = w^ I,
    // P = 2 p (coriolis_matrix.cpp, doubled).
    const Vector3 w = v.head<3>(), u = v.tail<3>();
    Matrix3 A;
    for (int c = 0; c < 3; ++c) A.col(c) = w.cross(b.I.col(c));
    const Matrix3 hu = b.h * u.transpose();
    Matrix3& T = d.coriolis_block[i];
    T = A + A.transpose() - hu - hu.transpose() - skew(momentum.head<3>());
    T.diagonal().array() += 2.0 * u.dot(b.h);
    d.momentum[i] = 2.0 * momentum.tail<3>();
    d.inertia[i] = b;
  }

  // Backward pass: composites, then row j of both matrices.
  for (int j = n; j >= 1; --j) {
    if (j < n) {
      d.inertia[j] += d.inertia[j + 1];
      d.coriolis_block[j] += d.coriolis_block[j + 1];
      d.momentum[j] += d.momentum[j + 1];
      d.force[j] += d.force[j + 1];
    }
    const RigidBodyParameters& Ic = d.inertia[j];
    const Matrix3& T = d.coriolis_block[j];
    const Vector3& P = d.momentum[j];
    const Vector6& S = d.S[j];
    // D y = [T y_w; y_w x P] depends on the angular part of y only.
    const auto D_times = [&](const Vector6& y) {
      Vector6 out;
      out << T * y.head<3>(), y.head<3>().cross(P);
      return out;
    };
    d.column_q[j] = force_cross(S, d.force[j]) + inertia_times(Ic, d.dAdq[j]) + D_times(d.dVdq[j]);
    d.column_qd[j] = inertia_times(Ic, 2.0 * d.dVdq[j]) + D_times(S);
    // S_j . (Ic x + D y) = (Ic S_j) . x + (T^T s + P x l) . y_w, S_j = [s; l].
    const Vector6 row_inertia = inertia_times(Ic, S);
    const Vector3 row_D = T.transpose() * S.head<3>() + P.cross(S.tail<3>());
    for (int k = 1; k <= j; ++k) {
      dtau_dq(j - 1, k - 1) = row_inertia.dot(d.dAdq[k]) + row_D.dot(d.dVdq[k].head<3>());
      dtau_dqd(j - 1, k - 1) = 2.0 * row_inertia.dot(d.dVdq[k]) + row_D.dot(d.S[k].head<3>());
    }
    for (int k = j + 1; k <= n; ++k) {
      dtau_dq(j - 1, k - 1) = S.dot(d.column_q[k]);
      dtau_dqd(j - 1, k - 1) = S.dot(d.column_qd[k]);
    }
  }
  // Drive terms: viscous friction T^T diag(Fv) T qd; Coulomb Fs sign(T qd) is flat away from
  // zero motor velocity and the rotor inertia enters dtau/dqdd only.
  detail::add_drive_damping(model, dtau_dqd);
}

}  // namespace dynid
