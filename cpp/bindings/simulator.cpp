// Binding of the Simulator: converts and checks the arrays, builds the controller and runs the
// whole simulation in C++ with the GIL released; a Python controller takes the GIL back only for
// its call, once per control period.
#include "simulator.hpp"

#include <memory>
#include <string>

#include "arrays.hpp"
#include "dynid/controllers.hpp"
#include "dynid/simulator.hpp"
#include "interruptible.hpp"
#include "model.hpp"

namespace dynid::binding {
namespace {

using RowMajorMap = Eigen::Map<RowMajorMatrixX>;

// controller(t, q, qd) -> tau, called with the GIL held; the result is checked like any input.
class PythonController : public Controller {
 public:
  PythonController(py::object function, int n) : function_(std::move(function)), n_(n) {}

  void command(int, double t, const VectorIn& q, const VectorIn& qd, VectorOut tau) override {
    py::gil_scoped_acquire gil;
    py::array_t<double> q_arg(n_), qd_arg(n_);
    Eigen::Map<VectorX>(q_arg.mutable_data(), n_) = q;
    Eigen::Map<VectorX>(qd_arg.mutable_data(), n_) = qd;
    py::object result = function_(t, q_arg, qd_arg);
    const Array a = as_real_array(result, "controller");
    if (a.ndim() != 1 || a.shape(0) != n_)
      throw py::value_error("controller: expected the callable to return " + std::to_string(n_) +
                            " torques, shape (" + std::to_string(n_) + ",), got shape " +
                            shape_string(a) + " at t = " + std::to_string(t) + " s");
    require_finite(a, "controller");
    tau = Eigen::Map<const VectorX>(a.data(), n_);
  }

 private:
  py::object function_;
  int n_;
};

Integrator parse_integrator(const std::string& method) {
  if (method == "rk4") return Integrator::RungeKutta4;
  if (method == "euler") return Integrator::SemiImplicitEuler;
  throw py::value_error("method: expected 'rk4' or 'euler' (semi-implicit), got '" + method + "'");
}

// A (rows, n) reference array, or zeros when None (e.g. no qdd_d for a PD law).
Array reference_block(py::handle obj, const char* name, py::ssize_t rows, int n) {
  if (obj.is_none()) {
    Array zeros({rows, static_cast<py::ssize_t>(n)});
    std::fill(zeros.mutable_data(), zeros.mutable_data() + zeros.size(), 0.0);
    return zeros;
  }
  return parse_fixed(obj, name, {rows, n});
}

}  // namespace

void bind_simulator(py::module_& m) {
  m.def(
      "_simulate",
      [](PyModel& plant, py::handle q0_obj, py::handle qd0_obj, int periods, double dt,
         int substeps, const std::string& method, bool friction, double coulomb_band,
         double torque_noise, double encoder_counts, std::uint64_t seed, const std::string& kind,
         py::object model_obj, py::handle kp_obj, py::handle kd_obj, py::handle q_d_obj,
         py::handle qd_d_obj, py::handle qdd_d_obj, py::object function, bool record_measured) {
        const int n = plant.model->n();
        if (periods < 1) throw py::value_error("duration: expected at least one control period");
        const py::ssize_t rows = static_cast<py::ssize_t>(periods) + 1;
        const Array q0 = parse_fixed(q0_obj, "q0", {n});
        const Array qd0 = parse_fixed(qd0_obj, "qd0", {n});
        SimulationSettings settings;
        settings.dt = dt;
        settings.substeps = substeps;
        settings.integrator = parse_integrator(method);
        settings.friction = friction;
        settings.coulomb_band = coulomb_band;
        settings.torque_noise = torque_noise;
        settings.encoder_counts = encoder_counts;
        settings.seed = seed;
        std::shared_ptr<const Model> plant_model = plant.model;
        std::shared_ptr<const Model> controller_model;
        if (!model_obj.is_none()) controller_model = model_obj.cast<PyModel&>().model;

        std::unique_ptr<Controller> controller;
        Array kp, kd, q_d, qd_d, qdd_d;
        if (kind == "callable") {
          controller = std::make_unique<PythonController>(function, n);
        } else {
          kp = parse_fixed(kp_obj, "kp", {n});
          kd = parse_fixed(kd_obj, "kd", {n});
          q_d = reference_block(q_d_obj, "reference", rows, n);
          qd_d = reference_block(qd_d_obj, "reference", rows, n);
          qdd_d = reference_block(qdd_d_obj, "reference", rows, n);
          const ReferenceTrajectory reference{q_d.data(), qd_d.data(), qdd_d.data(),
                                              static_cast<int>(rows), n};
          const Eigen::Map<const VectorX> Kp(kp.data(), n), Kd(kd.data(), n);
          if (kind == "pd") {
            controller = std::make_unique<PDController>(Kp, Kd, reference);
          } else if (kind == "pd_gravity" || kind == "computed_torque") {
            if (!controller_model || controller_model->n() != n)
              throw py::value_error("model: expected the controller's Robot with " +
                                    std::to_string(n) + " joints");
            if (kind == "pd_gravity")
              controller =
                  std::make_unique<PDGravityController>(*controller_model, Kp, Kd, reference);
            else
              controller =
                  std::make_unique<ComputedTorqueController>(*controller_model, Kp, Kd, reference);
          } else {
            throw py::value_error("controller: unknown kind '" + kind + "'");
          }
        }

        Simulator simulator(*plant_model, settings);
        const auto cols = static_cast<py::ssize_t>(n);
        py::array_t<double> q({rows, cols}), qd({rows, cols}), qdd({rows, cols}), tau({rows, cols});
        py::array_t<double> q_measured({record_measured ? rows : py::ssize_t{0}, cols});
        SimulationOutput out{
            RowMajorMap(q.mutable_data(), rows, n), RowMajorMap(qd.mutable_data(), rows, n),
            RowMajorMap(qdd.mutable_data(), rows, n), RowMajorMap(tau.mutable_data(), rows, n),
            RowMajorMap(q_measured.mutable_data(), q_measured.shape(0), n)};
        Interruptible interruptible(*controller);
        {
          py::gil_scoped_release release;
          simulator.run(interruptible, Eigen::Map<const VectorX>(q0.data(), n),
                        Eigen::Map<const VectorX>(qd0.data(), n), periods, out);
        }
        py::object measured = record_measured ? py::object(q_measured) : py::object(py::none());
        return py::make_tuple(q, qd, qdd, tau, measured);
      },
      py::arg("plant"), py::arg("q0"), py::arg("qd0"), py::arg("periods"), py::arg("dt"),
      py::arg("substeps"), py::arg("method"), py::arg("friction"), py::arg("coulomb_band"),
      py::arg("torque_noise"), py::arg("encoder_counts"), py::arg("seed"), py::arg("kind"),
      py::arg("model"), py::arg("kp"), py::arg("kd"), py::arg("q_d"), py::arg("qd_d"),
      py::arg("qdd_d"), py::arg("function"), py::arg("record_measured"),
      "Closed-loop simulation (use dynid.sim.simulate): returns q, qd, qdd, tau and the measured "
      "q (or None), each (periods + 1, n).");
}

}  // namespace dynid::binding
