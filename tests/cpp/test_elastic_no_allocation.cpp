// Proof that rnea_time_derivatives (the jerk/snap Newton-Euler recursion behind ElasticRobot's
// inverse dynamics) never touches the heap per call, nor does a run of the ElasticSimulator under
// the built-in motor PD or the KUKA-like controller (500 periods, 5 RK4 substeps): 10^4 calls on a
// 7-joint arm (standard DH, one prismatic joint, base, tool, drive terms) with every operator new
// and (on glibc) malloc counted (cpp/examples/allocation_counter.hpp). Also checks that a badly
// sized argument is a std::invalid_argument whose message starts with the argument's name. Exit
// status 1 on an allocation, 2 on a missing or wrong error, 3 if the counters miss a probe.
//
// Build (tests/test_elastic.py does this and runs it):
//   g++ -O1 -std=c++17 -I cpp/include -I cpp/examples -I <eigen3>
//       tests/cpp/test_elastic_no_allocation.cpp cpp/src/*.cpp
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/dynid.hpp"

#include "allocation_counter.hpp"  // cpp/examples/
#include "test_support.hpp"

int main() {
  const dynid::Model model = make_test_arm();
  const int n = model.n();
  dynid::Workspace ws(model);
  dynid::VectorX q(n), qd(n), qdd(n), qddd(n), qdddd(n), tau(n), tau_dot(n), tau_ddot(n),
      rnea_tau(n);

  if (!allocation_counter_works(n)) return 3;

  double sink = 0.0, max_difference_to_rnea = 0.0;
  counting = true;
  for (int k = 0; k < 10000; ++k) {
    const double t = 1e-3 * k;
    for (int i = 0; i < n; ++i) {  // q = 0.5 sin(0.7 t + i) and its derivatives
      const double s = std::sin(0.7 * t + i), c = std::cos(0.7 * t + i);
      q[i] = 0.5 * s;
      qd[i] = 0.35 * c;
      qdd[i] = -0.245 * s;
      qddd[i] = -0.1715 * c;
      qdddd[i] = 0.12005 * s;
    }
    dynid::rnea_time_derivatives(model, ws, q, qd, qdd, qddd, qdddd, tau, tau_dot, tau_ddot);
    dynid::rnea(model, ws, q, qd, qdd, rnea_tau);
    max_difference_to_rnea =
        std::fmax(max_difference_to_rnea, (tau - rnea_tau).cwiseAbs().maxCoeff());
    sink += tau_dot[0] + tau_ddot[n - 1];
  }
  counting = false;

  // A closed-loop run of the elastic-joint simulator under the motor PD (built-in controller):
  // constructed outside the count, run inside it.
  dynid::Model links = model;
  links.set_rotor_inertia(dynid::VectorX::Zero(n));
  links.set_viscous_friction(dynid::VectorX::Zero(n));
  links.set_coulomb_friction(dynid::VectorX::Zero(n));
  const dynid::ElasticDrives drives{
      dynid::VectorX::Constant(n, 3000.0), dynid::VectorX::Constant(n, 0.4),
      dynid::VectorX::Constant(n, 1.0), dynid::VectorX::Constant(n, 0.2)};
  dynid::ElasticSimulator simulator(links, drives, 1e-3, 5, 1e-3);
  dynid::MotorPDController pd(links, drives, dynid::VectorX::Constant(n, 300.0),
                              dynid::VectorX::Constant(n, 30.0), dynid::VectorX::Constant(n, 0.2));
  const int periods = 500;
  dynid::RowMajorMatrixX blocks[6];
  for (auto& b : blocks) b.resize(periods + 1, n);
  dynid::ElasticSimulationOutput out{blocks[0], blocks[1], blocks[2],
                                     blocks[3], blocks[4], blocks[5]};
  const dynid::VectorX zero = dynid::VectorX::Zero(n);
  counting = true;
  simulator.run(pd, zero, zero, zero, zero, periods, out);
  counting = false;
  sink += blocks[0](periods, 0);

  // The same run under the KUKA-like controller (static gravity: a fixed-point iteration of
  // gravity() per command, torque loop, a user torque), constructed outside the count.
  std::vector<double> ref_q((periods + 1) * n), ref_qd((periods + 1) * n), user((periods + 1) * n);
  for (int k = 0; k <= periods; ++k)
    for (int i = 0; i < n; ++i) {
      ref_q[k * n + i] = 0.2 + 0.1 * std::sin(1e-3 * k + i);
      ref_qd[k * n + i] = 0.1e-3 * std::cos(1e-3 * k + i);
      user[k * n + i] = 0.1 * i;
    }
  const dynid::ReferenceTrajectory reference{ref_q.data(), ref_qd.data(), nullptr, periods + 1, n};
  const dynid::KukaLikeGains gains{
      dynid::VectorX::Constant(n, 300.0), dynid::VectorX::Constant(n, 30.0),
      dynid::VectorX::Constant(n, 3.0), dynid::VectorX::Constant(n, 1e-3)};
  dynid::KukaLikeController kuka(links, drives.stiffness, gains, dynid::GravityCompensation::Static,
                                 reference, user.data());
  counting = true;
  simulator.run(kuka, zero, zero, zero, zero, periods, out);
  counting = false;
  sink += blocks[4](periods, n - 1);
  std::printf("allocations_during_calls=%ld\n", allocations);
  std::printf("max_abs_difference_to_rnea=%.3e\n", max_difference_to_rnea);
  if (allocations != 0 || !std::isfinite(sink)) return 1;
  if (!(max_difference_to_rnea < 1e-10)) return 1;

  dynid::VectorX short_v(n - 1);
  bool ok = true;
  const auto call = [&](const dynid::VectorX& a, const dynid::VectorX& b, const dynid::VectorX& c,
                        const dynid::VectorX& d, const dynid::VectorX& e, dynid::VectorX& f,
                        dynid::VectorX& g, dynid::VectorX& h) {
    dynid::rnea_time_derivatives(model, ws, a, b, c, d, e, f, g, h);
  };
  ok &= names_argument("q", [&] { call(short_v, qd, qdd, qddd, qdddd, tau, tau_dot, tau_ddot); });
  ok &= names_argument("qd", [&] { call(q, short_v, qdd, qddd, qdddd, tau, tau_dot, tau_ddot); });
  ok &= names_argument("qdd", [&] { call(q, qd, short_v, qddd, qdddd, tau, tau_dot, tau_ddot); });
  ok &= names_argument("qddd", [&] { call(q, qd, qdd, short_v, qdddd, tau, tau_dot, tau_ddot); });
  ok &= names_argument("qdddd", [&] { call(q, qd, qdd, qddd, short_v, tau, tau_dot, tau_ddot); });
  dynid::VectorX short_out(n - 1);
  ok &= names_argument("tau", [&] { call(q, qd, qdd, qddd, qdddd, short_out, tau_dot, tau_ddot); });
  ok &= names_argument("tau_dot", [&] { call(q, qd, qdd, qddd, qdddd, tau, short_out, tau_ddot); });
  ok &= names_argument("tau_ddot", [&] { call(q, qd, qdd, qddd, qdddd, tau, tau_dot, short_out); });
  ok &=
      names_argument("theta0", [&] { simulator.run(pd, zero, zero, short_v, zero, periods, out); });
  ok &= names_argument("periods", [&] { simulator.run(pd, zero, zero, zero, zero, 0, out); });
  dynid::ElasticDrives bad = drives;
  bad.stiffness[0] = 0.0;
  ok &= names_argument("stiffness", [&] { dynid::ElasticSimulator(links, bad, 1e-3, 5, 1e-3); });
  ok &= names_argument("substeps", [&] { dynid::ElasticSimulator(links, drives, 1e-3, 0, 1e-3); });
  const auto kuka_with = [&](const dynid::VectorX& stiffness, const dynid::KukaLikeGains& g) {
    dynid::KukaLikeController(links, stiffness, g, dynid::GravityCompensation::Desired, reference);
  };
  dynid::KukaLikeGains bad_gains = gains;
  bad_gains.torque_gain[1] = -1.0;
  ok &= names_argument("torque_gain", [&] { kuka_with(drives.stiffness, bad_gains); });
  bad_gains = gains;
  bad_gains.kd.resize(n - 1);
  ok &= names_argument("kd", [&] { kuka_with(drives.stiffness, bad_gains); });
  ok &= names_argument("stiffness", [&] { kuka_with(short_v, gains); });
  dynid::VectorX tau_out(n);
  ok &= names_argument("theta",
                       [&] { kuka.command(0, 0.0, zero, zero, short_v, zero, zero, tau_out); });
  return ok ? 0 : 2;
}
