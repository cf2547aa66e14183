// Binding of dynid::RecursiveLeastSquares as dynid._core.RecursiveLeastSquares.
#pragma once

#include <pybind11/pybind11.h>

#include "dynid/recursive_least_squares.hpp"
#include "initialised.hpp"

namespace dynid::binding {

void bind_recursive_least_squares(pybind11::module_& m);

}  // namespace dynid::binding

// `self` must have been initialised (initialised.hpp).
template <>
struct pybind11::detail::type_caster<dynid::RecursiveLeastSquares>
    : dynid::binding::initialised_caster<dynid::RecursiveLeastSquares> {};
