// Binding of the MomentumObserver of docs/uses.md (update per sample, run over a log with the
// GIL released); section 8's rnea_derivatives and jacobian_dot are entries of call_table.hpp.
#include "uses.hpp"

#include <memory>
#include <stdexcept>
#include <string>

#include "arrays.hpp"
#include "model.hpp"
#include "object_lock.hpp"

namespace dynid::binding {
namespace {

// The observer with the model snapshot it was built from (for its n in the argument checks).
struct PyMomentumObserver {
  std::unique_ptr<MomentumObserver> observer;
};

VectorX parse_gain(py::handle obj, int n) {
  Array a = as_real_array(obj, "gain");
  if (!(a.ndim() == 0 || (a.ndim() == 1 && a.shape(0) == n)))
    throw py::value_error("gain: expected a number or shape (" + std::to_string(n) + ",), got " +
                          shape_string(a));
  require_finite(a, "gain");
  const VectorX gain =
      a.ndim() == 0 ? VectorX::Constant(n, a.data()[0]) : VectorX(ConstVec(a.data(), n));
  if (!(gain.minCoeff() > 0.0))
    throw py::value_error("gain: expected values > 0 (1/s), got a minimum of " +
                          std::to_string(gain.minCoeff()));
  return gain;
}

py::array vector_copy(const VectorX& v) {
  py::array_t<double> out(v.size());
  std::copy(v.data(), v.data() + v.size(), out.mutable_data());
  return out;
}

}  // namespace

void bind_uses(py::module_& m) {
  py::class_<PyMomentumObserver>(m, "MomentumObserver", R"doc(
Generalized-momentum collision residual (De Luca & Mattone 2005):
r = K_O (p(t) - p(0) - int (tau + S^T qd - g - F(qd) + r) dt), p = M(q) qd.

r tracks the external joint torque J^T F_ext through a first-order filter of time constant
1 / gain and stays zero (to the model and integration error) without contact. Discretised with
the trapezoidal rule, r implicit (Tustin). The robot's model is copied at construction.

Parameters: robot, gain (K_O > 0 in 1/s: a number or one per joint), dt (sample period, s).
Calls on one observer from several threads run one after the other (run() releases the GIL but
keeps the observer to itself); use one observer per thread to run in parallel.
)doc")
      .def(py::init([](PyModel& robot, py::handle gain, py::handle dt) {
             const double period = parse_number(dt, "dt");
             if (!std::isfinite(period) || !(period > 0.0))
               throw py::value_error("dt: expected a finite sample period > 0 (s), got " +
                                     std::string(py::repr(dt)));
             const VectorX K = parse_gain(gain, robot.model->n());
             return PyMomentumObserver{std::make_unique<MomentumObserver>(*robot.model, K, period)};
           }),
           py::arg("robot"), py::arg("gain"), py::arg("dt"))
      .def_property_readonly(
          "n", [](const PyMomentumObserver& self) { return self.observer->model().n(); })
      .def_property_readonly(
          "gain", [](const PyMomentumObserver& self) { return vector_copy(self.observer->gain()); },
          "K_O per joint (n,), 1/s.")
      .def_property_readonly("dt",
                             [](const PyMomentumObserver& self) { return self.observer->dt(); })
      .def_property_readonly(
          "residual",
          [](const PyMomentumObserver& self) {
            const auto lock = lock_object(&self);
            return vector_copy(self.observer->residual());
          },
          "The last residual r (n,).")
      .def_property_readonly(
          "samples",
          [](const PyMomentumObserver& self) {
            const auto lock = lock_object(&self);
            return self.observer->samples();
          },
          "Samples seen since construction or reset().")
      .def(
          "reset",
          [](PyMomentumObserver& self) {
            const auto lock = lock_object(&self);
            self.observer->reset();
          },
          "Forget the history: the next sample starts a new integral (r = 0, p(0) = M q̇).")
      .def(
          "update",
          [](PyMomentumObserver& self, py::handle q, py::handle qd, py::handle tau) {
            const int n = self.observer->model().n();
            const Samples s = parse_samples({{q, "q"}, {qd, "qd"}, {tau, "tau"}}, n);
            if (!s.single)
              throw py::value_error("q: expected shape (" + std::to_string(n) +
                                    ",) (one sample; run() takes a log)");
            py::array_t<double> r(n);
            OutVec out(r.mutable_data(), n);
            const auto lock = lock_object(&self);
            self.observer->update(ConstVec(s.row(0, 0, n), n), ConstVec(s.row(1, 0, n), n),
                                  ConstVec(s.row(2, 0, n), n), out);
            require_finite_result(r.data(), n, s.names.c_str());
            return r;
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"),
          "One sample (n,) each of measured q, qd and motor torque tau: the residual r (n,).")
      .def(
          "run",
          [](PyMomentumObserver& self, py::handle q, py::handle qd, py::handle tau) {
            const int n = self.observer->model().n();
            const Samples s = parse_samples({{q, "q"}, {qd, "qd"}, {tau, "tau"}}, n);
            if (s.single)
              throw py::value_error("q: expected shape (T, " + std::to_string(n) +
                                    ") (a log; update() takes one sample)");
            py::array_t<double> r({s.count, static_cast<py::ssize_t>(n)});
            double* data = r.mutable_data();
            const auto lock = lock_object(&self);  // the whole log, one thread at a time
            {
              py::gil_scoped_release release;
              for (py::ssize_t t = 0; t < s.count; ++t) {
                OutVec out(data + t * n, n);
                self.observer->update(ConstVec(s.row(0, t, n), n), ConstVec(s.row(1, t, n), n),
                                      ConstVec(s.row(2, t, n), n), out);
              }
            }
            require_finite_result(data, s.count * n, s.names.c_str());
            return r;
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"),
          "The residual (T, n) over a log (T, n) each, sample by sample in C++ with the GIL "
          "released, "
          "continuing from the current state (call reset() first for a new log).");
}

}  // namespace dynid::binding
