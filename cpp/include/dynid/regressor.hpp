// Linear parametrisations of the dynamics in the standard parameters (notes, "Dynamic parameters
// of robots 4"; paper eqs. (17)-(18)). Columns: the 10n standard parameters in standard order
// (docs/conventions.md), link 1 first, then optionally Ia (n), then Fv (n) and Fs (n).
#pragma once

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// P, the columns of regressor(): 10n, plus n with rotor, plus 2n with friction.
int regressor_columns(int n, bool rotor, bool friction);

// The three regressors check q, qd, qdd (n entries) and the output's shape (given with each)
// and throw std::invalid_argument naming the argument (or ws) that does not fit the model.

// Y(q, qd, qdd) (n x P) with Y pi == rnea(q, qd, qdd). Block upper triangular: the row of joint i
// has zeros in the columns of links j < i.
void regressor(const Model& model, Workspace& ws, const VectorIn& q, const VectorIn& qd,
               const VectorIn& qdd, bool rotor, bool friction, RowMajorOut Y);

// Y_g(q) (n x 10n) with Y_g pi == gravity(q).
void gravity_regressor(const Model& model, Workspace& ws, const VectorIn& q, RowMajorOut Yg);

// Y_m(q) (n(n+1)/2 x 10n [+ n]) with Y_m pi == the lower triangle of B(q) [of M(q) with the rotor
// columns], rows in np.tril_indices(n) order: (0,0), (1,0), (1,1), (2,0), ...
void inertia_regressor(const Model& model, Workspace& ws, const VectorIn& q, bool rotor,
                       RowMajorOut Ym);

}  // namespace dynid
