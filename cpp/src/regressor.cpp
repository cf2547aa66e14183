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

#include "dynid/kinematics.hpp"
#include "dynid/rnea.hpp"

namespace dynid {
namespace {

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

// Frame J_j -> DH frame j = J_j * (R, p) with (R, p) the model's link offset.
inline Vector6 axis_in_link_frame(const Vector6& U, const Matrix3& R, const Vector3& p) {
  Vector6 out;
  out.head<3>() = R.transpose() * U.head<3>();
  out.tail<3>() = R.transpose() * (U.tail<3>() + U.head<3>().cross(p));
  return out;
}

inline LinkMotion motion_in_link_frame(const Workspace& ws, int j, const Matrix3& R,
                                       const Vector3& p) {
  const Vector3& w = ws.omega[j];
  const Vector3& wd = ws.omegad[j];
  return {R.transpose() * w, R.transpose() * wd,
          R.transpose() * (ws.a[j] + wd.cross(p) + w.cross(w.cross(p)))};
}

// Y_ij of the header comment, written into row[0..9].
inline void axis_row(const Vector6& U, const LinkMotion& k, double* row) {
  const Vector3 s = U.head<3>(), l = U.tail<3>();
  row[0] = l.dot(k.a);
  const Vector3 h = l.cross(k.wd) + k.w * l.dot(k.w) - l * k.w.squaredNorm() + k.a.cross(s);
  row[1] = h.x();
  row[2] = h.y();
  row[3] = h.z();
  for (int c = 4; c < 10; ++c) row[c] = 0.0;
  add_quadratic_form(s, k.wd, row + 4);
  add_quadratic_form(s.cross(k.w), k.w, row + 4);
}

// Axis of joint j in its own frame J_j.
inline Vector6 own_axis(const Model& model, int j) {
  Vector6 U = Vector6::Zero();
  U[model.joint(j - 1).revolute ? 2 : 5] = 1.0;
  return U;
}

// Motion vector in J_{j-1} -> J_j: move the reference point to O_j, then rotate.
inline Vector6 axis_to_child(const JointTransform& X, const Vector6& U) {
  Vector6 out;
  out.head<3>() = X.rotate_to_child(U.head<3>());
  out.tail<3>() = X.rotate_to_child(U.tail<3>() + U.head<3>().cross(X.p));
  return out;
}

// Fills the 10n rigid-body columns from the current ws.X and ws.omega/omegad/a.
void rigid_body_columns(const Model& model, Workspace& ws, MatrixOut Y) {
  const int n = ws.n;
  const bool offset = model.convention() == Convention::Standard;
  double row[10];
  for (int j = 1; j <= n; ++j) {
    for (int i = 1; i < j; ++i) ws.axes[i] = axis_to_child(ws.X[j], ws.axes[i]);
    ws.axes[j] = own_axis(model, j);
    const Matrix3& R = model.link_offset_rotation(j - 1);
    const Vector3& p = model.link_offset_translation(j - 1);
    const LinkMotion k = offset ? motion_in_link_frame(ws, j, R, p)
                                : LinkMotion{ws.omega[j], ws.omegad[j], ws.a[j]};
    for (int i = 1; i <= j; ++i) {
      axis_row(offset ? axis_in_link_frame(ws.axes[i], R, p) : ws.axes[i], k, row);
      for (int c = 0; c < 10; ++c) Y(i - 1, 10 * (j - 1) + c) = row[c];
    }
    for (int i = j + 1; i <= n; ++i)
      for (int c = 0; c < 10; ++c) Y(i - 1, 10 * (j - 1) + c) = 0.0;
  }
}

}  // namespace

int regressor_columns(int n, bool rotor, bool friction) {
  return 10 * n + (rotor ? n : 0) + (friction ? 2 * n : 0);
}

void regressor(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
               const VectorIn& qdd, bool rotor, bool friction, MatrixOut Y) {
  const int n = ws.n;
  update_joint_transforms(model, ws, q);
  propagate_motion(model, ws, qd, qdd, -model.gravity_base());
  rigid_body_columns(model, ws, Y);
  int column = 10 * n;
  if (rotor) {
    Y.middleCols(column, n).setZero();
    for (int i = 0; i < n; ++i) Y(i, column + i) = qdd[i];
    column += n;
  }
  if (friction) {
    Y.middleCols(column, 2 * n).setZero();
    for (int i = 0; i < n; ++i) {
      Y(i, column + i) = qd[i];
      Y(i, column + n + i) = (qd[i] > 0.0) - (qd[i] < 0.0);
    }
  }
}

void gravity_regressor(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut Yg) {
  update_joint_transforms(model, ws, q);
  propagate_motion(model, ws, ws.zeros, ws.zeros, -model.gravity_base());
  rigid_body_columns(model, ws, Yg);
}

void inertia_regressor(const Model& model, Workspace& ws, const VectorIn& q, bool rotor,
                       MatrixOut Ym) {
  // Column k of B is the torque for qdd = e_k at rest without gravity: link j >= k then has
  // wd = s_kj and a = l_kj (its joint-k axis), so entry (i, k) of link j's block is
  //   [ l_i . l_k,  l_i x s_k + l_k x s_i,  K(s_i, s_k) ]   (the body regressor with w = 0).
  const int n = ws.n;
  update_joint_transforms(model, ws, q);
  const bool offset = model.convention() == Convention::Standard;
  Ym.setZero();
  for (int j = 1; j <= n; ++j) {
    for (int i = 1; i < j; ++i) ws.axes[i] = axis_to_child(ws.X[j], ws.axes[i]);
    ws.axes[j] = own_axis(model, j);
    const Matrix3& R = model.link_offset_rotation(j - 1);
    const Vector3& p = model.link_offset_translation(j - 1);
    for (int i = 1; i <= j; ++i) {
      const Vector6 Ui = offset ? axis_in_link_frame(ws.axes[i], R, p) : ws.axes[i];
      for (int k = 1; k <= i; ++k) {
        const Vector6 Uk = offset ? axis_in_link_frame(ws.axes[k], R, p) : ws.axes[k];
        const Vector3 si = Ui.head<3>(), li = Ui.tail<3>(), sk = Uk.head<3>(), lk = Uk.tail<3>();
        const int r = (i - 1) * i / 2 + (k - 1);
        const int c0 = 10 * (j - 1);
        Ym(r, c0) = li.dot(lk);
        const Vector3 h = li.cross(sk) + lk.cross(si);
        Ym(r, c0 + 1) = h.x();
        Ym(r, c0 + 2) = h.y();
        Ym(r, c0 + 3) = h.z();
        double quad[6] = {0, 0, 0, 0, 0, 0};
        add_quadratic_form(si, sk, quad);
        for (int c = 0; c < 6; ++c) Ym(r, c0 + 4 + c) = quad[c];
      }
    }
  }
  if (rotor)
    for (int i = 1; i <= n; ++i) Ym((i - 1) * i / 2 + (i - 1), 10 * n + (i - 1)) = 1.0;
}

}  // namespace dynid
