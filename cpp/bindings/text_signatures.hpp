// __text_signature__ for the bound functions, so that inspect.signature, help() and editors that
// introspect (rather than read _core.pyi) see the parameter names.
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::binding {

// Call last in PYBIND11_MODULE: gives every non-overloaded function of the module and every
// method of its classes a text signature ("name(self, q, qd, qdd)\n--\n\n" before the docstring),
// derived from the signature pybind11 wrote. Functions whose defaults are not plain literals are
// left as they are.
void add_text_signatures(pybind11::module_& m);

}  // namespace dynid::binding
