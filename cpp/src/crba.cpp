// Composite-rigid-body algorithm (Featherstone, "Rigid Body Dynamics Algorithms", ch. 6) in the
// joint frames. Column i of B is the wrench that a unit acceleration of joint i demands from the
// composite body of links i..n, carried inwards and projected on each joint axis (b_ij depends
// only on links max(i,j)..n, notes "Dynamic parameters of robots 4").
//
// The composite inertias are moved to the parent frame with the DH structure of the joint
// transform (R = Rx(alpha) Rz(theta)): two plane rotations of the six entries of a symmetric
// tensor instead of a general R I R^T.
#include "dynid/crba.hpp"

#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/composite_rigid_body.hpp"
#include "dynid/detail/drive_terms.hpp"
#include "dynid/detail/kinematics.hpp"

namespace dynid {
namespace detail {
namespace {

using Composite = WorkspaceBuffers::Composite;

Composite from_body(const RigidBodyParameters& b) {
  return {b.m, b.h, {b.I(0, 0), b.I(0, 1), b.I(0, 2), b.I(1, 1), b.I(1, 2), b.I(2, 2)}};
}

// The composite body of J_i seen from J_{i-1} (x_parent = R x + p), added to `parent`.
void add_to_parent(const JointTransform& X, const Composite& c, Composite& parent) {
  const double* I = c.I;  // xx, xy, xz, yy, yz, zz
  // Rz(theta) I Rz^T
  const double C = X.ct, S = X.st, CC = C * C, SS = S * S, CS = C * S;
  const double xx = CC * I[0] - 2.0 * CS * I[1] + SS * I[3];
  const double yy = SS * I[0] + 2.0 * CS * I[1] + CC * I[3];
  const double xy = CS * (I[0] - I[3]) + (CC - SS) * I[1];
  const double xz = C * I[2] - S * I[4];
  const double yz = S * I[2] + C * I[4];
  const double zz = I[5];
  // Rx(alpha) (...) Rx^T
  const double ca = X.ca, sa = X.sa, aa = ca * ca, bb = sa * sa, ab = ca * sa;
  double R[6] = {xx,
                 ca * xy - sa * xz,
                 sa * xy + ca * xz,
                 aa * yy - 2.0 * ab * yz + bb * zz,
                 ab * (yy - zz) + (aa - bb) * yz,
                 bb * yy + 2.0 * ab * yz + aa * zz};
  // Shift to the parent origin (generalised Steiner, rigid_body.cpp):
  // + 2 (p.hr) E - (hr p^T + p hr^T) + m (|p|^2 E - p p^T)
  const Vector3 hr = X.rotate_to_parent(c.h);
  const Vector3& p = X.p;
  const double m = c.m;
  const double k = 2.0 * p.dot(hr) + m * p.squaredNorm();
  R[0] += k - 2.0 * hr.x() * p.x() - m * p.x() * p.x();
  R[3] += k - 2.0 * hr.y() * p.y() - m * p.y() * p.y();
  R[5] += k - 2.0 * hr.z() * p.z() - m * p.z() * p.z();
  R[1] -= hr.x() * p.y() + p.x() * hr.y() + m * p.x() * p.y();
  R[2] -= hr.x() * p.z() + p.x() * hr.z() + m * p.x() * p.z();
  R[4] -= hr.y() * p.z() + p.y() * hr.z() + m * p.y() * p.z();
  parent.m += m;
  parent.h += hr + m * p;
  for (int e = 0; e < 6; ++e) parent.I[e] += R[e];
}

}  // namespace

void composite_rigid_body(const Model& model, WorkspaceBuffers& ws, MatrixOut B) {
  const int n = ws.n;
  for (int i = 1; i <= n; ++i) ws.composite[i] = from_body(model.body(i - 1));
  for (int i = n; i >= 2; --i) add_to_parent(ws.X[i], ws.composite[i], ws.composite[i - 1]);

  // Column i of B starts as the wrench of composite i for a unit acceleration of joint i ...
  for (int i = 1; i <= n; ++i) {
    const Composite& C = ws.composite[i];
    Vector3& f = ws.f[i];
    Vector3& mu = ws.mu[i];  // about the origin of J_i
    if (model.joint(i - 1).revolute) {
      mu = Vector3(C.I[2], C.I[4], C.I[5]);  // I e_z
      f = Vector3(-C.h.y(), C.h.x(), 0.0);   // z x h
    } else {
      mu = Vector3(C.h.y(), -C.h.x(), 0.0);  // h x z
      f = Vector3(0.0, 0.0, C.m);
    }
    B(i - 1, i - 1) = model.joint(i - 1).revolute ? mu.z() : f.z();
  }
  // ... and is carried inwards frame by frame. Every column that has reached J_{j+1} crosses
  // X[j+1] in the same sweep: the columns' chains are independent, so interleaving them keeps
  // the floating-point units busy instead of waiting on one chain's latency.
  // Written out in scalars (JointTransform::rotate_to_parent, then mu += p x f): GCC's
  // vectorisation of the Eigen form packed pairs through the stack and stalled on store
  // forwarding, which cost more than the arithmetic.
  for (int j = n - 1; j >= 1; --j) {
    const JointTransform& X = ws.X[j + 1];
    const double ct = X.ct, st = X.st, ca = X.ca, sa = X.sa;
    const double px = X.p.x(), py = X.p.y(), pz = X.p.z();
    const bool revolute = model.joint(j - 1).revolute;
    for (int i = j + 1; i <= n; ++i) {
      double* f = ws.f[i].data();
      double* mu = ws.mu[i].data();
      const double f1 = st * f[0] + ct * f[1];
      const double F0 = ct * f[0] - st * f[1], F1 = ca * f1 - sa * f[2], F2 = sa * f1 + ca * f[2];
      const double m1 = st * mu[0] + ct * mu[1];
      const double M0 = ct * mu[0] - st * mu[1] + (py * F2 - pz * F1);
      const double M1 = ca * m1 - sa * mu[2] + (pz * F0 - px * F2);
      const double M2 = sa * m1 + ca * mu[2] + (px * F1 - py * F0);
      f[0] = F0, f[1] = F1, f[2] = F2;
      mu[0] = M0, mu[1] = M1, mu[2] = M2;
      const double bji = revolute ? M2 : F2;
      B(j - 1, i - 1) = bji;
      B(i - 1, j - 1) = bji;
    }
  }
}

}  // namespace detail

void crba(const Model& model, Workspace& workspace, const VectorIn& q, MatrixOut M) {
  detail::WorkspaceBuffers& ws = DYNID_CHECKED_BUFFERS(model, workspace);
  DYNID_CHECK_JOINT_VECTOR(q, model);
  DYNID_CHECK_SHAPE(M, model.n(), model.n());
  detail::update_joint_transforms(model, ws, q);
  detail::composite_rigid_body(model, ws, M);
  detail::add_drive_inertia(model, M);
}

}  // namespace dynid
