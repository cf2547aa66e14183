#include "dynid/rigid_body.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace dynid {

RigidBodyParameters RigidBodyParameters::from_standard(const double* pi10) {
  RigidBodyParameters body;
  body.m = pi10[0];
  body.h = Vector3(pi10[1], pi10[2], pi10[3]);
  body.I << pi10[4], pi10[5], pi10[6],  //
      pi10[5], pi10[7], pi10[8],        //
      pi10[6], pi10[8], pi10[9];
  return body;
}

void RigidBodyParameters::to_standard(double* pi10) const {
  pi10[0] = m;
  pi10[1] = h.x();
  pi10[2] = h.y();
  pi10[3] = h.z();
  pi10[4] = I(0, 0);
  pi10[5] = I(0, 1);
  pi10[6] = I(0, 2);
  pi10[7] = I(1, 1);
  pi10[8] = I(1, 2);
  pi10[9] = I(2, 2);
}

RigidBodyParameters RigidBodyParameters::from_physical(double mass, const Vector3& com,
                                                       const Matrix3& inertia_com) {
  RigidBodyParameters at_com;
  at_com.m = mass;
  at_com.I = inertia_com;
  return at_com.expressed_in_parent(Matrix3::Identity(), com);
}

RigidBodyParameters RigidBodyParameters::expressed_in_parent(const Matrix3& R,
                                                             const Vector3& p) const {
  // Sum over mass points x_A = R x_B + p of m (|x|^2 E - x x^T), with hr = R h:
  // R I R^T + 2 (p . hr) E - hr p^T - p hr^T + m (|p|^2 E - p p^T).
  // Written for the six independent entries (the result is symmetric by construction).
  RigidBodyParameters out;
  const Vector3 hr = R * h;
  out.m = m;
  out.h = hr + m * p;
  const double k = 2.0 * p.dot(hr) + m * p.squaredNorm();
  // Scalar loops over the symmetric entries: cheaper than Eigen's general 3x3 products here.
  double RI[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      RI[r][c] = R(r, 0) * I(0, c) + R(r, 1) * I(1, c) + R(r, 2) * I(2, c);
  for (int r = 0; r < 3; ++r) {
    for (int c = r; c < 3; ++c) {
      double v = RI[r][0] * R(c, 0) + RI[r][1] * R(c, 1) + RI[r][2] * R(c, 2) - hr[r] * p[c] -
                 p[r] * hr[c] - m * p[r] * p[c];
      if (r == c) v += k;
      out.I(r, c) = v;
      out.I(c, r) = v;
    }
  }
  return out;
}

Matrix3 RigidBodyParameters::inertia_about_com() const {
  const Vector3 c = h / m;
  return I - m * (c.squaredNorm() * Matrix3::Identity() - c * c.transpose());
}

std::string physical_inconsistency(double mass, const Matrix3& inertia_com) {
  if (!(mass > 0.0)) return "mass must be positive, got " + std::to_string(mass);
  const double scale = inertia_com.cwiseAbs().maxCoeff();
  if ((inertia_com - inertia_com.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
    return "inertia about the centre of mass must be symmetric";
  const Vector3 moments = Eigen::SelfAdjointEigenSolver<Matrix3>(inertia_com).eigenvalues();
  if (!(moments.minCoeff() > 0.0))
    return "inertia about the centre of mass must be positive definite (smallest principal "
           "moment " +
           std::to_string(moments.minCoeff()) + ")";
  const double slack = 1e-12 * moments.sum();
  for (int k = 0; k < 3; ++k) {
    if (moments[(k + 1) % 3] + moments[(k + 2) % 3] < moments[k] - slack)
      return "principal moments of inertia violate the triangle inequality";
  }
  return "";
}

std::string physical_inconsistency(const RigidBodyParameters& body) {
  if (!(body.m > 0.0)) return physical_inconsistency(body.m, Matrix3::Identity());
  return physical_inconsistency(body.m, body.inertia_about_com());
}

}  // namespace dynid
