// A batch of the core (dynid::batch, dynid::detail::run_chunks) run from Python: the GIL is
// released for it, and Ctrl-C stops it. The core's interrupt check (BatchInterrupt) takes the
// GIL on the calling thread every 20 ms and runs Python's signal handlers (PyErr_CheckSignals);
// when one raises (KeyboardInterrupt), every thread stops after its current chunk and the
// handler's exception propagates. A chunk is a few milliseconds of work, so a batch stops within
// a few tens of milliseconds.
#pragma once

#include <pybind11/pybind11.h>

#include "dynid/batch.hpp"

namespace dynid::binding {

namespace py = pybind11;

// The interrupt check: Python's signal handlers, run with the GIL taken for the moment.
inline bool python_signal_raised(void*) {
  py::gil_scoped_acquire gil;
  return PyErr_CheckSignals() != 0;
}

inline BatchInterrupt python_interrupt() { return BatchInterrupt{&python_signal_raised, nullptr}; }

// run() without the GIL (call with it held); the signal handler's exception when it stopped.
template <class Run>
batch::Report without_gil(Run run) {
  batch::Report report;
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    try {
      report = run();
    } catch (const batch::Interrupted&) {
      interrupted = true;
    }
  }
  if (interrupted) throw py::error_already_set();  // the signal handler's exception
  return report;
}

}  // namespace dynid::binding
