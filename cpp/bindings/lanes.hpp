// Python access to the batch path selection of the core (dynid/detail/batch.hpp) and to the
// result pool, for tests.
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

namespace py = pybind11;

void bind_lanes(py::module_& m);

}  // namespace dynid::binding
