// The Coriolis/centrifugal factorisation c(q, qd) = S(q, qd) qd built from the Christoffel
// symbols, so that Mdot - 2S is skew-symmetric (notes, "Bounds on dynamic terms"; paper eqs.
// (15)-(16)).
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

void coriolis_matrix(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
                     MatrixOut S);
// q, qd: n entries, S: n x n; std::invalid_argument naming the argument (or ws) otherwise.

}  // namespace dynid
