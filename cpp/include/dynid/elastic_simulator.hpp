// Closed-loop simulation of a robot with elastic joints (Spong's model, paper eqs. (1)-(3), notes
// p. 16) at a controller rate. The state x = (q, theta, qd, thetad) follows
//   qdd     = M(q)^-1 (K (theta - q) - c(q, qd) - g(q))                 link equation
//   thetadd = B^-1 (tau - K (theta - q) - Fv_m thetad - Fs_m s(thetad))  motor equation
// with s(x) = tanh(x / coulomb_band) (sign(x) for a zero band), integrated by classical RK4 with a
// fixed step h = dt / substeps while the controller's torque is held over each period dt.
// The link model's own drive terms (Ia, Fv, Fs) are ignored: the motor inertia and friction act
// on theta (docs/elastic.md). After construction a run touches the heap only to call a user's
// controller.
#pragma once

#include "dynid/elastic_motor.hpp"  // ElasticDrives and the motor equation
#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// Called once per control period k (t = k dt) with the exact link and motor state and the elastic
// torque tau_J = K (theta - q) (what the joint torque sensors measure).
class ElasticController {
 public:
  virtual ~ElasticController() = default;
  virtual void command(int k, double t, const VectorIn& q, const VectorIn& qd,
                       const VectorIn& theta, const VectorIn& thetad, const VectorIn& tau_J,
                       VectorOut tau) = 0;
};

// Motor PD with constant gravity compensation for a set-point q_d (Tomei 1991; De Luca,
// Siciliano, Zollo 2005): tau = Kp (theta_d - theta) - Kd thetad + g(q_d), theta_d = q_d +
// K^-1 g(q_d). Asymptotically stable for Kp large enough w.r.t. the gravity gradient.
class MotorPDController : public ElasticController {
 public:
  // g(q_d) is evaluated with `links` once, here.
  MotorPDController(const Model& links, const ElasticDrives& drives, const VectorIn& kp,
                    const VectorIn& kd, const VectorIn& q_d);
  void command(int k, double t, const VectorIn& q, const VectorIn& qd, const VectorIn& theta,
               const VectorIn& thetad, const VectorIn& tau_J, VectorOut tau) override;

 private:
  VectorX kp_, kd_, theta_d_, gravity_;
};

// Where a run writes its samples: (periods + 1) x n row-major blocks, row k at t = k dt.
struct ElasticSimulationOutput {
  RowMajorOut q, qd, theta, thetad, tau, tau_J;
};

class ElasticSimulator {
 public:
  // Keeps references to `links` and `drives`, which must outlive the simulator. Throws
  // std::invalid_argument naming the drive or setting that is out of range.
  ElasticSimulator(const Model& links, const ElasticDrives& drives, double dt, int substeps,
                   double coulomb_band);

  // Runs `periods` control periods from (q0, qd0, theta0, thetad0). std::invalid_argument naming
  // the argument on a size mismatch; std::runtime_error when the state stops being finite.
  void run(ElasticController& controller, const VectorIn& q0, const VectorIn& qd0,
           const VectorIn& theta0, const VectorIn& thetad0, int periods,
           ElasticSimulationOutput& out);

  // xd = f(x, tau) for x = (q, theta, qd, thetad), 4n each.
  void rate(const VectorIn& x, const VectorIn& tau, VectorOut xd);

 private:
  const Model& links_;
  const ElasticDrives& drives_;
  double dt_, coulomb_band_;
  int substeps_;
  Workspace workspace_;
  VectorX x_, tau_, tau_J_, k1_, k2_, k3_, k4_, stage_;
};

}  // namespace dynid
