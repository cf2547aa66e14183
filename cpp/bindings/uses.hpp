// Binding of the momentum observer (docs/uses.md; the other uses, rnea_derivatives and
// jacobian_dot, are Model calls of call_table.hpp).
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

namespace py = pybind11;

// m.MomentumObserver (after bind_model: its constructor takes a Model).
void bind_uses(py::module_& m);

}  // namespace dynid::binding
