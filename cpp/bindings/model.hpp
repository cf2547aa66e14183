// The Python-facing model: a shared snapshot of the immutable C++ Model (replaced, not mutated,
// when a setter runs, so a batch running without the GIL keeps a consistent model) and the
// workspace used by single-sample calls, which run with the GIL held.
#pragma once

#include <atomic>
#include <memory>

#include "arrays.hpp"
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

void bind_model(py::module_& m);

}  // namespace dynid::binding
