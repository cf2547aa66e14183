// Binding of the elastic-joint simulator (docs/elastic.md; the exact time derivatives
// of inverse dynamics are the Model call rnea_time_derivatives of call_table.hpp).
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

namespace py = pybind11;

// _simulate_elastic and _simulate_elastic_kuka (after bind_model: they take Models).
void bind_elastic(py::module_& m);

}  // namespace dynid::binding
