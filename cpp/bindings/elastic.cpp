// Binding of the elastic-joint simulator (the whole run in C++ without the GIL; a Python
// controller takes it back for its call only). rnea_time_derivatives is an entry of
// call_table.hpp.
#include "elastic.hpp"

#include <memory>
#include <string>

#include "arrays.hpp"
#include "dynid/elastic_simulator.hpp"
#include "dynid/kuka_like_controller.hpp"
#include "interruptible.hpp"
#include "model.hpp"

namespace dynid::binding {
namespace {

// controller(t, q, qd, theta, thetad, tau_J) -> tau, called with the GIL held.
class PythonElasticController : public ElasticController {
 public:
  PythonElasticController(py::object function, int n) : function_(std::move(function)), n_(n) {}

  void command(int, double t, const VectorIn& q, const VectorIn& qd, const VectorIn& theta,
               const VectorIn& thetad, const VectorIn& tau_J, VectorOut tau) override {
    py::gil_scoped_acquire gil;
    const auto copy = [this](const VectorIn& v) {
      py::array_t<double> a(n_);
      Eigen::Map<VectorX>(a.mutable_data(), n_) = v;
      return a;
    };
    py::object result = function_(t, copy(q), copy(qd), copy(theta), copy(thetad), copy(tau_J));
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

// Zero motor torque: free motion.
class ZeroTorque : public ElasticController {
 public:
  void command(int, double, const VectorIn&, const VectorIn&, const VectorIn&, const VectorIn&,
               const VectorIn&, VectorOut tau) override {
    tau.setZero();
  }
};

VectorX vector_argument(py::handle obj, const char* name, int n) {
  const Array a = parse_fixed(obj, name, {n});
  return Eigen::Map<const VectorX>(a.data(), n);
}

ElasticDrives drives_argument(py::handle K, py::handle B, py::handle Fv, py::handle Fs, int n) {
  return ElasticDrives{vector_argument(K, "stiffness", n), vector_argument(B, "motor_inertia", n),
                       vector_argument(Fv, "motor_viscous", n),
                       vector_argument(Fs, "motor_coulomb", n)};
}

// Runs the simulator without the GIL from the initial state; returns q, qd, theta, thetad, tau,
// tau_J, each (periods + 1, n).
py::tuple run_elastic(ElasticSimulator& simulator, ElasticController& controller, int n,
                      py::handle q0, py::handle qd0, py::handle theta0, py::handle thetad0,
                      int periods) {
  const VectorX x_q = vector_argument(q0, "q0", n), x_qd = vector_argument(qd0, "qd0", n);
  const VectorX x_th = vector_argument(theta0, "theta0", n),
                x_thd = vector_argument(thetad0, "thetad0", n);
  const py::ssize_t rows = static_cast<py::ssize_t>(periods) + 1, cols = n;
  py::array_t<double> q({rows, cols}), qd({rows, cols}), th({rows, cols}), thd({rows, cols}),
      tau({rows, cols}), tau_J({rows, cols});
  ElasticSimulationOutput out{
      RowMajorMap(q.mutable_data(), rows, n),   RowMajorMap(qd.mutable_data(), rows, n),
      RowMajorMap(th.mutable_data(), rows, n),  RowMajorMap(thd.mutable_data(), rows, n),
      RowMajorMap(tau.mutable_data(), rows, n), RowMajorMap(tau_J.mutable_data(), rows, n)};
  InterruptibleElastic interruptible(controller);  // Ctrl-C stops a long run
  {
    py::gil_scoped_release release;
    simulator.run(interruptible, x_q, x_qd, x_th, x_thd, periods, out);
  }
  return py::make_tuple(q, qd, th, thd, tau, tau_J);
}

// A (rows, n) block of the reference or of tau_user.
Array block_argument(py::handle obj, const char* name, py::ssize_t rows, int n) {
  return parse_fixed(obj, name, {rows, static_cast<py::ssize_t>(n)});
}

}  // namespace

void bind_elastic(py::module_& m) {
  m.def(
      "_simulate_elastic",
      [](PyModel& links, py::handle K, py::handle B, py::handle Fv, py::handle Fs, py::handle q0,
         py::handle qd0, py::handle theta0, py::handle thetad0, int periods, double dt,
         int substeps, double coulomb_band, const std::string& kind, py::handle kp, py::handle kd,
         py::handle q_d, py::object function) {
        const int n = links.model->n();
        if (periods < 1) throw py::value_error("duration: expected at least one control period");
        std::shared_ptr<const Model> model = links.model;
        const ElasticDrives drives = drives_argument(K, B, Fv, Fs, n);
        ElasticSimulator simulator(*model, drives, dt, substeps, coulomb_band);
        std::unique_ptr<ElasticController> controller;
        if (kind == "callable")
          controller = std::make_unique<PythonElasticController>(function, n);
        else if (kind == "motor_pd")
          controller = std::make_unique<MotorPDController>(
              *model, drives, vector_argument(kp, "kp", n), vector_argument(kd, "kd", n),
              vector_argument(q_d, "q_d", n));
        else if (kind == "none")
          controller = std::make_unique<ZeroTorque>();
        else
          throw py::value_error("controller: unknown kind '" + kind + "'");
        return run_elastic(simulator, *controller, n, q0, qd0, theta0, thetad0, periods);
      },
      py::arg("links"), py::arg("stiffness"), py::arg("motor_inertia"), py::arg("motor_viscous"),
      py::arg("motor_coulomb"), py::arg("q0"), py::arg("qd0"), py::arg("theta0"),
      py::arg("thetad0"), py::arg("periods"), py::arg("dt"), py::arg("substeps"),
      py::arg("coulomb_band"), py::arg("kind"), py::arg("kp"), py::arg("kd"), py::arg("q_d"),
      py::arg("function"),
      "Closed-loop simulation of an elastic-joint robot (use dynid.sim.simulate_elastic): returns "
      "q, qd, theta, thetad, tau, tau_J, each (periods + 1, n).");

  m.def(
      "_simulate_elastic_kuka",
      [](PyModel& links, py::handle K, py::handle B, py::handle Fv, py::handle Fs, py::handle q0,
         py::handle qd0, py::handle theta0, py::handle thetad0, int periods, double dt,
         int substeps, double coulomb_band, PyModel& model, py::handle model_stiffness,
         py::handle kp, py::handle kd, py::handle torque_gain, py::handle torque_damping,
         const std::string& gravity, py::handle q_d, py::handle qd_d, py::handle tau_user) {
        const int n = links.model->n();
        if (periods < 1) throw py::value_error("duration: expected at least one control period");
        if (model.model->n() != n)
          throw py::value_error("model: expected the controller's model with " + std::to_string(n) +
                                " joints, got " + std::to_string(model.model->n()));
        std::shared_ptr<const Model> plant = links.model, controller_model = model.model;
        const ElasticDrives drives = drives_argument(K, B, Fv, Fs, n);
        ElasticSimulator simulator(*plant, drives, dt, substeps, coulomb_band);
        const py::ssize_t rows = static_cast<py::ssize_t>(periods) + 1;
        const Array q_ref = block_argument(q_d, "reference", rows, n);
        const Array qd_ref = block_argument(qd_d, "reference", rows, n);
        Array user;
        if (!tau_user.is_none()) user = block_argument(tau_user, "tau_user", rows, n);
        const ReferenceTrajectory reference{q_ref.data(), qd_ref.data(), nullptr,
                                            static_cast<int>(rows), n};
        const KukaLikeGains gains{vector_argument(kp, "kp", n), vector_argument(kd, "kd", n),
                                  vector_argument(torque_gain, "torque_gain", n),
                                  vector_argument(torque_damping, "torque_damping", n)};
        GravityCompensation compensation;
        if (gravity == "desired")
          compensation = GravityCompensation::Desired;
        else if (gravity == "static")
          compensation = GravityCompensation::Static;
        else
          throw py::value_error("gravity: expected 'static' or 'desired', got '" + gravity + "'");
        KukaLikeController controller(
            *controller_model, vector_argument(model_stiffness, "stiffness", n), gains,
            compensation, reference, tau_user.is_none() ? nullptr : user.data());
        return run_elastic(simulator, controller, n, q0, qd0, theta0, thetad0, periods);
      },
      py::arg("links"), py::arg("stiffness"), py::arg("motor_inertia"), py::arg("motor_viscous"),
      py::arg("motor_coulomb"), py::arg("q0"), py::arg("qd0"), py::arg("theta0"),
      py::arg("thetad0"), py::arg("periods"), py::arg("dt"), py::arg("substeps"),
      py::arg("coulomb_band"), py::arg("model"), py::arg("model_stiffness"), py::arg("kp"),
      py::arg("kd"), py::arg("torque_gain"), py::arg("torque_damping"), py::arg("gravity"),
      py::arg("q_d"), py::arg("qd_d"), py::arg("tau_user"),
      "Elastic-joint simulation under the KUKA-like joint torque controller (use "
      "dynid.sim.simulate_elastic with dynid.sim.KukaLike): returns q, qd, theta, thetad, tau, "
      "tau_J, each (periods + 1, n).");
}

}  // namespace dynid::binding
