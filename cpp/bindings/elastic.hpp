// Binding of the C++ parts of the elastic-joint model (SPEC section 8, last bullet): the exact
// time derivatives of inverse dynamics that its flat-output inverse dynamics needs.
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

namespace py = pybind11;

// After bind_model: adds rnea_time_derivatives to m.Model.
void bind_elastic(py::module_& m);

}  // namespace dynid::binding
