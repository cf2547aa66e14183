// The Python-facing model: a shared snapshot of the immutable C++ Model (replaced, not mutated,
// when a setter runs, so a batch running without the GIL keeps a consistent model) and the
// workspace used by single-sample calls, which run with the GIL held.
#pragma once

#include <memory>

#include "arrays.hpp"
#include "dynid/dynid.hpp"

namespace dynid::binding {

struct PyModel {
  std::shared_ptr<const Model> model;
  std::unique_ptr<Workspace> ws;

  explicit PyModel(Model m)
      : model(std::make_shared<const Model>(std::move(m))), ws(std::make_unique<Workspace>(*model)) {}

  template <class Change>
  void modify(Change change) {
    auto copy = std::make_shared<Model>(*model);
    change(*copy);
    model = std::move(copy);
  }
};

using ConstVec = Eigen::Map<const VectorX>;
using OutVec = Eigen::Map<VectorX>;
using OutMat = Eigen::Map<MatrixX, 0, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;
using RowMajorMap = Eigen::Map<RowMajorMatrixX>;

// A row-major block of the output array seen as an Eigen matrix.
inline OutMat row_major(double* data, int rows, int cols) {
  return OutMat(data, rows, cols, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(1, cols));
}

// Runs kernel(model, workspace, inputs, output) on one sample, or on each of T samples in C++
// with the GIL released; the output has shape `tail` or (T, *tail).
template <class Kernel>
py::array evaluate(PyModel& self, const Samples& s, std::vector<py::ssize_t> tail, Kernel kernel) {
  const int n = self.model->n();
  py::ssize_t per_sample = 1;
  for (py::ssize_t d : tail) per_sample *= d;
  if (!s.single) tail.insert(tail.begin(), s.count);
  py::array_t<double> out(tail);
  double* out_data = out.mutable_data();
  const double* in[4] = {nullptr, nullptr, nullptr, nullptr};
  if (s.single) {
    for (std::size_t k = 0; k < s.arrays.size(); ++k) in[k] = s.row(k, 0, n);
    kernel(*self.model, *self.ws, in, out_data);
    return out;
  }
  std::shared_ptr<const Model> model = self.model;
  {
    py::gil_scoped_release release;
    Workspace ws(*model);
    for (py::ssize_t t = 0; t < s.count; ++t) {
      for (std::size_t k = 0; k < s.arrays.size(); ++k) in[k] = s.row(k, t, n);
      kernel(*model, ws, in, out_data + t * per_sample);
    }
  }
  return out;
}

void bind_model(py::module_& m);

}  // namespace dynid::binding
