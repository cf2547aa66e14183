#include "dynid/sos_filter.hpp"

#include "dynid/detail/argument_checks.hpp"

#include <stdexcept>
#include <string>

namespace dynid {

void sos_filter(const SectionsIn& sections, SignalBlock signal, SignalBlock state) {
  const Eigen::Index sections_count = sections.rows();
  const Eigen::Index columns = signal.cols();
  DYNID_CHECK_SHAPE(state, sections_count, 2 * columns);
  for (Eigen::Index s = 0; s < sections_count; ++s) {
    if (sections(s, 3) != 1.0)
      throw std::invalid_argument(
          "sections: expected a0 = 1 in every row (normalised "
          "sections), got a0 = " +
          std::to_string(sections(s, 3)) + " in row " + std::to_string(s) +
          " (in dynid::sos_filter)");
  }
  // Samples outside, columns inside: each row of the signal is contiguous, and a column's
  // sections must run in time order anyway.
  for (Eigen::Index t = 0; t < signal.rows(); ++t) {
    double* x = signal.row(t).data();
    for (Eigen::Index s = 0; s < sections_count; ++s) {
      const double b0 = sections(s, 0), b1 = sections(s, 1), b2 = sections(s, 2);
      const double a1 = sections(s, 4), a2 = sections(s, 5);
      double* z1 = state.row(s).data();
      double* z2 = z1 + columns;
      for (Eigen::Index c = 0; c < columns; ++c) {
        const double input = x[c];
        const double output = b0 * input + z1[c];
        z1[c] = b1 * input - a1 * output + z2[c];
        z2[c] = b2 * input - a2 * output;
        x[c] = output;
      }
    }
  }
}

}  // namespace dynid
