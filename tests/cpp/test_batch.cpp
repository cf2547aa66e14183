// Proof of the public batch API (dynid/batch.hpp) on a 7-joint arm (standard DH, one prismatic
// joint, base, tool, drive terms), on every batch path this CPU runs (scalar, SSE2, AVX2,
// AVX-512 lanes):
// - every batch call equals the per-sample call on each of T random states, to 1e-12 relative
//   to the result's size (the lanes reorder no operation but use their own sin and cos, a few
//   ulp); odd T, so that the lane kernels' partial last vector is covered;
// - two threads give exactly the one-thread results and report two threads;
// - a wrong size of any argument, a workspace of another model, threads < 1 and bad columns are
//   std::invalid_argument naming the argument;
// - a reused BatchWorkspace on one thread allocates nothing, whatever T (every operator new and
//   malloc counted);
// - an overflow is reported at its sample, an interrupt check stops the batch, and
//   forward_dynamics' std::domain_error reaches the caller.
// Exit status 1 on a wrong result, 2 on a missing or wrong error, 3 if the counters miss a probe,
// 4 on an allocation.
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/batch.hpp"
#include "dynid/detail/batch.hpp"
#include "dynid/dynid.hpp"

#include "allocation_counter.hpp"  // cpp/examples/
#include "test_support.hpp"

namespace {

using dynid::MatrixX;
using dynid::RowMajorMatrixX;
using dynid::VectorX;
using Index = Eigen::Index;
using Strides = Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>;
using RowBlock = Eigen::Map<MatrixX, 0, Strides>;

RowMajorMatrixX random_samples(Index T, int n, double scale, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-scale, scale);
  RowMajorMatrixX x(T, n);
  for (Index t = 0; t < T; ++t)
    for (int i = 0; i < n; ++i) x(t, i) = u(rng);
  return x;
}

VectorX sample(const RowMajorMatrixX& x, Index t) { return x.row(t).transpose(); }

int failures = 0;

// max |batch row t - expected| <= 1e-12 * max(1, max |expected|) for every t.
void expect_rows(const std::string& what, const RowMajorMatrixX& batch,
                 const std::function<void(Index, double*)>& single) {
  std::vector<double> expected(static_cast<std::size_t>(batch.cols()));
  double worst = 0.0;
  for (Index t = 0; t < batch.rows(); ++t) {
    single(t, expected.data());
    double scale = 1.0, error = 0.0;
    for (Index k = 0; k < batch.cols(); ++k) {
      scale = std::max(scale, std::abs(expected[k]));
      error = std::max(error, std::abs(batch(t, k) - expected[k]));
    }
    worst = std::max(worst, error / scale);
  }
  if (!(worst <= 1e-12)) {
    std::printf("FAIL %s: relative error %.3e\n", what.c_str(), worst);
    ++failures;
  }
}

RowBlock row_major(double* data, int rows, int cols) {
  return RowBlock(data, rows, cols, Strides(1, cols));
}

// Every batch call against the per-sample call, on the batch path in use.
void check_against_single_calls(const dynid::Model& model, Index T, std::mt19937_64& rng) {
  const int n = model.n();
  const std::string path = dynid::detail::batch_isa() + " T=" + std::to_string(T) + " ";
  dynid::Workspace w(model);
  dynid::BatchWorkspace ws(model);
  const RowMajorMatrixX Q = random_samples(T, n, 3.0, rng), Qd = random_samples(T, n, 2.0, rng),
                        Qdd = random_samples(T, n, 5.0, rng), Q3 = random_samples(T, n, 5.0, rng),
                        Q4 = random_samples(T, n, 5.0, rng);
  const int P = dynid::regressor_columns(n, true, true), rows = n * (n + 1) / 2;
  RowMajorMatrixX tau(T, n), M(T, n * n), g(T, n), c(T, n), S(T, n * n), f(T, n), qdd(T, n),
      K(T, 1), U(T, 1), pose(T, 16), J(T, 6 * n), Jdot(T, 6 * n), Y(T, n * P), Yc(T, n * 5),
      Y0(T, n * 10 * n), Yg(T, n * 10 * n), Ym(T, rows * (11 * n)), dtau(T, 2 * n * n),
      taus(T, 3 * n);
  const std::vector<int> columns = {0, 3, 17, P - 1, 42};
  namespace batch = dynid::batch;
  batch::rnea(model, ws, Q, Qd, Qdd, tau);
  batch::mass_matrix(model, ws, Q, M);
  batch::gravity(model, ws, Q, g);
  batch::coriolis(model, ws, Q, Qd, c);
  batch::coriolis_matrix(model, ws, Q, Qd, S);
  batch::friction(model, ws, Qd, f);
  batch::forward_dynamics(model, ws, Q, Qd, tau, qdd);
  batch::kinetic_energy(model, ws, Q, Qd, K);
  batch::potential_energy(model, ws, Q, U);
  batch::fkine(model, ws, Q, pose);
  batch::jacobian(model, ws, Q, J);
  batch::jacobian_dot(model, ws, Q, Qd, Jdot);
  batch::regressor(model, ws, Q, Qd, Qdd, true, true, Y);
  batch::regressor(model, ws, Q, Qd, Qdd, true, true, columns, Yc);
  batch::regressor(model, ws, Q, Qd, Qdd, false, false, Y0);
  batch::gravity_regressor(model, ws, Q, Yg);
  batch::inertia_regressor(model, ws, Q, true, Ym);
  batch::rnea_derivatives(model, ws, Q, Qd, Qdd, dtau);
  batch::rnea_time_derivatives(model, ws, Q, Qd, Qdd, Q3, Q4, taus);

  using VecMap = Eigen::Map<VectorX>;
  using RowMap = Eigen::Map<RowMajorMatrixX>;
  expect_rows(path + "rnea", tau, [&](Index t, double* o) {
    dynid::rnea(model, w, sample(Q, t), sample(Qd, t), sample(Qdd, t), VecMap(o, n));
  });
  expect_rows(path + "mass_matrix", M,
              [&](Index t, double* o) { dynid::crba(model, w, sample(Q, t), row_major(o, n, n)); });
  expect_rows(path + "gravity", g,
              [&](Index t, double* o) { dynid::gravity(model, w, sample(Q, t), VecMap(o, n)); });
  expect_rows(path + "coriolis", c, [&](Index t, double* o) {
    dynid::coriolis(model, w, sample(Q, t), sample(Qd, t), VecMap(o, n));
  });
  expect_rows(path + "coriolis_matrix", S, [&](Index t, double* o) {
    dynid::coriolis_matrix(model, w, sample(Q, t), sample(Qd, t), row_major(o, n, n));
  });
  expect_rows(path + "friction", f,
              [&](Index t, double* o) { dynid::friction(model, sample(Qd, t), VecMap(o, n)); });
  expect_rows(path + "forward_dynamics", qdd, [&](Index t, double* o) {
    dynid::forward_dynamics(model, w, sample(Q, t), sample(Qd, t), sample(tau, t), VecMap(o, n));
  });
  expect_rows(path + "kinetic_energy", K, [&](Index t, double* o) {
    *o = dynid::kinetic_energy(model, w, sample(Q, t), sample(Qd, t));
  });
  expect_rows(path + "potential_energy", U,
              [&](Index t, double* o) { *o = dynid::potential_energy(model, w, sample(Q, t)); });
  expect_rows(path + "fkine", pose, [&](Index t, double* o) {
    dynid::fkine(model, w, sample(Q, t), row_major(o, 4, 4));
  });
  expect_rows(path + "jacobian", J, [&](Index t, double* o) {
    dynid::jacobian(model, w, sample(Q, t), row_major(o, 6, n));
  });
  expect_rows(path + "jacobian_dot", Jdot, [&](Index t, double* o) {
    dynid::jacobian_dot(model, w, sample(Q, t), sample(Qd, t), row_major(o, 6, n));
  });
  expect_rows(path + "regressor", Y, [&](Index t, double* o) {
    dynid::regressor(model, w, sample(Q, t), sample(Qd, t), sample(Qdd, t), true, true,
                     RowMap(o, n, P));
  });
  expect_rows(path + "regressor(columns)", Yc, [&](Index t, double* o) {
    RowMajorMatrixX full(n, P);
    dynid::regressor(model, w, sample(Q, t), sample(Qd, t), sample(Qdd, t), true, true, full);
    for (int i = 0; i < n; ++i)
      for (std::size_t k = 0; k < columns.size(); ++k) o[i * 5 + k] = full(i, columns[k]);
  });
  expect_rows(path + "regressor(links)", Y0, [&](Index t, double* o) {
    dynid::regressor(model, w, sample(Q, t), sample(Qd, t), sample(Qdd, t), false, false,
                     RowMap(o, n, 10 * n));
  });
  expect_rows(path + "gravity_regressor", Yg, [&](Index t, double* o) {
    dynid::gravity_regressor(model, w, sample(Q, t), RowMap(o, n, 10 * n));
  });
  expect_rows(path + "inertia_regressor", Ym, [&](Index t, double* o) {
    dynid::inertia_regressor(model, w, sample(Q, t), true, RowMap(o, rows, 11 * n));
  });
  expect_rows(path + "rnea_derivatives", dtau, [&](Index t, double* o) {
    dynid::rnea_derivatives(model, w, sample(Q, t), sample(Qd, t), sample(Qdd, t),
                            row_major(o, n, n), row_major(o + n * n, n, n));
  });
  expect_rows(path + "rnea_time_derivatives", taus, [&](Index t, double* o) {
    VecMap a(o, n), b(o + n, n), d(o + 2 * n, n);
    dynid::rnea_time_derivatives(model, w, sample(Q, t), sample(Qd, t), sample(Qdd, t),
                                 sample(Q3, t), sample(Q4, t), a, b, d);
  });
}

bool check_threads(const dynid::Model& model, std::mt19937_64& rng) {
  const int n = model.n();
  const Index T = 3001;  // two threads of at least 512 samples, and a remainder
  const RowMajorMatrixX Q = random_samples(T, n, 3.0, rng), Qd = random_samples(T, n, 2.0, rng);
  RowMajorMatrixX one(T, n * n), two(T, n * n), c1(T, n), c2(T, n);
  dynid::BatchWorkspace single(model, 1), pair(model, 2);
  dynid::batch::mass_matrix(model, single, Q, one);
  const dynid::batch::Report r = dynid::batch::mass_matrix(model, pair, Q, two);
  dynid::batch::coriolis(model, single, Q, Qd, c1);
  const dynid::batch::Report rc = dynid::batch::coriolis(model, pair, Q, Qd, c2);
  // Each sample is computed by the same code whichever thread runs it: bit-identical.
  if (r.threads != 2 || rc.threads != 2 || one != two || c1 != c2) {
    std::printf("FAIL threads: %d and %d threads, equal %d %d\n", r.threads, rc.threads, one == two,
                c1 == c2);
    return false;
  }
  return true;
}

bool check_errors(const dynid::Model& model) {
  namespace batch = dynid::batch;
  const int n = model.n();
  const Index T = 10;
  dynid::BatchWorkspace ws(model);
  std::vector<dynid::DHRow> short_rows(model.dh().begin(), model.dh().end() - 1);
  const dynid::Model other(short_rows, dynid::Convention::Standard);
  dynid::BatchWorkspace other_ws(other);
  RowMajorMatrixX q = RowMajorMatrixX::Zero(T, n), narrow(T, n - 1), short_q(T - 1, n);
  RowMajorMatrixX tau(T, n), M(T, n * n), wrong(T, n + 1), Y(T, n * 10 * n);
  bool ok = true;
  ok &= names_argument("threads", [&] { dynid::BatchWorkspace(model, 0); });
  ok &= names_argument("ws", [&] { batch::rnea(model, other_ws, q, q, q, tau); });
  ok &= names_argument("q", [&] { batch::rnea(model, ws, narrow, q, q, tau); });
  ok &= names_argument("qd", [&] { batch::rnea(model, ws, q, short_q, q, tau); });
  ok &= names_argument("qdd", [&] { batch::rnea(model, ws, q, q, narrow, tau); });
  ok &= names_argument("tau", [&] { batch::rnea(model, ws, q, q, q, wrong); });
  ok &= names_argument("M", [&] { batch::mass_matrix(model, ws, q, tau); });
  ok &= names_argument("tau", [&] { batch::forward_dynamics(model, ws, q, q, narrow, tau); });
  ok &= names_argument("Y", [&] { batch::regressor(model, ws, q, q, q, true, false, Y); });
  ok &= names_argument("columns", [&] {
    batch::regressor(model, ws, q, q, q, false, false, std::vector<int>{0, 10 * n}, Y);
  });
  ok &=
      names_argument("columns", [&] { batch::regressor(model, ws, q, q, q, false, false, {}, Y); });
  ok &= names_argument("qdddd", [&] {
    RowMajorMatrixX out(T, 3 * n);
    batch::rnea_time_derivatives(model, ws, q, q, q, q, narrow, out);
  });
  try {
    batch::rnea(model, ws, narrow, q, q, tau);
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).find("(in dynid::batch::rnea)") == std::string::npos) {
      std::printf("FAIL the message does not name dynid::batch::rnea: %s\n", e.what());
      ok = false;
    }
  }
  // forward dynamics with negative masses: M(q) not positive definite, from the worker.
  dynid::Model bad = model;
  MatrixX params = model.parameters();
  params.col(0).setConstant(-1.0);
  bad.set_parameters(params);
  bad.set_rotor_inertia(VectorX::Zero(n));
  try {
    batch::forward_dynamics(bad, ws, q, q, q, tau);
    std::printf("FAIL forward_dynamics: no std::domain_error for an indefinite M\n");
    ok = false;
  } catch (const std::domain_error&) {
  }
  // An overflow is reported at the first sample it happens in.
  RowMajorMatrixX qd = RowMajorMatrixX::Zero(T, n);
  qd(7, 1) = 1e200;
  qd(9, 0) = 1e200;
  for (const std::string& isa : dynid::detail::supported_batch_isas()) {
    dynid::detail::set_batch_isa(isa);
    const batch::Report r = batch::rnea(model, ws, q, qd, q, tau);
    if (r.first_nonfinite != 7) {
      std::printf("FAIL %s: first_nonfinite %ld, expected 7\n", isa.c_str(),
                  static_cast<long>(r.first_nonfinite));
      ok = false;
    }
  }
  // An interrupt check that says stop: batch::Interrupted after the first 20 ms.
  int checks = 0;
  dynid::BatchWorkspace stoppable(model);
  stoppable.set_interrupt({[](void* count) { return ++*static_cast<int*>(count) >= 2; }, &checks});
  const Index long_T = 400000;  // seconds of forward dynamics
  RowMajorMatrixX Q = RowMajorMatrixX::Zero(long_T, n), out(long_T, n);
  try {
    batch::forward_dynamics(model, stoppable, Q, Q, Q, out);
    std::printf("FAIL the interrupt check did not stop the batch (%d checks)\n", checks);
    ok = false;
  } catch (const batch::Interrupted&) {
  }
  return ok;
}

// One thread, a reused BatchWorkspace: no allocation in any batch call, on every path.
bool check_no_allocation(const dynid::Model& model, std::mt19937_64& rng) {
  namespace batch = dynid::batch;
  const int n = model.n();
  const Index T = 1000;
  const RowMajorMatrixX Q = random_samples(T, n, 3.0, rng), Qd = random_samples(T, n, 2.0, rng);
  RowMajorMatrixX tau(T, n), M(T, n * n), Y(T, n * 3), S(T, n * n);
  const std::vector<int> columns = {1, 2, 3};
  dynid::BatchWorkspace ws(model);
  bool ok = true;
  for (const std::string& isa : dynid::detail::supported_batch_isas()) {
    dynid::detail::set_batch_isa(isa);
    auto calls = [&] {
      batch::rnea(model, ws, Q, Qd, Qd, tau);
      batch::mass_matrix(model, ws, Q, M);
      batch::regressor(model, ws, Q, Qd, Qd, false, false, columns, Y);
      batch::coriolis_matrix(model, ws, Q, Qd, S);
    };
    calls();  // the first call sizes the regressor's buffer
    counting = true;
    calls();
    counting = false;
    std::printf("%s: allocations_during_batches=%ld\n", isa.c_str(), allocations);
    ok &= allocations == 0;
    allocations = 0;
  }
  return ok;
}

}  // namespace

int main() {
  const dynid::Model model = make_test_arm();
  std::mt19937_64 rng(20261127);
  if (!allocation_counter_works(model.n())) return 3;
  const std::vector<std::string> paths = dynid::detail::supported_batch_isas();
  for (const std::string& isa : paths) {
    dynid::detail::set_batch_isa(isa);
    for (Index T : {Index{1}, Index{7}, Index{1001}}) check_against_single_calls(model, T, rng);
  }
  std::printf("paths checked:");
  for (const std::string& isa : paths) std::printf(" %s", isa.c_str());
  std::printf("\n");
  if (failures != 0 || !check_threads(model, rng)) return 1;
  if (!check_no_allocation(model, rng)) return 4;
  return check_errors(model) ? 0 : 2;
}
