// The Python-facing model: a shared snapshot of the immutable C++ Model (replaced, not mutated,
// when a setter runs, so a batch running without the GIL keeps a consistent model) and the
// workspace used by single-sample calls, which run with the GIL held.
#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <memory>
#include <thread>
#include <vector>

#include "arrays.hpp"
#include "batch.hpp"
#include "dynid/dynid.hpp"
#include "initialised.hpp"

namespace dynid::binding {

struct PyModel {
  std::shared_ptr<const Model> model;
  std::unique_ptr<Workspace> ws;

  explicit PyModel(Model m)
      : model(std::make_shared<const Model>(std::move(m))),
        ws(std::make_unique<Workspace>(*model)) {}

  template <class Change>
  void modify(Change change) {
    auto copy = std::make_shared<Model>(*model);
    change(*copy);
    model = std::move(copy);
  }
};

}  // namespace dynid::binding

// `self` must have been initialised (initialised.hpp).
template <>
struct pybind11::detail::type_caster<dynid::binding::PyModel>
    : dynid::binding::initialised_caster<dynid::binding::PyModel> {};

namespace dynid::binding {

using ConstVec = Eigen::Map<const VectorX>;
using OutVec = Eigen::Map<VectorX>;
using OutMat = Eigen::Map<MatrixX, 0, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;
using RowMajorMap = Eigen::Map<RowMajorMatrixX>;

// A row-major block of the output array seen as an Eigen matrix.
inline OutMat row_major(double* data, int rows, int cols) {
  return OutMat(data, rows, cols, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(1, cols));
}

// Worker threads for batch calls (dynid.set_threads); 1 by default.
int batch_threads();
void set_batch_threads(int threads);
// Threads the last batch call ran on (for tests of the splitting).
extern std::atomic<int> last_batch_threads;

// Below this many samples per thread a batch runs on one thread: starting a thread costs about
// as much as a few hundred samples.
constexpr py::ssize_t kMinSamplesPerThread = 512;

// Runs kernel(model, workspace, inputs, output) on one sample, or on each of T samples in C++
// with the GIL released, split over batch_threads() threads each with its own Workspace
// (run_batch: interruptible by Ctrl-C, fewer threads when the system refuses some); the output
// has shape `tail` or (T, *tail) and is `out` when given (output_array). Each sample's output is
// checked for finiteness right after it is written, while it is in cache.
template <class Kernel>
py::array evaluate(PyModel& self, const Samples& s, std::vector<py::ssize_t> tail, Kernel kernel,
                   py::handle out_arg = py::none()) {
  const int n = self.model->n();
  py::ssize_t per_sample = 1;
  for (py::ssize_t d : tail) per_sample *= d;
  if (!s.single) tail.insert(tail.begin(), s.count);
  py::array_t<double> out = output_array(out_arg, tail);
  double* out_data = out.mutable_data();
  const std::size_t arguments = s.size;
  if (s.single) {
    const double* in[Samples::kMaxArguments] = {};
    for (std::size_t k = 0; k < arguments; ++k) in[k] = s.row(k, 0, n);
    kernel(*self.model, *self.ws, in, out_data);
    if (!all_finite(out_data, per_sample))
      require_finite_result(out_data, per_sample, s.names.c_str());
    return out;
  }
  std::shared_ptr<const Model> model = self.model;
  const int threads = static_cast<int>(std::max<py::ssize_t>(
      1, std::min<py::ssize_t>(batch_threads(), s.count / kMinSamplesPerThread)));
  // One worker per thread, with its own Workspace (batch.hpp: chunks, Ctrl-C, thread failures).
  std::atomic<py::ssize_t> first_bad{s.count};  // the first sample with a non-finite output
  auto make_worker = [&] {
    return [&, ws = Workspace(*model)](py::ssize_t begin, py::ssize_t end) mutable {
      const double* in[Samples::kMaxArguments] = {};
      for (py::ssize_t t = begin; t < end; ++t) {
        for (std::size_t k = 0; k < arguments; ++k) in[k] = s.row(k, t, n);
        double* sample = out_data + t * per_sample;
        kernel(*model, ws, in, sample);
        if (!all_finite(sample, per_sample)) {
          py::ssize_t seen = first_bad.load();
          while (t < seen && !first_bad.compare_exchange_weak(seen, t)) {
          }
          return;
        }
      }
    };
  };
  const double work = std::max<double>(static_cast<double>(n) * n, static_cast<double>(per_sample));
  last_batch_threads = run_batch(s.count, threads, make_worker, chunk_for_work(work));
  if (first_bad < s.count)
    require_finite_result(out_data + first_bad * per_sample, per_sample, s.names.c_str());
  return out;
}

void bind_model(py::module_& m);

}  // namespace dynid::binding
