// IIR filtering in second-order sections (biquads), the form that keeps high-order, low-cutoff
// filters numerically stable. dynid.signal runs its zero-phase Butterworth low-pass on it
// (forwards, then backwards), and a control loop can run it causally sample by sample.
#pragma once

#include <Eigen/Core>

namespace dynid {

// Row-major blocks: one time sample per row of a signal, one section per row of `sections`.
using SignalBlock =
    Eigen::Ref<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
using SectionsIn = Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>>;

// Filters every column of `signal` (T x C, time along the rows) in place through the S sections,
// each row [b0 b1 b2 a0 a1 a2] with a0 = 1 (std::invalid_argument naming `sections` otherwise),
// in transposed direct form II:
//   y = b0 x + z1,   z1 <- b1 x - a1 y + z2,   z2 <- b2 x - a2 y,
// the output of a section being the input of the next (the same recursion and section order as
// scipy.signal.sosfilt). `state` (S x 2C: section s holds z1 of the C columns, then their z2)
// gives the initial conditions and receives the final ones, so that a long signal can be
// filtered block by block. No allocation.
void sos_filter(const SectionsIn& sections, SignalBlock signal, SignalBlock state);

}  // namespace dynid
