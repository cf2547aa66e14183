// The Python-facing model: a shared snapshot of the immutable C++ Model (replaced, not mutated,
// when a setter runs, so a batch running without the GIL keeps a consistent model) and the
// workspace used by single-sample calls, which run with the GIL held.
#pragma once

#include <algorithm>
#include <atomic>
#include <memory>
#include <vector>

#include "arrays.hpp"
#include "dynid/detail/batch_runner.hpp"
#include "dynid/dynid.hpp"
#include "initialised.hpp"
#include "without_gil.hpp"

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

// The workspaces a batch of `count` samples needs: one per thread it will run on
// (dynid.set_threads; fewer below detail::kMinSamplesPerThread samples per thread).
inline int batch_workspace_threads(py::ssize_t count) {
  return static_cast<int>(std::min<py::ssize_t>(
      batch_threads(), std::max<py::ssize_t>(1, count / detail::kMinSamplesPerThread)));
}

// For per-sample calls that are not Model methods of call_table.hpp (e.g. laws.cpp):
// kernel(model, workspace, inputs (n values each), output) on one sample with the model's
// workspace, or on each of T samples through the core's batch loop (detail::run_chunks: the
// threads of dynid.set_threads, each with its own workspace; Ctrl-C) without the GIL. The output
// has shape `tail` or (T, *tail) and is `out` when given (output_array); each sample's output is
// checked for finiteness right after it is written.
template <class Kernel>
py::array evaluate(PyModel& self, const Samples& s, std::vector<py::ssize_t> tail, Kernel kernel,
                   py::handle out_arg = py::none()) {
  const int n = self.model->n();
  py::ssize_t per_sample = 1;
  for (py::ssize_t d : tail) per_sample *= d;
  if (!s.single) tail.insert(tail.begin(), s.count);
  py::array_t<double> out = output_array(out_arg, tail);
  double* out_data = out.mutable_data();
  if (s.single) {
    const double* in[Samples::kMaxArguments] = {};
    for (std::size_t k = 0; k < s.size; ++k) in[k] = s.row(k, 0, n);
    kernel(*self.model, *self.ws, in, out_data);
    if (!all_finite(out_data, per_sample))
      require_finite_result(out_data, per_sample, s.names.c_str());
    return out;
  }
  const std::shared_ptr<const Model> model = self.model;  // alive while the GIL is released
  BatchWorkspace ws(*model, batch_workspace_threads(s.count));
  std::vector<detail::BatchSlot>& slots = detail::slots(ws);
  auto work = [&](int slot, Eigen::Index begin, Eigen::Index end) -> Eigen::Index {
    Workspace& w = slots[static_cast<std::size_t>(slot)].ws;
    const double* in[Samples::kMaxArguments] = {};
    for (Eigen::Index t = begin; t < end; ++t) {
      for (std::size_t k = 0; k < s.size; ++k) in[k] = s.row(k, t, n);
      double* sample = out_data + t * per_sample;
      kernel(*model, w, in, sample);
      if (!all_finite(sample, per_sample)) return t;
    }
    return -1;
  };
  const double cost = std::max<double>(static_cast<double>(n) * n, static_cast<double>(per_sample));
  const batch::Report report = without_gil([&] {
    return detail::run_chunks(s.count, detail::batch_threads(ws, s.count),
                              detail::chunk_for_work(cost), work, python_interrupt());
  });
  last_batch_threads = report.threads;
  if (report.first_nonfinite >= 0)
    require_finite_result(out_data + report.first_nonfinite * per_sample, per_sample,
                          s.names.c_str());
  return out;
}

void bind_model(py::module_& m);

}  // namespace dynid::binding
