// Binding of the closed-loop simulator (dynid.sim.simulate calls dynid._core._simulate).
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

void bind_simulator(pybind11::module_& m);

}  // namespace dynid::binding
