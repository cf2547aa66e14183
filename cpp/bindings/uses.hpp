// Bindings of the uses of the model (SPEC section 8): analytic RNEA derivatives, the Jacobian's
// time derivative (methods added to the existing Model class) and the momentum observer.
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

namespace py = pybind11;

// After bind_model: adds rnea_derivatives and jacobian_dot to m.Model, and m.MomentumObserver.
void bind_uses(py::module_& m);

}  // namespace dynid::binding
