// Binding of rnea_time_derivatives (registered onto the Model class of model.cpp, single sample
// or a batch looped in C++ by evaluate(), GIL released).
#include "elastic.hpp"

#include "arrays.hpp"
#include "model.hpp"

namespace dynid::binding {

void bind_elastic(py::module_& m) {
  auto model = py::reinterpret_borrow<py::class_<PyModel>>(m.attr("Model"));
  model.def(
      "rnea_time_derivatives",
      [](PyModel& self, py::handle q, py::handle qd, py::handle qdd, py::handle qddd, py::handle qdddd) {
        const int n = self.model->n();
        const Samples s = parse_samples(
            {{q, "q"}, {qd, "qd"}, {qdd, "qdd"}, {qddd, "qddd"}, {qdddd, "qdddd"}}, n);
        // The three vectors of a sample in one block: out[..., 0, :] = tau, 1: tau_dot, 2: tau_ddot.
        py::array all = evaluate(self, s, {3, n}, [n](const Model& mdl, Workspace& ws, const double* const* in, double* out) {
          OutVec tau(out, n), tau_dot(out + n, n), tau_ddot(out + 2 * n, n);
          rnea_time_derivatives(mdl, ws, ConstVec(in[0], n), ConstVec(in[1], n), ConstVec(in[2], n),
                                ConstVec(in[3], n), ConstVec(in[4], n), tau, tau_dot, tau_ddot);
        });
        const auto part = [&](int k) {
          return s.single ? all[py::int_(k)]
                          : all[py::make_tuple(py::ellipsis(), k, py::slice())];
        };
        return py::make_tuple(part(0), part(1), part(2));
      },
      py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("qddd"), py::arg("qdddd"),
      "Inverse dynamics and its exact first and second time derivatives (tau, tau_dot, tau_ddot) "
      "along a motion with joint derivatives qd, qdd, qddd (jerk) and qdddd (snap): (n,) each, or "
      "(T, n) each for T samples (views into one (3, n) or (T, 3, n) array). tau equals rnea(q, qd, "
      "qdd) (links, gravity and drive terms); tau_dot = dtau/dq qd + dtau/dqd qdd + M qddd, "
      "tau_ddot its time derivative. Drive terms are included (Ia qddd + Fv qdd and Ia qdddd + Fv "
      "qddd); Coulomb friction is flat away from qd = 0. Use robot.rigid_body() for the links "
      "alone (the link side of ElasticRobot).");
}

}  // namespace dynid::binding
