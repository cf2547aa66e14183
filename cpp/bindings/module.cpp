// dynid._core: the C++ core seen from Python. Nothing but conversions lives in this folder.
#include <pybind11/pybind11.h>

#include "model.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() = "dynid C++ core (use the dynid package, not this module)";
  dynid::binding::bind_model(m);
}
