// Joint friction of the drive model (notes, "Adding dynamic terms"): the one home of the friction
// law tau_F = Fv w + Fs s(w) on the motor velocities w = T qd, reaching the joints as T^T tau_F
// (docs/transmission.md). The algorithms that add friction (rnea, forward dynamics, the
// simulators, the regressor) all evaluate it through dynid/detail/drive_terms.hpp.
#pragma once

#include "dynid/model.hpp"

namespace dynid {

// Fv qd + Fs sign(qd), sign(0) = 0. qd and tau have n entries (std::invalid_argument otherwise).
void friction(const Model& model, const VectorIn& qd, VectorOut tau);

// Fv qd + Fs tanh(qd / coulomb_band): the simulator's smoothed friction (coulomb_band = 0 is the
// exact sign, the same as friction() above). std::invalid_argument naming coulomb_band unless it
// is finite and >= 0, naming qd or tau for a wrong size.
void friction(const Model& model, const VectorIn& qd, double coulomb_band, VectorOut tau);

// The two terms of friction(model, qd, coulomb_band, .) apart: viscous = T^T (Fv . T qd) and
// coulomb = T^T (Fs . s(T qd)), s as above. Their sum is the friction up to rounding.
void friction_terms(const Model& model, const VectorIn& qd, double coulomb_band, VectorOut viscous,
                    VectorOut coulomb);

// The regressor of the asymmetric friction model (docs/identification.md, "Friction models"): Y
// (n x asymmetric_friction_columns(n, offset)) with blocks of n columns max(qd_j, 0) (Fv+),
// min(qd_j, 0) (Fv-), [qd_j > 0] (Fs+) and -[qd_j < 0] (Fs-), each in row j only; with `offset`
// three blocks Fv+, Fv-, sign(qd_j) (Fs). Per joint on qd (no transmission: the model is refused
// for coupled drives). std::invalid_argument naming Y for a wrong shape.
int asymmetric_friction_columns(int n, bool offset);
void asymmetric_friction_regressor(const VectorIn& qd, bool offset, RowMajorOut Y);

}  // namespace dynid
