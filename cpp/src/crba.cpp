// Composite-rigid-body algorithm (Featherstone, "Rigid Body Dynamics Algorithms", ch. 6) in the
// joint frames. Column i of B is the wrench that a unit acceleration of joint i demands from the
// composite body of links i..n, carried inwards and projected on each joint axis (b_ij depends
// only on links max(i,j)..n, notes "Dynamic parameters of robots 4").
#include "dynid/crba.hpp"

#include "dynid/kinematics.hpp"

namespace dynid {

void composite_rigid_body(const Model& model, Workspace& ws, MatrixOut B) {
  const int n = ws.n;
  ws.composite[n] = model.body(n - 1);
  for (int i = n - 1; i >= 1; --i) {
    const JointTransform& X = ws.X[i + 1];
    ws.composite[i] = ws.composite[i + 1].expressed_in_parent(X.rotation(), X.p);
    ws.composite[i] += model.body(i - 1);
  }

  for (int i = 1; i <= n; ++i) {
    const RigidBodyParameters& C = ws.composite[i];
    Vector3 f, mu;  // wrench about the origin of J_i for a unit acceleration along z
    if (model.joint(i - 1).revolute) {
      mu = C.I.col(2);
      f = Vector3(-C.h.y(), C.h.x(), 0.0);  // z x h
    } else {
      mu = Vector3(C.h.y(), -C.h.x(), 0.0);  // h x z
      f = Vector3(0.0, 0.0, C.m);
    }
    B(i - 1, i - 1) = model.joint(i - 1).revolute ? mu.z() : f.z();
    for (int j = i - 1; j >= 1; --j) {
      const JointTransform& X = ws.X[j + 1];
      f = X.rotate_to_parent(f);
      mu = X.rotate_to_parent(mu) + X.p.cross(f);
      const double bji = model.joint(j - 1).revolute ? mu.z() : f.z();
      B(j - 1, i - 1) = bji;
      B(i - 1, j - 1) = bji;
    }
  }
}

void crba(const Model& model, Workspace& ws, const VectorIn& q, MatrixOut M) {
  update_joint_transforms(model, ws, q);
  composite_rigid_body(model, ws, M);
  M.diagonal() += model.rotor_inertia();
}

}  // namespace dynid
