// Binding of the second-order-section filter (dynid/sos_filter.hpp) that dynid.signal's
// zero-phase low-pass runs on.
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

namespace py = pybind11;

void bind_signal(py::module_& m);

}  // namespace dynid::binding
