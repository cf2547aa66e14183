// The loop of every batch (detail/batch_runner.hpp) and the BatchWorkspace it runs on.
#include "dynid/detail/batch_runner.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <new>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace dynid {

BatchWorkspace::BatchWorkspace(const Model& model, int threads) : n_(model.n()) {
  if (threads < 1)
    throw std::invalid_argument("threads: expected at least 1, got " + std::to_string(threads) +
                                " (in dynid::BatchWorkspace)");
  slots_.reserve(static_cast<std::size_t>(threads));
  slots_.emplace_back(model);  // std::bad_alloc here: not even one thread's workspace
  try {
    while (static_cast<int>(slots_.size()) < threads) slots_.emplace_back(model);
  } catch (const std::bad_alloc&) {
    // Too little memory for all of them: fewer threads.
  }
  joints_.resize(static_cast<std::size_t>(n_));
}

namespace detail {

std::vector<BatchSlot>& slots(BatchWorkspace& ws) { return ws.slots_; }
std::vector<BatchJoint>& lane_joints(BatchWorkspace& ws) { return ws.joints_; }

namespace {
constexpr std::chrono::milliseconds kInterruptInterval{20};
}  // namespace

Eigen::Index chunk_for_work(double work_per_sample, double budget) {
  const double samples = budget / std::max(work_per_sample, 1.0);
  return samples >= static_cast<double>(kChunk)
             ? kChunk
             : std::max<Eigen::Index>(1, static_cast<Eigen::Index>(samples));
}

int batch_threads(const BatchWorkspace& ws, Eigen::Index count) {
  return static_cast<int>(std::max<Eigen::Index>(
      1, std::min<Eigen::Index>(ws.threads(), count / kMinSamplesPerThread)));
}

batch::Report run_chunks(Eigen::Index count, int threads, Eigen::Index chunk, ChunkWork work,
                         void* context, const BatchInterrupt& interrupt) {
  std::atomic<Eigen::Index> next{0};
  std::atomic<Eigen::Index> first_bad{count};
  std::atomic<bool> stop{false};
  // Claims and runs chunks until none is left or another thread stopped the batch; true when
  // the interrupt check (calling thread only) asked to stop.
  auto run = [&](int slot, bool check) {
    auto last = std::chrono::steady_clock::now();
    while (!stop.load(std::memory_order_relaxed)) {
      const Eigen::Index begin = next.fetch_add(chunk, std::memory_order_relaxed);
      if (begin >= count) return false;
      const Eigen::Index bad = work(context, slot, begin, std::min(begin + chunk, count));
      if (bad >= 0) {
        Eigen::Index seen = first_bad.load();
        while (bad < seen && !first_bad.compare_exchange_weak(seen, bad)) {
        }
      }
      if (check && interrupt.check) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last >= kInterruptInterval) {
          last = now;
          if (interrupt.check(interrupt.context)) {
            stop = true;
            return true;
          }
        }
      }
    }
    return false;
  };

  // The other threads' errors (none for a single thread: then nothing here allocates).
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(std::max(threads, 1) - 1));
  std::exception_ptr own_error;
  std::vector<std::thread> pool;
  bool interrupted = false;
  try {
    if (!errors.empty()) pool.reserve(errors.size());
    for (std::size_t k = 0; k < errors.size(); ++k) {
      pool.emplace_back([&, k] {
        try {
          run(static_cast<int>(k) + 1, false);
        } catch (...) {
          errors[k] = std::current_exception();
          stop = true;
        }
      });
    }
  } catch (const std::system_error&) {
    // The system refuses more threads: the batch runs on those started.
  } catch (const std::bad_alloc&) {
  }
  const int participants = static_cast<int>(pool.size()) + 1;
  try {
    interrupted = run(0, true);
  } catch (...) {
    own_error = std::current_exception();
    stop = true;
  }
  for (std::thread& thread : pool) thread.join();
  if (own_error) std::rethrow_exception(own_error);
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);
  if (interrupted) throw batch::Interrupted();
  const Eigen::Index bad = first_bad.load();
  return batch::Report{bad < count ? bad : -1, participants};
}

}  // namespace detail
}  // namespace dynid
