// The batch loop of the binding: T independent samples evaluated in C++ with the GIL released,
// in chunks claimed from a shared counter by up to `threads` threads (the calling one included).
//
// - Ctrl-C: between chunks the calling thread takes the GIL every kInterruptInterval and runs
//   Python's signal handlers (PyErr_CheckSignals); when one raises (KeyboardInterrupt), every
//   thread stops after its current chunk and the exception propagates. A chunk is a few
//   milliseconds of work, so a batch stops within a few tens of milliseconds.
// - Threads that cannot be started (the system's thread limit, no memory for a stack or a
//   workspace) are not an error: the batch runs on the threads that did start, at least the
//   calling one (dynid.set_threads documents this). No memory for even one workspace raises
//   MemoryError. An exception in any thread stops the others and is raised after all joined.
#pragma once

#include <pybind11/pybind11.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <new>
#include <optional>
#include <system_error>
#include <thread>
#include <vector>

namespace dynid::binding {

namespace py = pybind11;

// Samples claimed at a time by default: large enough that the shared counter and the clock are
// read rarely, small enough that a chunk takes a millisecond or less (about 1 us per sample for
// n = 7). chunk_for_work() scales it down for costlier samples.
constexpr py::ssize_t kChunk = 256;

// A chunk of about `budget` elementary operations when one sample costs `work_per_sample`.
inline py::ssize_t chunk_for_work(double work_per_sample, double budget = 65536.0) {
  const double samples = budget / std::max(work_per_sample, 1.0);
  return samples >= static_cast<double>(kChunk)
             ? kChunk
             : std::max<py::ssize_t>(1, static_cast<py::ssize_t>(samples));
}
constexpr std::chrono::milliseconds kInterruptInterval{20};

// True when a Python signal handler raised (its exception is then pending); checks at most
// every kInterruptInterval. Called with the GIL released, from the thread that released it.
class InterruptCheck {
 public:
  bool raised() {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < kInterruptInterval) return false;
    last_ = now;
    py::gil_scoped_acquire gil;
    return PyErr_CheckSignals() != 0;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// Runs worker(begin, end) over [0, count) in chunks of `chunk` samples; make_worker() builds one
// worker per thread (in that thread: its workspace). Call with the GIL held; returns the number of
// threads that took part. Raises the first exception of any thread, or the signal handler's
// exception.
template <class MakeWorker>
int run_batch(py::ssize_t count, int threads, MakeWorker make_worker, py::ssize_t chunk = kChunk) {
  using Worker = decltype(make_worker());
  std::atomic<py::ssize_t> next{0};
  std::atomic<bool> stop{false};
  int participants = 1;
  // Claims and runs chunks until none is left or another thread stopped the batch; true when
  // the caller's interrupt check raised.
  auto work = [&](Worker& worker, InterruptCheck* interrupt) {
    while (!stop.load(std::memory_order_relaxed)) {
      const py::ssize_t begin = next.fetch_add(chunk, std::memory_order_relaxed);
      if (begin >= count) return false;
      worker(begin, std::min(begin + chunk, count));
      if (interrupt && interrupt->raised()) {
        stop = true;
        return true;
      }
    }
    return false;
  };

  // Every worker (its workspace) is made here, before any thread starts: a started thread then
  // allocates nothing and touches no thread-local storage of its own unless a kernel throws, so
  // it cannot fail for lack of memory (glibc aborts the process when it cannot allocate a
  // thread's dynamic TLS). Too little memory for all of them means fewer threads; for none, the
  // std::bad_alloc is raised (MemoryError).
  std::vector<std::optional<Worker>> workers(static_cast<std::size_t>(std::max(threads, 1)));
  workers[0].emplace(make_worker());
  std::size_t ready = 1;
  try {
    for (; ready < workers.size(); ++ready) workers[ready].emplace(make_worker());
  } catch (const std::bad_alloc&) {
  }
  std::vector<std::exception_ptr> errors(ready);
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    std::vector<std::thread> pool;
    try {
      pool.reserve(ready - 1);
      for (std::size_t k = 1; k < ready; ++k) {
        pool.emplace_back([&, k] {
          try {
            work(*workers[k], nullptr);
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
    participants = static_cast<int>(pool.size()) + 1;
    try {
      InterruptCheck interrupt;
      interrupted = work(*workers[0], &interrupt);
    } catch (...) {
      errors[0] = std::current_exception();
      stop = true;
    }
    for (std::thread& thread : pool) thread.join();
  }
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);
  if (interrupted) throw py::error_already_set();  // the signal handler's exception
  return participants;
}

}  // namespace dynid::binding
