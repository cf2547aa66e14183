// Batches on the SIMD lane kernels (dynid/detail/batch.hpp): run_batch's chunks (batch.hpp:
// threads, Ctrl-C) of kChunk samples, a multiple of every lane count, the first non-finite
// result reported like evaluate()'s.
#pragma once

#include <algorithm>
#include <atomic>
#include <vector>

#include "batch.hpp"
#include "dynid/detail/batch.hpp"
#include "model.hpp"

namespace dynid::binding {

// True when a batch of `s` should use the lane kernels. Their drive terms are per joint (T = I),
// so a model with a coupled transmission runs the scalar kernels (detail/drive_terms.hpp).
inline bool use_lanes(const PyModel& self, const Samples& s,
                      int max_joints = detail::kMaxBatchJoints) {
  return !s.single && s.count > 0 && detail::batch_kernels() != nullptr &&
         self.model->n() <= max_joints && self.model->transmission_is_identity();
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
  const int threads = static_cast<int>(std::max<py::ssize_t>(
      1, std::min<py::ssize_t>(batch_threads(), s.count / kMinSamplesPerThread)));
  static_assert(kChunk % 8 == 0, "chunks in whole vectors of every lane count");
  std::atomic<py::ssize_t> first_bad{s.count};
  auto make_worker = [&] {
    return [&](py::ssize_t begin, py::ssize_t end) {
      const double* in[3] = {nullptr, nullptr, nullptr};
      for (std::size_t a = 0; a < s.size; ++a) in[a] = s.row(a, begin, n);
      const long first =
          kernel(k, bm, in, out_data + begin * per_sample, static_cast<long>(end - begin));
      if (first >= 0) {
        py::ssize_t seen = first_bad.load();
        const py::ssize_t t = begin + first;
        while (t < seen && !first_bad.compare_exchange_weak(seen, t)) {
        }
      }
    };
  };
  last_batch_threads = run_batch(s.count, threads, make_worker, kChunk);
  if (first_bad < s.count)
    require_finite_result(out_data + first_bad * per_sample, per_sample, s.names.c_str());
  return out;
}

void bind_lanes(py::module_& m);

}  // namespace dynid::binding
