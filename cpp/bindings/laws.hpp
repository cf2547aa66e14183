// Binding of the physical laws' one home in the core (issue 19, item 3): the drive friction
// (smoothed, and split by term), the elastic joints' motor equation and the world frames of all
// links, each batched over samples in C++ with the GIL released. Private functions of dynid._core
// (underscore names), called by the Python package.
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

namespace py = pybind11;

void bind_laws(py::module_& m);

}  // namespace dynid::binding
