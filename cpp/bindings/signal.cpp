#include "signal.hpp"

#include <stdexcept>

#include "arrays.hpp"
#include "dynid/sos_filter.hpp"

namespace dynid::binding {

namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMap = Eigen::Map<RowMatrix>;
using SectionsMap = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>>;

Array checked(py::handle arg, const char* name, int ndim) {
  Array a = as_real_array(arg, name);
  if (a.ndim() != ndim)
    throw py::value_error(std::string(name) + ": expected " + std::to_string(ndim) +
                          " dimensions, got shape " + shape_string(a));
  require_finite(a, name);
  return a;
}

}  // namespace

void bind_signal(py::module_& m) {
  m.def(
      "_sos_filter",
      [](py::handle sections_arg, py::handle x_arg, py::handle state_arg) {
        const Array sections = checked(sections_arg, "sections", 2);
        const Array x = checked(x_arg, "x", 2);
        const Array state_in = checked(state_arg, "state", 3);
        const py::ssize_t S = sections.shape(0), T = x.shape(0), C = x.shape(1);
        if (sections.shape(1) != 6 || S == 0)
          throw py::value_error("sections: expected shape (S, 6) with S >= 1, got " +
                                shape_string(sections));
        if (state_in.shape(0) != S || state_in.shape(1) != 2 || state_in.shape(2) != C)
          throw py::value_error("state: expected shape (" + std::to_string(S) + ", 2, " +
                                std::to_string(C) + "), got " + shape_string(state_in));
        py::array_t<double> y({T, C});
        py::array_t<double> state({S, py::ssize_t{2}, C});
        std::copy(x.data(), x.data() + x.size(), y.mutable_data());
        std::copy(state_in.data(), state_in.data() + state_in.size(), state.mutable_data());
        try {
          py::gil_scoped_release release;
          sos_filter(SectionsMap(sections.data(), S, 6), RowMap(y.mutable_data(), T, C),
                     RowMap(state.mutable_data(), S, 2 * C));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        return py::make_tuple(y, state);
      },
      py::arg("sections"), py::arg("x"), py::arg("state"),
      "Filter the columns of x (T, C) through the second-order sections (S, 6) from the initial "
      "state (S, 2, C) (transposed direct form II, as scipy.signal.sosfilt with zi); returns "
      "(y, final state).");
}

}  // namespace dynid::binding
