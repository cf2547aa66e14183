// Proof that RecursiveLeastSquares::update() never touches the heap, and its time per update.
//
// Every allocation function is replaced by a counting one: the global operator new/delete (all
// C++17 forms) and, on glibc, malloc and its relatives too, because Eigen allocates with
// std::malloc rather than operator new (elsewhere only operator new is counted). The estimator is
// built (allocations allowed), then 10^4 updates with 7 x 43 blocks (the KUKA LWR4 base
// regressor) run with counting on, read from row-major storage as the Python binding does,
// followed by blocks of every size m = 1..24 and both allocation-free resets.
// Exit status 1 if any allocation happened during the updates, 2 if the estimate is wrong, 3 if
// the counters do not see a deliberate allocation.
//
// Build (from the repository root):
//   g++ -O3 -DNDEBUG -std=c++17 -I cpp/include -I cpp/examples -I <eigen3>
//   tests/cpp/test_rls_no_allocation.cpp
//       cpp/src/recursive_least_squares.cpp
// (tests/test_recursive.py does this and runs it.)
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <new>
#include <random>
#include <vector>

#include "dynid/recursive_least_squares.hpp"

#include "allocation_counter.hpp"  // cpp/examples/

namespace {

using dynid::MatrixX;
using dynid::RecursiveLeastSquares;
using dynid::VectorX;
using RowMajorBlock = Eigen::Map<const MatrixX, 0, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;
using Vector = Eigen::Map<const VectorX>;

constexpr int kParameters = 43;  // base parameters of the KUKA LWR4 torque regressor
constexpr int kRows = 7;         // joints
constexpr int kUpdates = 10000;
constexpr int kChunk = 200;

// Blocks stored as NumPy would hand them over: T x m x p, row-major.
struct Data {
  std::vector<double> Y, tau;
};

Data make_data(const VectorX& theta_true, int blocks, int m, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Data d;
  d.Y.resize(static_cast<std::size_t>(blocks) * m * kParameters);
  d.tau.resize(static_cast<std::size_t>(blocks) * m);
  for (double& y : d.Y) y = normal(rng);
  for (int t = 0; t < blocks; ++t) {
    RowMajorBlock Y(d.Y.data() + t * m * kParameters, m, kParameters,
                    Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(1, kParameters));
    Eigen::Map<VectorX> tau(d.tau.data() + t * m, m);
    tau = Y * theta_true;
    for (int r = 0; r < m; ++r) tau[r] += 1e-3 * normal(rng);
  }
  return d;
}

void run(RecursiveLeastSquares& rls, const Data& d, int first, int blocks, int m) {
  for (int t = first; t < first + blocks; ++t) {
    rls.update(RowMajorBlock(d.Y.data() + t * m * kParameters, m, kParameters,
                             Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(1, kParameters)),
               Vector(d.tau.data() + t * m, m));
  }
}

}  // namespace

int main() {
  std::mt19937_64 rng(20240611);
  std::normal_distribution<double> normal;
  const VectorX theta_true =
      VectorX::NullaryExpr(kParameters, [&](Eigen::Index) { return normal(rng); });
  const Data data = make_data(theta_true, kUpdates, kRows, rng);
  std::vector<Data> varying;  // one block of each size m = 1..24
  for (int m = 1; m <= 24; ++m) varying.push_back(make_data(theta_true, 1, m, rng));

  // The counters must see what they are meant to see: an Eigen vector (std::malloc) and a
  // std::vector (operator new) are counted.
  counting = true;
  {
    VectorX probe(kParameters);
    std::vector<double> probe_new(kParameters);
    probe.setZero();
    probe_new[0] = probe[0];
  }
  counting = false;
  const long expected_probe = 2;
  if (allocations < expected_probe) {
    std::printf("allocation counter broken: %ld of %ld probe allocations seen\n", allocations,
                expected_probe);
    return 3;
  }
  allocations = 0;

  RecursiveLeastSquares rls(kParameters, 0.999, 1e6);
  counting = true;
  run(rls, data, 0, kUpdates, kRows);
  for (int m = 1; m <= 24; ++m) run(rls, varying[m - 1], 0, 1, m);
  const VectorX& theta = rls.theta();  // a reference: reading the estimate allocates nothing
  const double first = theta[0];
  rls.reset();
  rls.reset(1e3);
  run(rls, data, 0, 10, kRows);
  counting = false;
  std::printf("allocations_during_updates=%ld\n", allocations);

  // The estimate must have converged (noise 1e-3 on 7e4 equations): a broken update that
  // allocates nothing must not pass either.
  rls.reset();
  run(rls, data, 0, kUpdates, kRows);
  const double error = (rls.theta() - theta_true).norm() / theta_true.norm();
  if (!std::isfinite(first)) return 2;
  std::printf("relative_parameter_error=%.3e\n", error);

  // Time per update: the median over chunks of kChunk updates, so that the scheduler's pauses on
  // a busy machine land in a few chunks instead of in every measurement; wall-clock time and the
  // process's CPU time (which leaves out the time other processes ran) both.
  std::vector<double> wall, cpu;
  RecursiveLeastSquares timed(kParameters, 0.999, 1e6);
  for (int start = 0; start + kChunk <= kUpdates; start += kChunk) {
    const std::clock_t cpu_begin = std::clock();
    const auto begin = std::chrono::steady_clock::now();
    run(timed, data, start, kChunk, kRows);
    const auto end = std::chrono::steady_clock::now();
    const std::clock_t cpu_end = std::clock();
    wall.push_back(std::chrono::duration<double, std::micro>(end - begin).count() / kChunk);
    cpu.push_back(1e6 * static_cast<double>(cpu_end - cpu_begin) / CLOCKS_PER_SEC / kChunk);
  }
  if (!timed.theta().allFinite()) return 2;
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  std::printf(
      "us_per_update_median=%.3f (wall clock; min %.3f; cpu time median %.3f; %d x %d blocks, "
      "%zu chunks of %d updates)\n",
      wall[wall.size() / 2], wall.front(), cpu[cpu.size() / 2], kRows, kParameters, wall.size(),
      kChunk);

  if (allocations != 0) return 1;
  if (!(error < 1e-3)) return 2;
  return 0;
}
