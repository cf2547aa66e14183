// Spatial (6-D) vector algebra in world axes about the world origin, [angular; linear]
// (Featherstone, "Rigid Body Dynamics Algorithms", ch. 2), for the algorithms that work in the
// world frame (Coriolis matrix, analytic derivatives, Jacobian derivative).
#pragma once

#include "dynid/rigid_body.hpp"
#include "dynid/types.hpp"

namespace dynid::detail {

// Motion cross product m1 x m2 = [w1 x w2; w1 x u2 + u1 x w2].
inline Vector6 motion_cross(const Vector6& m1, const Vector6& m2) {
  Vector6 out;
  const Vector3 w1 = m1.head<3>(), u1 = m1.tail<3>(), w2 = m2.head<3>(), u2 = m2.tail<3>();
  out << w1.cross(w2), w1.cross(u2) + u1.cross(w2);
  return out;
}

// Force cross product m x* f = [w x n + u x f; w x f] (the dual of motion_cross).
inline Vector6 force_cross(const Vector6& m, const Vector6& f) {
  Vector6 out;
  const Vector3 w = m.head<3>(), u = m.tail<3>(), n = f.head<3>(), l = f.tail<3>();
  out << w.cross(n) + u.cross(l), w.cross(l);
  return out;
}

// Spatial inertia (m, h = m c, I about the origin) times a motion [w; u]: [I w + h x u; m u - h x
// w].
inline Vector6 inertia_times(const RigidBodyParameters& b, const Vector6& x) {
  Vector6 out;
  out << b.I * x.head<3>() + b.h.cross(x.tail<3>()), b.m * x.tail<3>() - b.h.cross(x.head<3>());
  return out;
}

}  // namespace dynid::detail
