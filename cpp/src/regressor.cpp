// Regressors assembled recursively, without evaluating the dynamics for unit parameter vectors.
//
// Link j's wrench about the origin of its parameter frame is linear in its ten parameters
// pi_j = (m, h, I) (the body regressor, notes "Dynamic parameters of robots 3"):
//   f = m a + wd x h + w x (w x h),   mu = I wd + w x (I w) + h x a.
// Joint i carries the share U_ij . (mu, f) of it, where U_ij = [s; l] is joint i's axis as a
// spatial motion vector at that origin. So instead of carrying 6 x 10 body regressors inwards,
// the forward recursion carries the axes outwards (one motion transform per pair i <= j) and each
// 1 x 10 block Y_ij is the axis applied to link j's body regressor in closed form:
//   Y_ij = [ l.a,  l x wd + w (l.w) - l |w|^2 + a x s,  K(s, wd) + K(s x w, w) ]
// with K(u, v) the coefficients of u^T I v in (Ixx, Ixy, Ixz, Iyy, Iyz, Izz). Blocks j < i stay
// zero: the block upper-triangular structure of the notes.
#include "dynid/regressor.hpp"

#include <algorithm>

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/drive_terms.hpp"
#include "dynid/detail/kinematics.hpp"
#include "dynid/detail/newton_euler.hpp"

namespace dynid {
namespace {

using detail::JointTransform;
using detail::LinkOffset;
using detail::WorkspaceBuffers;

// The coefficients of u^T I v over the six independent entries of a symmetric I.
inline void add_quadratic_form(const Vector3& u, const Vector3& v, double* out) {
  out[0] += u.x() * v.x();
  out[1] += u.x() * v.y() + u.y() * v.x();
  out[2] += u.x() * v.z() + u.z() * v.x();
  out[3] += u.y() * v.y();
  out[4] += u.y() * v.z() + u.z() * v.y();
  out[5] += u.z() * v.z();
}

// Motion of link j seen in the frame its parameters are given in (DH frame j).
struct LinkMotion {
  Vector3 w, wd, a;
};

inline LinkMotion motion_in_link_frame(const WorkspaceBuffers& ws, int j, const LinkOffset& o) {
  const Vector3& w = ws.omega[j];
  const Vector3& wd = ws.omegad[j];
  const Vector3 p(o.a, 0.0, 0.0);
  return {o.rotate_to_link(w), o.rotate_to_link(wd),
          o.rotate_to_link(ws.a[j] + wd.cross(p) + w.cross(w.cross(p)))};
}

// Link j's body regressor as a linear map of a joint axis [s; l] given in DH frame j: the closed
// form of the header comment written as
//   Y_ij = [ a . l,  W l + a x s,  G s ],  W = w w^T - |w|^2 E - wd^,  G = Q(wd) - Q(w) w^
// where Q(v) u = K(u, v). W and G are formed once per link from the six products of w; the
// n(n+1)/2 blocks are then plain scalar products (written out: Eigen's small fixed-size
// expressions cost more here than the arithmetic itself).
struct BodyMap {
  double a[3], W[9], G[18];

  explicit BodyMap(const LinkMotion& k) {
    const Vector3& w = k.w;
    const Vector3& wd = k.wd;
    const double xx = w.x() * w.x(), yy = w.y() * w.y(), zz = w.z() * w.z();
    const double xy = w.x() * w.y(), xz = w.x() * w.z(), yz = w.y() * w.z();
    a[0] = k.a.x(), a[1] = k.a.y(), a[2] = k.a.z();
    const double W_[9] = {-yy - zz,    xy + wd.z(), xz - wd.y(),  //
                          xy - wd.z(), -xx - zz,    yz + wd.x(),  //
                          xz + wd.y(), yz - wd.x(), -xx - yy};
    // Q(wd) minus Q(w) w^, entry by entry.
    const double G_[18] = {wd.x(),      xz,          -xy,          //
                           wd.y() - xz, wd.x() + yz, xx - yy,      //
                           wd.z() + xy, zz - xx,     wd.x() - yz,  //
                           -yz,         wd.y(),      xy,           //
                           yy - zz,     wd.z() - xy, wd.y() + xz,  //
                           yz,          -xz,         wd.z()};
    std::copy(W_, W_ + 9, W);
    std::copy(G_, G_ + 18, G);
  }

  void row(const double* U, double* out) const {
    const double s0 = U[0], s1 = U[1], s2 = U[2], l0 = U[3], l1 = U[4], l2 = U[5];
    out[0] = a[0] * l0 + a[1] * l1 + a[2] * l2;
    out[1] = W[0] * l0 + W[1] * l1 + W[2] * l2 + a[1] * s2 - a[2] * s1;
    out[2] = W[3] * l0 + W[4] * l1 + W[5] * l2 + a[2] * s0 - a[0] * s2;
    out[3] = W[6] * l0 + W[7] * l1 + W[8] * l2 + a[0] * s1 - a[1] * s0;
    for (int r = 0; r < 6; ++r) out[4 + r] = G[3 * r] * s0 + G[3 * r + 1] * s1 + G[3 * r + 2] * s2;
  }
};

// Joint axes are kept in the frames the link parameters are given in (DH frame j for standard
// DH, J_j for modified DH), so that each 1 x 10 block reads them directly.
//   modified: L_{j-1} -> L_j is the whole joint transform X[j];
//   standard: F_{j-1} -> J_j is only Rz(theta_j) Tz(d_j) (X[j]'s constant part Rx Tx is link
//             j-1's offset, already applied), then J_j -> F_j is link j's offset Tx(a_j)
//             Rx(alpha_j).
inline void axis_to_child(const JointTransform& X, Vector6& U) {
  // Reference point to O_j (l + s x p), then R^T = Rz(-theta) Rx(-alpha) on both parts.
  const Vector3 s = U.head<3>();
  const Vector3 l = U.tail<3>() + s.cross(X.p);
  U.head<3>() = X.rotate_to_child(s);
  U.tail<3>() = X.rotate_to_child(l);
}

inline void axis_through_joint_to_link(const JointTransform& X, const LinkOffset& o, Vector6& U) {
  // F_{j-1} -> J_j: reference point to (0, 0, d), then Rz(-theta).
  const double c = X.ct, sn = X.st;
  const double l0 = U[3] + X.d * U[1], l1 = U[4] - X.d * U[0];
  const double s0 = c * U[0] + sn * U[1], s1 = -sn * U[0] + c * U[1], s2 = U[2];
  const double m0 = c * l0 + sn * l1, m1 = -sn * l0 + c * l1, m2 = U[5];
  // J_j -> F_j: reference point to (a, 0, 0) (l + s x (a, 0, 0)), then Rx(-alpha).
  const double ca = o.cos_alpha, sa = o.sin_alpha;
  const double n1 = m1 + o.a * s2, n2 = m2 - o.a * s1;
  U[0] = s0;
  U[1] = ca * s1 + sa * s2;
  U[2] = -sa * s1 + ca * s2;
  U[3] = m0;
  U[4] = ca * n1 + sa * n2;
  U[5] = -sa * n1 + ca * n2;
}

inline Vector6 axis_to_link(const LinkOffset& o, const Vector6& U) {
  Vector6 out;
  out << o.rotate_to_link(U.head<3>()),
      o.rotate_to_link(Vector3(U[3], U[4] + o.a * U[2], U[5] - o.a * U[1]));
  return out;
}

// Moves the axes of joints 1..j-1 from link frame j-1 to link frame j and adds joint j's own.
inline void advance_axes(const Model& model, WorkspaceBuffers& ws, int j) {
  const LinkOffset& o = model.link_offset(j - 1);
  Vector6 own = Vector6::Zero();
  own[model.joint(j - 1).revolute ? 2 : 5] = 1.0;
  if (o.identity) {
    for (int i = 1; i < j; ++i) axis_to_child(ws.X[j], ws.axes[i]);
    ws.axes[j] = own;
  } else {
    for (int i = 1; i < j; ++i) axis_through_joint_to_link(ws.X[j], o, ws.axes[i]);
    ws.axes[j] = axis_to_link(o, own);
  }
}

// Fills the 10n rigid-body columns from the current ws.X and ws.omega/omegad/a.
void rigid_body_columns(const Model& model, WorkspaceBuffers& ws, RowMajorOut Y) {
  const int n = ws.n;
  for (int i = 1; i <= n; ++i) std::fill(&Y(i - 1, 0), &Y(i - 1, 0) + 10 * (i - 1), 0.0);
  for (int j = 1; j <= n; ++j) {
    advance_axes(model, ws, j);
    const LinkOffset& o = model.link_offset(j - 1);
    const BodyMap map(o.identity ? LinkMotion{ws.omega[j], ws.omegad[j], ws.a[j]}
                                 : motion_in_link_frame(ws, j, o));
    for (int i = 1; i <= j; ++i) map.row(ws.axes[i].data(), &Y(i - 1, 10 * (j - 1)));
  }
}

}  // namespace

int regressor_columns(int n, bool rotor, bool friction) {
  return 10 * n + (rotor ? n : 0) + (friction ? 2 * n : 0);
}

void regressor(const Model& model, Workspace& workspace, const VectorIn& q, const VectorIn& qd,
               const VectorIn& qdd, bool rotor, bool friction, RowMajorOut Y) {
  WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  const int n = ws.n;
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_JOINT_VECTOR(qd, model);
  DYNID_CHECK_JOINT_VECTOR(qdd, model);
  DYNID_CHECK_SHAPE(Y, n, regressor_columns(n, rotor, friction));
  detail::update_joint_transforms(model, ws, q);
  detail::propagate_motion(model, ws, qd, qdd, -model.gravity_base());
  rigid_body_columns(model, ws, Y);
  // Drive columns (detail/drive_terms.hpp): motor k's Ia_k, Fv_k, Fs_k multiply T^T e_k times
  // (T qdd)_k, (T qd)_k, sign((T qd)_k); with T = I the diagonals qdd_i, qd_i, sign(qd_i).
  const bool decoupled = model.transmission_is_identity();
  const MatrixX& T = model.transmission();
  int column = 10 * n;
  if (rotor) {
    Y.middleCols(column, n).setZero();
    for (int k = 0; k < n; ++k) {
      if (decoupled) {
        Y(k, column + k) = qdd[k];
        continue;
      }
      const double a = detail::motor_value(model, k, qdd);
      for (int j = 0; j < n; ++j) Y(j, column + k) = T(k, j) * a;
    }
    column += n;
  }
  if (friction) {
    Y.middleCols(column, 2 * n).setZero();
    for (int k = 0; k < n; ++k) {
      if (decoupled) {
        Y(k, column + k) = qd[k];
        Y(k, column + n + k) = detail::sign(qd[k]);
        continue;
      }
      const double w = detail::motor_value(model, k, qd), s = detail::sign(w);
      for (int j = 0; j < n; ++j) {
        Y(j, column + k) = T(k, j) * w;
        Y(j, column + n + k) = T(k, j) * s;
      }
    }
  }
}

void gravity_regressor(const Model& model, Workspace& workspace, const VectorIn& q,
                       RowMajorOut Yg) {
  WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_SHAPE(Yg, model.n(), 10 * model.n());
  detail::update_joint_transforms(model, ws, q);
  detail::propagate_motion(model, ws, ws.zeros, ws.zeros, -model.gravity_base());
  rigid_body_columns(model, ws, Yg);
}

void inertia_regressor(const Model& model, Workspace& workspace, const VectorIn& q, bool rotor,
                       RowMajorOut Ym) {
  // Column k of B is the torque for qdd = e_k at rest without gravity: link j >= k then has
  // wd = s_kj and a = l_kj (its joint-k axis), so entry (i, k) of link j's block is
  //   [ l_i . l_k,  l_i x s_k + l_k x s_i,  K(s_i, s_k) ]   (the body regressor with w = 0).
  WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  const int n = ws.n;
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_SHAPE(Ym, n * (n + 1) / 2, 10 * n + (rotor ? n : 0));
  detail::update_joint_transforms(model, ws, q);
  Ym.setZero();
  for (int j = 1; j <= n; ++j) {
    advance_axes(model, ws, j);
    for (int i = 1; i <= j; ++i) {
      const Vector3 si = ws.axes[i].head<3>(), li = ws.axes[i].tail<3>();
      for (int k = 1; k <= i; ++k) {
        const Vector3 sk = ws.axes[k].head<3>(), lk = ws.axes[k].tail<3>();
        double* row = &Ym((i - 1) * i / 2 + (k - 1), 10 * (j - 1));
        row[0] = li.dot(lk);
        const Vector3 h = li.cross(sk) + lk.cross(si);
        row[1] = h.x();
        row[2] = h.y();
        row[3] = h.z();
        add_quadratic_form(si, sk, row + 4);
      }
    }
  }
  // Rotor columns: entry (i, j) of T^T diag(Ia) T is sum_k Ia_k T(k, i) T(k, j).
  if (rotor) {
    const MatrixX& T = model.transmission();
    for (int i = 1; i <= n; ++i) {
      if (model.transmission_is_identity()) {
        Ym((i - 1) * i / 2 + (i - 1), 10 * n + (i - 1)) = 1.0;
        continue;
      }
      for (int k = 1; k <= i; ++k)
        for (int m = 0; m < n; ++m)
          Ym((i - 1) * i / 2 + (k - 1), 10 * n + m) = T(m, i - 1) * T(m, k - 1);
    }
  }
}

}  // namespace dynid
