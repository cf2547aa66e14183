// Proof that a Simulator run touches the heap only when it is constructed, whatever the
// controller, integrator and options, and that the runs it makes are right (so that a broken run
// allocating nothing cannot pass).
//
// A 7-dof arm with the KUKA LWR-IV's DH table (paper Table I), physically consistent links, rotor
// inertias and friction is simulated for 1000 control periods with each built-in controller,
// both integrators, friction, torque noise and an encoder, with every operator new and malloc
// counted (cpp/examples/allocation_counter.hpp). Exit status 1 if any allocation happened during
// the runs, 2 if a check of the results fails, 3 if the counters do not see a deliberate
// allocation.
//
// Build (tests/test_simulator.py does this and runs it):
//   g++ -O3 -DNDEBUG -std=c++17 -I cpp/include -I cpp/examples -I <eigen3>
//       tests/cpp/test_simulator_no_allocation.cpp cpp/src/*.cpp
#include <cmath>
#include <cstdio>
#include <vector>

#include "dynid/dynid.hpp"

#include "allocation_counter.hpp"  // cpp/examples/
#include "test_support.hpp"

namespace {

using namespace dynid;
using RowMajorMap = Eigen::Map<RowMajorMatrixX>;

constexpr int kJoints = 7;
constexpr int kPeriods = 1000;
constexpr double kPi = 3.141592653589793;

Model lwr_like() {
  const double alpha[kJoints] = {kPi / 2, -kPi / 2, -kPi / 2, kPi / 2, kPi / 2, -kPi / 2, 0.0};
  const double d[kJoints] = {0.0, 0.0, 0.4, 0.0, 0.39, 0.0, 0.0};
  std::vector<DHRow> rows;
  for (int i = 0; i < kJoints; ++i)
    rows.push_back(DHRow{0.0, alpha[i], d[i], 0.0, JointType::Revolute});
  Model model(rows, Convention::Standard);
  for (int i = 0; i < kJoints; ++i) {
    const double mass = 3.0 - 0.35 * i;
    const Vector3 com(0.002 * i, -0.03 + 0.01 * i, 0.05 - 0.004 * i);
    const Matrix3 inertia =
        Vector3(0.02 - 0.002 * i, 0.018 - 0.002 * i, 0.01 - 0.001 * i).asDiagonal();
    model.set_link(i, RigidBodyParameters::from_physical(mass, com, inertia));
  }
  VectorX Ia(kJoints), Fv(kJoints), Fs(kJoints);
  Ia << 0.32, 0.30, 0.21, 0.19, 0.11, 0.08, 0.07;
  Fv << 0.90, 0.85, 0.55, 0.50, 0.30, 0.25, 0.15;
  Fs << 1.10, 1.00, 0.60, 0.55, 0.45, 0.35, 0.20;
  model.set_rotor_inertia(Ia);
  model.set_viscous_friction(Fv);
  model.set_coulomb_friction(Fs);
  return model;
}

struct Buffers {
  std::vector<double> q, qd, qdd, tau, q_measured;
  explicit Buffers(int rows)
      : q(rows * kJoints),
        qd(rows * kJoints),
        qdd(rows * kJoints),
        tau(rows * kJoints),
        q_measured(rows * kJoints) {}
  SimulationOutput output(int rows) {
    return SimulationOutput{
        RowMajorMap(q.data(), rows, kJoints), RowMajorMap(qd.data(), rows, kJoints),
        RowMajorMap(qdd.data(), rows, kJoints), RowMajorMap(tau.data(), rows, kJoints),
        RowMajorMap(q_measured.data(), rows, kJoints)};
  }
};

}  // namespace

int main() {
  if (!allocation_counter_works(kJoints)) return 3;

  const Model plant = lwr_like();
  const int rows = kPeriods + 1;
  // A reference trajectory (paper eq. (33)) sampled at 1 kHz, row-major as NumPy hands it over.
  std::vector<double> q_d(rows * kJoints), qd_d(rows * kJoints), qdd_d(rows * kJoints);
  const double w = kPi / 7.0;
  for (int k = 0; k < rows; ++k)
    for (int i = 0; i < kJoints; ++i) {
      const double t = k * 1e-3;
      q_d[k * kJoints + i] = kPi / 2 * std::cos(w * t);
      qd_d[k * kJoints + i] = -kPi / 2 * w * std::sin(w * t);
      qdd_d[k * kJoints + i] = -kPi / 2 * w * w * std::cos(w * t);
    }
  const ReferenceTrajectory reference{q_d.data(), qd_d.data(), qdd_d.data(), rows, kJoints};
  const VectorX kp = VectorX::Constant(kJoints, 400.0), kd = VectorX::Constant(kJoints, 40.0);
  const VectorX q0 = VectorX::Constant(kJoints, kPi / 2), qd0 = VectorX::Zero(kJoints);

  PDController pd(kp, kd, reference);
  PDGravityController pd_gravity(plant, kp, kd, reference);
  ComputedTorqueController computed_torque(plant, kp, kd, reference);
  Controller* controllers[3] = {&pd, &pd_gravity, &computed_torque};

  SimulationSettings settings;
  settings.substeps = 4;
  settings.torque_noise = 0.05;
  settings.encoder_counts = 1 << 20;
  settings.seed = 7;
  SimulationSettings euler = settings;
  euler.integrator = Integrator::SemiImplicitEuler;
  Simulator rk4_sim(plant, settings), euler_sim(plant, euler);
  Buffers buffers(rows);
  SimulationOutput out = buffers.output(rows);

  counting = true;
  for (Controller* controller : controllers) {
    rk4_sim.run(*controller, q0, qd0, kPeriods, out);
    euler_sim.run(*controller, q0, qd0, kPeriods, out);
  }
  rk4_sim.run(computed_torque, q0, qd0, kPeriods, out);  // the last run is checked below
  counting = false;
  std::printf("allocations_during_runs=%ld\n", allocations);

  // Computed torque with the plant's model tracks eq. (33): error below 0.01 rad (noise 0.05 N m,
  // encoder 2^20 counts per revolution).
  double tracking = 0.0;
  for (int j = 0; j < rows * kJoints; ++j)
    tracking = std::fmax(tracking, std::fabs(buffers.q[j] - q_d[j]));
  std::printf("computed_torque_max_tracking_error=%.3e\n", tracking);

  // Free motion without friction: RK4 conserves T + U to 1e-9 of the largest kinetic energy.
  SimulationSettings free_settings;
  free_settings.friction = false;
  free_settings.dt = 1e-4;
  Simulator free_sim(plant, free_settings);
  const VectorX zero = VectorX::Zero(kJoints);
  PDController none(zero, zero, reference);
  Buffers free_buffers(rows);
  SimulationOutput free_out = free_buffers.output(rows);
  const VectorX q_start = VectorX::Constant(kJoints, 0.3);
  const VectorX qd_start = VectorX::Constant(kJoints, 0.5);
  counting = true;
  free_sim.run(none, q_start, qd_start, kPeriods, free_out);
  counting = false;
  Workspace ws(plant);
  double e0 = 0.0, drift = 0.0, t_max = 0.0;
  for (int k = 0; k < rows; ++k) {
    const Eigen::Map<const VectorX> q(free_buffers.q.data() + k * kJoints, kJoints);
    const Eigen::Map<const VectorX> qd(free_buffers.qd.data() + k * kJoints, kJoints);
    const double kinetic = kinetic_energy(plant, ws, q, qd);
    const double e = kinetic + potential_energy(plant, ws, q);
    if (k == 0) e0 = e;
    drift = std::fmax(drift, std::fabs(e - e0));
    t_max = std::fmax(t_max, kinetic);
  }
  std::printf("allocations_total=%ld\nrelative_energy_drift=%.3e\n", allocations, drift / t_max);

  if (allocations != 0) return 1;
  if (!(tracking < 1e-2) || !(drift < 1e-9 * t_max)) return 2;
  return 0;
}
