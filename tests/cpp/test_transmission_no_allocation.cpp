// Proof that a coupled transmission (Model::set_transmission, detail/drive_terms.hpp) adds no
// heap allocation per call: rnea, crba, forward_dynamics, friction, kinetic_energy,
// rnea_derivatives, rnea_time_derivatives, regressor (rotor + friction columns),
// inertia_regressor (rotor columns) and Simulator::acceleration, 10^4 calls each on a 7-joint
// arm whose last three drives are coupled (a wrist), with every operator new and (on glibc)
// malloc counted (cpp/examples/allocation_counter.hpp). Also checks that a bad transmission is a
// std::invalid_argument whose message starts with "transmission:".
// Exit status 1 on an allocation, 2 on a missing or wrong error, 3 if the counters miss a probe.
//
// Build (tests/test_transmission.py does this and runs it):
//   g++ -O1 -std=c++17 -I cpp/include -I cpp/examples -I <eigen3>
//       tests/cpp/test_transmission_no_allocation.cpp cpp/src/*.cpp
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/dynid.hpp"

#include "allocation_counter.hpp"  // cpp/examples/
#include "test_support.hpp"

namespace {

dynid::Model make_arm() {
  const int n = 7;
  std::vector<dynid::DHRow> rows(n);
  for (int i = 0; i < n; ++i) {
    rows[i].a = 0.05 * i;
    rows[i].alpha = (i % 2 ? -1.0 : 1.0) * 1.5707963267948966;
    rows[i].d = 0.1 + 0.02 * i;
    rows[i].theta = 0.1 * i;
  }
  dynid::Model model(rows, dynid::Convention::Standard);
  for (int i = 0; i < n; ++i) {
    dynid::Matrix3 inertia = dynid::Matrix3::Identity() * (0.02 + 0.001 * i);
    model.set_link(i, dynid::RigidBodyParameters::from_physical(
                          2.0 - 0.2 * i, dynid::Vector3(0.01, -0.02, 0.05), inertia));
  }
  model.set_rotor_inertia(dynid::VectorX::Constant(n, 0.1));
  model.set_viscous_friction(dynid::VectorX::Constant(n, 0.5));
  model.set_coulomb_friction(dynid::VectorX::Constant(n, 0.3));
  dynid::MatrixX T = dynid::MatrixX::Identity(n, n);
  T(5, 4) = 0.2;
  T(6, 4) = -0.15;
  T(6, 5) = 0.3;
  model.set_transmission(T);
  return model;
}

}  // namespace

int main() {
  const dynid::Model model = make_arm();
  const int n = model.n();
  if (model.transmission_is_identity()) return 2;
  dynid::Workspace ws(model);
  dynid::SimulationSettings settings;
  dynid::Simulator simulator(model, settings);
  dynid::VectorX q(n), qd(n), qdd(n), qddd(n), qdddd(n), tau(n), tau_dot(n), tau_ddot(n), f(n),
      a(n);
  dynid::MatrixX M(n, n), dq(n, n), dqd(n, n);
  dynid::RowMajorMatrixX Y(n, dynid::regressor_columns(n, true, true));
  dynid::RowMajorMatrixX Ym(n * (n + 1) / 2, 11 * n);

  if (!allocation_counter_works(n)) return 3;

  double sink = 0.0;
  counting = true;
  for (int k = 0; k < 10000; ++k) {
    const double t = 1e-3 * k;
    for (int i = 0; i < n; ++i) {
      q[i] = 0.5 * std::sin(0.7 * t + i);
      qd[i] = 0.35 * std::cos(0.7 * t + i);
      qdd[i] = -0.245 * std::sin(0.7 * t + i);
      qddd[i] = -0.1715 * std::cos(0.7 * t + i);
      qdddd[i] = 0.12005 * std::sin(0.7 * t + i);
    }
    dynid::rnea(model, ws, q, qd, qdd, tau);
    dynid::crba(model, ws, q, M);
    dynid::forward_dynamics(model, ws, q, qd, tau, a);
    dynid::friction(model, qd, f);
    sink += dynid::kinetic_energy(model, ws, q, qd);
    dynid::rnea_derivatives(model, ws, q, qd, qdd, dq, dqd);
    dynid::rnea_time_derivatives(model, ws, q, qd, qdd, qddd, qdddd, tau, tau_dot, tau_ddot);
    dynid::regressor(model, ws, q, qd, qdd, true, true, Y);
    dynid::inertia_regressor(model, ws, q, true, Ym);
    simulator.acceleration(q, qd, tau, a);
    sink += tau[0] + M(0, 0) + a[0] + f[0] + dqd(n - 1, 0) + tau_ddot[0] + Y(0, 0) + Ym(0, 0);
  }
  counting = false;
  std::printf("allocations_during_calls=%ld\n", allocations);
  if (allocations != 0 || !std::isfinite(sink)) return 1;

  dynid::Model copy = model;
  dynid::MatrixX wrong(n, n + 1), nan = dynid::MatrixX::Identity(n, n),
                                  singular = dynid::MatrixX::Identity(n, n);
  nan(1, 2) = std::numeric_limits<double>::quiet_NaN();
  singular.row(3) = singular.row(4);
  bool ok = true;
  ok &= names_argument("transmission", [&] { copy.set_transmission(wrong); });
  ok &= names_argument("transmission", [&] { copy.set_transmission(nan); });
  ok &= names_argument("transmission", [&] { copy.set_transmission(singular); });
  return ok ? 0 : 2;
}
