// Batches on the SIMD lane kernels (dynid/detail/batch.hpp): the samples split over the batch
// threads in whole vectors, each thread running the kernel on its contiguous share with the GIL
// released, the first non-finite result reported like evaluate()'s.
#pragma once

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

#include "dynid/detail/batch.hpp"
#include "model.hpp"

namespace dynid::binding {

// True when a batch of `s` should use the lane kernels.
inline bool use_lanes(const PyModel& self, const Samples& s, int max_joints = detail::kMaxBatchJoints) {
  return !s.single && s.count > 0 && detail::batch_kernels() != nullptr &&
         self.model->n() <= max_joints;
}

// kernel(kernels, batch_model, inputs (each at sample `begin`), output at `begin`, count) returns
// the first non-finite sample relative to `begin`, or -1.
template <class Kernel>
py::array evaluate_lanes(PyModel& self, const Samples& s, std::vector<py::ssize_t> tail,
                         Kernel kernel, py::handle out_arg) {
  const int n = self.model->n();
  py::ssize_t per_sample = 1;
  for (py::ssize_t d : tail) per_sample *= d;
  tail.insert(tail.begin(), s.count);
  py::array_t<double> out = output_array(out_arg, tail);
  double* out_data = out.mutable_data();
  std::shared_ptr<const Model> model = self.model;
  std::vector<detail::BatchJoint> joints;
  const detail::BatchModel bm = detail::batch_model(*model, joints);
  const detail::LaneKernels& k = *detail::batch_kernels();
  const py::ssize_t threads = std::max<py::ssize_t>(
      1, std::min<py::ssize_t>(batch_threads(), s.count / kMinSamplesPerThread));
  std::vector<long> bad(threads, -1);
  auto run = [&](py::ssize_t part) {
    // Shares in whole vectors, so only the last one has a partial vector.
    const py::ssize_t vectors = (s.count + k.lanes - 1) / k.lanes;
    const py::ssize_t begin = std::min(s.count, vectors * part / threads * k.lanes);
    const py::ssize_t end = std::min(s.count, vectors * (part + 1) / threads * k.lanes);
    if (end <= begin) return;
    const double* in[3] = {nullptr, nullptr, nullptr};
    for (std::size_t a = 0; a < s.size; ++a) in[a] = s.row(a, begin, n);
    const long first = kernel(k, bm, in, out_data + begin * per_sample, static_cast<long>(end - begin));
    if (first >= 0) bad[part] = static_cast<long>(begin) + first;
  };
  {
    py::gil_scoped_release release;
    last_batch_threads = static_cast<int>(threads);
    if (threads == 1) {
      run(0);
    } else {
      std::vector<std::thread> pool;
      for (py::ssize_t part = 0; part < threads; ++part) pool.emplace_back(run, part);
      for (std::thread& worker : pool) worker.join();
    }
  }
  for (long first : bad)
    if (first >= 0) require_finite_result(out_data + first * per_sample, per_sample, s.names.c_str());
  return out;
}

void bind_batch(py::module_& m);

}  // namespace dynid::binding
