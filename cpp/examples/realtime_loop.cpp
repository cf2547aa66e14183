// A 1 kHz control loop using dynid from C++ without Python (docs/cpp.md): every cycle predicts the
// joint torques of a KUKA LWR-IV by RNEA, builds the joint-torque regressor Y(q, qd, qdd) and
// feeds the "measured" torques to a recursive least-squares estimate of the dynamic parameters
// (online identification, notes p. 27: tau = Y pi) and to a generalized-momentum observer whose
// residual would flag a collision (De Luca; docs/uses.md, "Collision residual").
//
// Real-time rule: everything that needs memory is allocated once, before the loop; inside the
// loop every call writes into those buffers. The program proves it: it replaces the global
// allocation functions by counting ones, switches counting on for the loop only, and exits with
// status 1 if the loop allocated anything. It also checks the numbers each cycle:
//   - rnea(q, qd, qdd) against M(q) qdd + S(q, qd) qd + g(q) + friction(qd), computed by three
//     other algorithms (CRBA, the Christoffel Coriolis matrix, gravity) -- max error printed;
//   - the regressor against rnea: Y pi == tau;
//   - forward dynamics of the predicted torques against the trajectory's qdd;
//   - the collision residual without contact: only the torque noise (0.02 N m) through the
//     observer's first-order filter, so |r| stays below 0.05 N m.
// Exit status 2 if an error exceeds 1e-9 (N m, rad/s^2) or the residual 0.05 N m, 3 if the
// counters miss a probe allocation.
//
// The loop is simulated: cycles run back to back on a smooth analytic trajectory (a sum of
// sines per joint, so q, qd and qdd are exact), and the time of each cycle's dynid work is
// measured; at 1 kHz it has to stay well under the 1000 us period.
//
// Usage:  realtime_loop [seconds]        (simulated duration, default 10 s = 10000 cycles)
// Build:  see cpp/examples/CMakeLists.txt (find_package(dynid) against the installed wheel).

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "dynid/dynid.hpp"
#include "dynid/recursive_least_squares.hpp"

#include "allocation_counter.hpp"

// ------------------------------------------------------------------------ the robot

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kJoints = 7;
constexpr double kPeriod = 1e-3;  // 1 kHz

// KUKA LWR-IV kinematics: Table I of Gaz, Flacco, De Luca (ICRA 2014), standard DH,
// rows [a, alpha, d, theta], all joints revolute.
dynid::Model make_lwr4() {
  const double alpha[kJoints] = {kPi / 2, -kPi / 2, -kPi / 2, kPi / 2, kPi / 2, -kPi / 2, 0.0};
  const double d[kJoints] = {0.0, 0.0, 0.4, 0.0, 0.39, 0.0, 0.0};
  std::vector<dynid::DHRow> rows(kJoints);
  for (int i = 0; i < kJoints; ++i) {
    rows[i].a = 0.0;
    rows[i].alpha = alpha[i];
    rows[i].d = d[i];
    rows[i].theta = 0.0;
    rows[i].type = dynid::JointType::Revolute;
  }
  dynid::Model model(rows, dynid::Convention::Standard, dynid::Vector3(0.0, 0.0, -9.81));

  // Links in physical form, in DH frame i: the values of dynid.models.kuka_lwr4() (plausible,
  // not identified): mass [kg], centre of mass [m], inertia about the centre of mass [kg m^2].
  struct Link {
    double m, cx, cy, cz, Ixx, Iyy, Izz, Ixy, Ixz, Iyz;
  };
  const Link links[kJoints] = {
      {2.85, 0.004, -0.072, 0.058, 0.0192, 0.0061, 0.0168, 0.0004, -0.0003, 0.0011},
      {2.75, -0.003, 0.058, 0.071, 0.0187, 0.0160, 0.0049, -0.0002, 0.0004, -0.0012},
      {2.60, 0.005, 0.069, 0.062, 0.0176, 0.0052, 0.0154, 0.0003, 0.0002, 0.0009},
      {2.55, -0.004, -0.061, 0.068, 0.0171, 0.0148, 0.0047, 0.0002, -0.0003, 0.0010},
      {1.85, 0.003, -0.063, 0.009, 0.0108, 0.0031, 0.0094, -0.0002, 0.0001, -0.0006},
      {1.70, 0.002, 0.004, 0.061, 0.0046, 0.0043, 0.0039, 0.0001, -0.0001, 0.0002},
      {0.45, -0.001, 0.002, 0.065, 0.00052, 0.00047, 0.00071, 0.00004, 0.00003, -0.00005},
  };
  for (int i = 0; i < kJoints; ++i) {
    const Link& l = links[i];
    dynid::Matrix3 inertia_com;
    inertia_com << l.Ixx, l.Ixy, l.Ixz, l.Ixy, l.Iyy, l.Iyz, l.Ixz, l.Iyz, l.Izz;
    model.set_link(i, dynid::RigidBodyParameters::from_physical(
                          l.m, dynid::Vector3(l.cx, l.cy, l.cz), inertia_com));
  }
  // Link-side drive terms (same source): reflected rotor inertia, viscous and Coulomb friction.
  dynid::VectorX Ia(kJoints), Fv(kJoints), Fs(kJoints);
  Ia << 0.32, 0.30, 0.21, 0.19, 0.11, 0.08, 0.07;
  Fv << 0.90, 0.85, 0.55, 0.50, 0.30, 0.25, 0.15;
  Fs << 1.10, 1.00, 0.60, 0.55, 0.45, 0.35, 0.20;
  model.set_rotor_inertia(Ia);
  model.set_viscous_friction(Fv);
  model.set_coulomb_friction(Fs);
  return model;
}

// The parameter vector matching the regressor's columns (docs/conventions.md,
// "Inertial parameters"): the 10 standard parameters of each link, link 1 first, then Ia (n), Fv
// (n), Fs (n).
dynid::VectorX parameter_vector(const dynid::Model& model) {
  const int n = model.n();
  dynid::VectorX pi(dynid::regressor_columns(n, true, true));
  for (int i = 0; i < n; ++i) pi.segment<10>(10 * i) = model.parameters().row(i).transpose();
  pi.segment(10 * n, n) = model.rotor_inertia();
  pi.segment(11 * n, n) = model.viscous_friction();
  pi.segment(12 * n, n) = model.coulomb_friction();
  return pi;
}

// A smooth exciting trajectory: q_i(t) = q0_i + sum_k A_k sin(k w_i t + phi_ik), three harmonics
// per joint, base frequencies 0.10 ... 0.34 Hz. Writes into q, qd, qdd (no allocation).
void trajectory(double t, dynid::VectorX& q, dynid::VectorX& qd, dynid::VectorX& qdd) {
  static const double q0[kJoints] = {0.0, 0.3, 0.0, -0.9, 0.0, 0.5, 0.0};
  for (int i = 0; i < kJoints; ++i) {
    const double w = 2.0 * kPi * (0.10 + 0.04 * i);
    q[i] = q0[i];
    qd[i] = 0.0;
    qdd[i] = 0.0;
    for (int k = 1; k <= 3; ++k) {
      const double amplitude = 0.4 / k;
      const double wk = k * w;
      const double phase = 0.7 * i + 1.3 * k;
      const double s = std::sin(wk * t + phase), c = std::cos(wk * t + phase);
      q[i] += amplitude * s;
      qd[i] += amplitude * wk * c;
      qdd[i] -= amplitude * wk * wk * s;
    }
  }
}

double median(std::vector<double> values) {  // a copy: called after the loop
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

double micros(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::micro>(b - a).count();
}

}  // namespace

int main(int argc, char** argv) {
  using Clock = std::chrono::steady_clock;
  double seconds = 10.0;
  if (argc > 1) {
    char* end = nullptr;
    seconds = std::strtod(argv[1], &end);
    if (end == argv[1] || *end != '\0' || !(seconds > 0.0) || seconds > 3600.0) {
      std::fprintf(stderr, "usage: %s [seconds]   (simulated duration, 0 < seconds <= 3600)\n",
                   argv[0]);
      return 64;
    }
  }
  const long cycles = std::lround(seconds / kPeriod);

  // ---- setup: every allocation happens here, before the loop ----

  // The model: DH table, links and drive terms live in std::vectors/Eigen matrices inside it, so
  // it is built once. It is read-only during the loop.
  const dynid::Model model = make_lwr4();
  const int n = model.n();
  // The Workspace holds every intermediate an algorithm needs (joint transforms, the Newton-Euler
  // velocities and forces, CRBA composites, ...), sized for this model: the algorithms write there
  // instead of allocating. One per thread.
  dynid::Workspace ws(model);

  // Joint state and torques: n-vectors written in place each cycle.
  dynid::VectorX q(n), qd(n), qdd(n), tau(n), tau_measured(n);
  // The regressor Y (n x 91: 70 link parameters + Ia, Fv, Fs), row-major as regressor() writes
  // it. P is fixed for the model, so the matrix is allocated once and overwritten each cycle.
  const bool rotor = true, friction = true;
  const int P = dynid::regressor_columns(n, rotor, friction);
  dynid::RowMajorMatrixX Y(n, P);
  // RecursiveLeastSquares::update() takes a column-major view with any strides: a row-major
  // n x P buffer is the column-major matrix with inner stride P and outer stride 1. Passing Y
  // itself would make Eigen copy it into a temporary column-major matrix -- an allocation.
  using Strides = Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>;
  const Eigen::Map<const dynid::MatrixX, 0, Strides> Y_view(Y.data(), n, P, Strides(1, P));

  // The estimator: theta_0 = 0, P_0 = 1e4 I, no forgetting. Its constructor allocates theta, the
  // UD factors of the covariance and its scratch vectors; update() then allocates nothing. The 91
  // columns are not independent (only the base parameters are identifiable; e.g. Ia_1 and Izz_1
  // enter joint 1 identically): the prior keeps the estimate defined in the other directions, and
  // the torque prediction Y theta is what converges.
  dynid::RecursiveLeastSquares rls(P, 1.0, 1e4);

  // The collision residual: the observer copies the model and sizes its buffers here; update()
  // then allocates nothing. Gain 25 /s: a 40 ms time constant.
  dynid::MomentumObserver observer(model, 25.0, kPeriod);
  dynid::VectorX residual(n);
  double max_residual = 0.0;
  const dynid::VectorX pi_true = parameter_vector(model);

  // Buffers of the self-check (M qdd + S qd + g + friction vs rnea) and of the prediction error.
  dynid::MatrixX M(n, n), S(n, n);
  dynid::VectorX g(n), f(n), tau_check(n), qdd_check(n), tau_hat(n);
  // Per-cycle timings, stored by index: sized up front (a push_back that grows would allocate).
  std::vector<double> t_rnea(cycles), t_regressor(cycles), t_rls(cycles), t_observer(cycles),
      t_cycle(cycles);

  // "Measured" torques = the model's own plus deterministic noise (fixed seed; the generator and
  // the distribution keep their state in place).
  std::mt19937_64 generator(20240611);
  std::normal_distribution<double> noise(0.0, 0.02);  // N m

  // The counters must see what they are meant to see: an Eigen vector (malloc) and a
  // std::vector (operator new).
  counting = true;
  {
    dynid::VectorX probe(n);
    std::vector<double> probe_new(n);
    probe.setZero();
    probe_new[0] = probe[0];
  }
  counting = false;
  if (allocations < 2) {
    std::printf("allocation counter broken: %ld of 2 probe allocations seen\n", allocations);
    return 3;
  }
  allocations = 0;

  // ---- the loop: no allocation from here ----
  double max_dynamics_error = 0.0, max_regressor_error = 0.0, max_forward_error = 0.0;
  double prediction_error_sq = 0.0, torque_sq = 0.0;  // over the last 10% of the cycles
  const long last_tenth = cycles - std::max(1L, cycles / 10);
  counting = true;
  for (long k = 0; k < cycles; ++k) {
    trajectory(k * kPeriod, q, qd, qdd);  // stands in for the robot's state estimate
    const Clock::time_point start = Clock::now();

    // 1. torque prediction (feed-forward of a computed-torque controller)
    dynid::rnea(model, ws, q, qd, qdd, tau);
    const Clock::time_point after_rnea = Clock::now();

    // 2. the regressor of this sample
    dynid::regressor(model, ws, q, qd, qdd, rotor, friction, Y);
    const Clock::time_point after_regressor = Clock::now();

    // 3. the a-priori prediction of the current estimate (for the error figure), then one RLS
    //    update with the measured torques
    for (int i = 0; i < n; ++i) tau_measured[i] = tau[i] + noise(generator);
    if (k >= last_tenth) {
      tau_hat.noalias() = Y * rls.theta();
      prediction_error_sq += (tau_hat - tau).squaredNorm();
      torque_sq += tau.squaredNorm();
    }
    rls.update(Y_view, tau_measured);
    const Clock::time_point after_rls = Clock::now();

    // 4. the collision residual of the measured torques
    observer.update(q, qd, tau_measured, residual);
    const Clock::time_point end = Clock::now();

    t_rnea[k] = micros(start, after_rnea);
    t_regressor[k] = micros(after_rnea, after_regressor);
    t_rls[k] = micros(after_regressor, after_rls);
    t_observer[k] = micros(after_rls, end);
    max_residual = std::max(max_residual, residual.cwiseAbs().maxCoeff());
    t_cycle[k] = micros(start, end);

    // Self-check, outside the timed part: rnea against three other algorithms, Y pi == tau, and
    // forward dynamics recovers qdd from tau.
    dynid::crba(model, ws, q, M);
    dynid::coriolis_matrix(model, ws, q, qd, S);
    dynid::gravity(model, ws, q, g);
    dynid::friction(model, qd, f);
    tau_check.noalias() = M * qdd;
    tau_check.noalias() += S * qd;
    tau_check += g + f;
    max_dynamics_error = std::max(max_dynamics_error, (tau_check - tau).cwiseAbs().maxCoeff());
    tau_check.noalias() = Y * pi_true;
    max_regressor_error = std::max(max_regressor_error, (tau_check - tau).cwiseAbs().maxCoeff());
    dynid::forward_dynamics(model, ws, q, qd, tau, qdd_check);
    max_forward_error = std::max(max_forward_error, (qdd_check - qdd).cwiseAbs().maxCoeff());
  }
  counting = false;
  const long loop_allocations = allocations;

  // ---- report ----
  const auto slowest = std::max_element(t_cycle.begin(), t_cycle.end());
  std::vector<double> sorted = t_cycle;
  std::sort(sorted.begin(), sorted.end());
  const double p99 = sorted[std::min<std::size_t>(sorted.size() - 1, sorted.size() * 99 / 100)];
  const long overruns =
      std::count_if(t_cycle.begin(), t_cycle.end(), [](double us) { return us > 1e6 * kPeriod; });
  const double prediction_error = std::sqrt(prediction_error_sq / torque_sq);
  const double parameter_error = (rls.theta() - pi_true).norm() / pi_true.norm();

  std::printf(
      "dynid real-time loop: KUKA LWR-IV, n = %d, %d regressor columns, 1 kHz, "
      "%.3g s simulated (%ld cycles)\n",
      n, P, seconds, cycles);
  std::printf("allocations: %ld allocations in %ld cycles (operator new and malloc counted)\n",
              loop_allocations, cycles);
  std::printf(
      "cycle time [us]: median %.2f, 99th percentile %.2f, max %.2f (cycle %ld); "
      "medians: rnea %.2f, regressor %.2f, RLS update %.2f, momentum observer %.2f; %ld "
      "cycles over the %.0f us period\n",
      median(t_cycle), p99, *slowest, static_cast<long>(slowest - t_cycle.begin()), median(t_rnea),
      median(t_regressor), median(t_rls), median(t_observer), overruns, 1e6 * kPeriod);
  std::printf("max |rnea - (M qdd + S qd + g + friction)| = %.3e N m\n", max_dynamics_error);
  std::printf("max |Y pi - rnea| = %.3e N m\n", max_regressor_error);
  std::printf("max |forward_dynamics(rnea) - qdd| = %.3e rad/s^2\n", max_forward_error);
  std::printf("max |collision residual| without contact = %.3e N m\n", max_residual);
  std::printf(
      "torque prediction error of the RLS estimate (a priori, last 10%% of the cycles): "
      "%.3e relative RMS\n",
      prediction_error);
  std::printf(
      "standard-parameter error |theta - pi| / |pi| = %.3e (not all identifiable: only "
      "their base combinations are)\n",
      parameter_error);

  if (loop_allocations != 0) return 1;
  if (!(max_dynamics_error < 1e-9) || !(max_regressor_error < 1e-9) ||
      !(max_forward_error < 1e-9) || !(max_residual < 0.05)) {
    return 2;
  }
  return 0;
}
