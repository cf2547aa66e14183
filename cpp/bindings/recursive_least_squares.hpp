// Binding of dynid::RecursiveLeastSquares as dynid._core.RecursiveLeastSquares.
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

void bind_recursive_least_squares(pybind11::module_& m);

}  // namespace dynid::binding
