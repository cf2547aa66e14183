// Ctrl-C during a long simulation run with a built-in C++ controller: the run holds no GIL, so
// Python never gets to run its signal handlers. These wrappers of a controller do, every
// kCheckPeriods control periods: they take the GIL for a moment and call PyErr_CheckSignals; a
// KeyboardInterrupt (or any handler's exception) propagates out of the run as
// py::error_already_set. A Python controller needs no wrapper (it runs Python every period).
#pragma once

#include <pybind11/pybind11.h>

#include "dynid/elastic_simulator.hpp"
#include "dynid/simulator.hpp"

namespace dynid::binding {

namespace py = pybind11;

// Runs Python's signal handlers at the last period of every kCheckPeriods.
inline void poll_signals(int k) {
  constexpr int kCheckPeriods = 1000;
  if (k % kCheckPeriods == kCheckPeriods - 1) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}

class Interruptible : public Controller {
 public:
  explicit Interruptible(Controller& inner) : inner_(inner) {}
  void command(int k, double t, const VectorIn& q, const VectorIn& qd, VectorOut tau) override {
    poll_signals(k);
    inner_.command(k, t, q, qd, tau);
  }

 private:
  Controller& inner_;
};

class InterruptibleElastic : public ElasticController {
 public:
  explicit InterruptibleElastic(ElasticController& inner) : inner_(inner) {}
  void command(int k, double t, const VectorIn& q, const VectorIn& qd, const VectorIn& theta,
               const VectorIn& thetad, const VectorIn& tau_J, VectorOut tau) override {
    poll_signals(k);
    inner_.command(k, t, q, qd, theta, thetad, tau_J, tau);
  }

 private:
  ElasticController& inner_;
};

}  // namespace dynid::binding
