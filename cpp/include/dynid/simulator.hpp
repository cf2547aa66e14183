// Closed-loop simulation at a controller rate (notes, "State equations" and "Dynamic simulation"):
// the state x = (q, qd) follows xd = (qd, M(q)^-1 (tau - c(q, qd) - g(q) - F(qd))), integrated with
// a fixed step, while a controller computes tau once per control period from the measured state and
// holds it (zero-order hold) over `substeps` integration steps.
//
// A Simulator owns every buffer a run needs (its Workspace, the integrator's stages, the noise
// generator): after construction a run touches the heap only to call a user's controller.
#pragma once

#include <cstdint>
#include <random>

#include "dynid/model.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

enum class Integrator {
  RungeKutta4,  // classical fourth-order Runge-Kutta, global error O(h^4)
  // qd += h qdd(q, qd); q += h qd, global error O(h); symplectic (bounded energy error) when M
  // is constant, nearly so otherwise (docs: simulation part of uses.md)
  SemiImplicitEuler,
};

struct SimulationSettings {
  double dt = 1e-3;  // control period [s]: the controller runs at 1 / dt
  int substeps = 1;  // integration steps per control period, h = dt / substeps
  Integrator integrator = Integrator::RungeKutta4;
  // Plant friction Fv qd + Fs tanh(qd / coulomb_band) from the model's Fv, Fs. The smoothing
  // band [rad/s or m/s] keeps the right-hand side Lipschitz, so a fixed-step integrator does not
  // chatter around qd = 0; 0 gives the exact sign(qd) of docs/conventions.md,
  // "Drive terms and the torque model". Explicit integration of the band's slope Fs / band is
  // stable for roughly h < 2.8 M_ii band / Fs_i (RK4).
  bool friction = true;
  double coulomb_band = 1e-3;
  // Standard deviation [N m or N] of white noise added to the commanded torque, one draw per
  // joint and control period (held with the torque).
  double torque_noise = 0.0;
  // Encoder resolution in counts per revolution (revolute joints; counts per metre for prismatic
  // ones), 0 or >= 1; 0: the controller sees the exact state. With an encoder the controller gets
  // the quantised position and the backward difference of the quantised positions as velocity.
  double encoder_counts = 0.0;
  std::uint64_t seed = 0;
};

// The control law: called once per control period k (t = k dt) with the measured state.
class Controller {
 public:
  virtual ~Controller() = default;
  virtual void command(int k, double t, const VectorIn& q, const VectorIn& qd, VectorOut tau) = 0;
};

// Where a run writes its samples: (periods + 1) x n row-major blocks, row k at t = k dt (row 0
// the initial state). qdd is the acceleration at the start of each period (with the held torque);
// tau the commanded torque (before noise). q_measured may have 0 rows (not recorded).
struct SimulationOutput {
  RowMajorOut q, qd, qdd, tau, q_measured;
};

class Simulator {
 public:
  // Keeps a reference to `plant`, which must outlive the Simulator. Throws std::invalid_argument
  // naming the setting when one is out of range.
  Simulator(const Model& plant, const SimulationSettings& settings);

  // Runs `periods` control periods from (q0, qd0). Throws std::invalid_argument naming the
  // argument on a size mismatch, std::runtime_error when the state stops being finite (too large
  // a step for the gains or the friction band).
  void run(Controller& controller, const VectorIn& q0, const VectorIn& qd0, int periods,
           SimulationOutput& out);

  // The plant's state equation: qdd = M(q)^-1 (tau - c - g - F(qd)), F as in the settings.
  void acceleration(const VectorIn& q, const VectorIn& qd, const VectorIn& tau, VectorOut qdd);

  const SimulationSettings& settings() const { return settings_; }

 private:
  void step_rk4(double h);
  void step_semi_implicit_euler(double h);
  void measure(int k);

  const Model& plant_;
  SimulationSettings settings_;
  Workspace ws_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_;
  double resolution_[2];  // encoder step for revolute, prismatic joints (0: exact)
  // State, held torque, the measured state given to the controller and the integrator's stages.
  VectorX q_, qd_, tau_, tau_applied_, q_meas_, q_meas_prev_, qd_meas_;
  VectorX a1_, a2_, a3_, a4_, q_stage_, qd_stage_, v_sum_;
};

}  // namespace dynid
