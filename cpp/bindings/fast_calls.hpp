// Single-sample fast path of the hottest calls (fast_calls.cpp).
#pragma once

#include "model.hpp"

namespace dynid::binding {

// Replaces Model.rnea, mass_matrix and gravity by vectorcall methods that handle positional
// single-sample float64 vectors themselves and pass every other call to the pybind11 method
// (kept as Model._rnea_full, ...). Call after bind_model.
void bind_fast_calls(py::module_& m);

}  // namespace dynid::binding
