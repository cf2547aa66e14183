// M by CRBA, the bias by Newton-Euler with qdd = 0, then a Cholesky solve: the whole M must be
// inverted, not its diagonal (notes, "... an incorrect realization").
#include "dynid/forward_dynamics.hpp"

#include <stdexcept>

#include "dynid/crba.hpp"
#include "dynid/rnea.hpp"

namespace dynid {

void forward_dynamics(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
                      const VectorIn& tau, VectorOut qdd) {
  rnea(model, ws, q, qd, ws.zeros, ws.bias);  // also leaves the joint transforms for q in ws.X
  composite_rigid_body(model, ws, ws.M);
  ws.M.diagonal() += model.rotor_inertia();
  ws.cholesky.compute(ws.M);
  if (ws.cholesky.info() != Eigen::Success)
    throw std::domain_error(
        "forward_dynamics: the mass matrix is not positive definite at this q (are the "
        "parameters physically consistent?)");
  qdd = tau - ws.bias;
  ws.cholesky.solveInPlace(qdd);
}

}  // namespace dynid
