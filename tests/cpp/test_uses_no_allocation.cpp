// Proof that the uses of docs/uses.md never touch the heap per call: MomentumObserver::update,
// rnea_derivatives and jacobian_dot, 10^4 calls each on a 7-joint arm (standard DH, one
// prismatic joint, base, tool, drive terms), with every operator new and (on glibc) malloc
// counted (cpp/examples/allocation_counter.hpp). Also checks that a badly sized argument is a
// std::invalid_argument whose message starts with the argument's name.
// Exit status 1 on an allocation, 2 on a missing or wrong error, 3 if the counters miss a probe.
//
// Build (tests/test_momentum_observer.py does this and runs it):
//   g++ -O1 -std=c++17 -I cpp/include -I cpp/examples -I <eigen3>
//       tests/cpp/test_uses_no_allocation.cpp cpp/src/*.cpp
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
  dynid::MomentumObserver observer(model, 25.0, 1e-3);
  dynid::VectorX q(n), qd(n), qdd(n), tau(n), r(n);
  dynid::MatrixX dq(n, n), dqd(n, n), Jdot(6, n);

  if (!allocation_counter_works(n)) return 3;

  double sink = 0.0;
  counting = true;
  for (int k = 0; k < 10000; ++k) {
    const double t = 1e-3 * k;
    for (int i = 0; i < n; ++i) {
      q[i] = 0.5 * std::sin(0.7 * t + i);
      qd[i] = 0.35 * std::cos(0.7 * t + i);
      qdd[i] = -0.245 * std::sin(0.7 * t + i);
    }
    dynid::rnea(model, ws, q, qd, qdd, tau);  // the measured torque: the model's own, no contact
    observer.update(q, qd, tau, r);
    dynid::rnea_derivatives(model, ws, q, qd, qdd, dq, dqd);
    dynid::jacobian_dot(model, ws, q, qd, Jdot);
    sink += r[0] + dq(0, 0) + dqd(n - 1, 0) + Jdot(0, 0);
  }
  counting = false;
  std::printf("allocations_during_calls=%ld\n", allocations);
  std::printf("max_abs_residual_without_contact=%.3e\n", observer.residual().cwiseAbs().maxCoeff());
  if (allocations != 0 || !std::isfinite(sink)) return 1;

  dynid::MatrixX wrong(n, n + 1), wrong_J(5, n);
  dynid::VectorX short_v(n - 1);
  bool ok = true;
  ok &= names_argument("qd", [&] { dynid::rnea_derivatives(model, ws, q, short_v, qdd, dq, dqd); });
  ok &= names_argument("qdd", [&] { dynid::rnea_derivatives(model, ws, q, qd, short_v, dq, dqd); });
  ok &= names_argument("dtau_dq",
                       [&] { dynid::rnea_derivatives(model, ws, q, qd, qdd, wrong, dqd); });
  ok &= names_argument("dtau_dqd",
                       [&] { dynid::rnea_derivatives(model, ws, q, qd, qdd, dq, wrong); });
  ok &= names_argument("q", [&] { dynid::rnea_derivatives(model, ws, short_v, qd, qdd, dq, dqd); });
  ok &= names_argument("Jdot", [&] { dynid::jacobian_dot(model, ws, q, qd, wrong_J); });
  ok &= names_argument("qd", [&] { dynid::jacobian_dot(model, ws, q, short_v, Jdot); });
  ok &= names_argument("tau", [&] { observer.update(q, qd, short_v, r); });
  ok &= names_argument("r", [&] { observer.update(q, qd, tau, short_v); });
  ok &= names_argument("gain", [&] { dynid::MomentumObserver(model, 0.0, 1e-3); });
  ok &= names_argument("gain", [&] { dynid::MomentumObserver(model, short_v, 1e-3); });
  ok &= names_argument("dt", [&] { dynid::MomentumObserver(model, 1.0, -1e-3); });
  return ok ? 0 : 2;
}
