// The form of one entry of the table of Model's dynamics calls (call_table.hpp): its name, the
// names of its per-sample inputs (each (n,) for one sample or (T, n) for T), its keyword options,
// the shape of one sample's result, the per-sample kernel, the batch kernel (dynid::batch) and
// the docstring. calls.cpp generates from each entry the pybind11 method, the fast path for
// single samples, the text signature and the docstring; check_table() is the build-time check
// that every entry has all of them.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "dynid/batch.hpp"
#include "dynid/dynid.hpp"
#include "model.hpp"

namespace dynid::binding {

// The shape of one sample's result (no allocation: the fast path computes it on every call).
struct Shape {
  int ndim;
  py::ssize_t dims[3];
  py::ssize_t size() const {
    py::ssize_t s = 1;
    for (int k = 0; k < ndim; ++k) s *= dims[k];
    return s;
  }
};

// What a call returns: an array (with out=None: the caller's array may receive it), an array
// without out=, a float for one sample and an array (T,) for T (the energies), or a tuple of
// Parts arrays, views along the first axis of one result of shape (Parts, ...) or (T, Parts, ...).
struct ReturnsArrayOrOut {};
struct ReturnsArray {};
struct ReturnsFloat {};
template <int Parts>
struct ReturnsParts {
  static constexpr int parts = Parts;
};

// A keyword option of a call: its name and its default as the Python literal of the signature.
struct OptionArg {
  const char* name;
  const char* literal;  // "False" or "None"
};

// Calls without options.
struct NoOptions {
  static constexpr std::array<OptionArg, 0> args{};
  static NoOptions parse(const py::handle*, int) { return {}; }
};

// One sample: the model, the single-call workspace, the inputs (n values each), the options.
template <class Options>
struct Sample {
  const Model& model;
  Workspace& ws;
  const double* const* inputs;
  const Options& options;
  int n() const { return model.n(); }
  ConstVec operator[](int k) const { return ConstVec(inputs[k], model.n()); }
};

// T samples: the model, the batch workspace, the inputs (T, n) each, the options.
template <class Options>
struct Batch {
  const Model& model;
  BatchWorkspace& ws;
  const Eigen::Map<const RowMajorMatrixX>* inputs;
  const Options& options;
  const Eigen::Map<const RowMajorMatrixX>& operator[](int k) const { return inputs[k]; }
};

// One entry. shape(n, options) -> Shape; single(Sample, double* result) writes one sample's
// result (or returns it, for ReturnsFloat); batch(Batch, Results) -> batch::Report.
template <class Returns, class Options, std::size_t N, class ShapeOf, class Single, class BatchOf>
struct Call {
  using returns = Returns;
  using options = Options;
  static constexpr std::size_t inputs_count = N;
  const char* name;
  std::array<const char*, N> inputs;
  ShapeOf shape;
  Single single;
  BatchOf batch;
  const char* doc;
  // A std::domain_error of the kernel (M(q) not positive definite) is a ValueError naming params.
  bool params_error;
};

template <class Returns, class Options = NoOptions, std::size_t N, class ShapeOf, class Single,
          class BatchOf>
constexpr auto call(const char* name, const char* const (&inputs)[N], ShapeOf shape, Single single,
                    BatchOf batch, const char* doc, bool params_error = false) {
  std::array<const char*, N> names{};
  for (std::size_t k = 0; k < N; ++k) names[k] = inputs[k];
  return Call<Returns, Options, N, ShapeOf, Single, BatchOf>{name,  names, shape,       single,
                                                             batch, doc,   params_error};
}

// Shapes of one sample's result.
inline constexpr auto per_joint = [](int n, const auto&) { return Shape{1, {n}}; };
inline constexpr auto joint_by_joint = [](int n, const auto&) { return Shape{2, {n, n}}; };
inline constexpr auto scalar = [](int, const auto&) { return Shape{0, {}}; };

// ---------------------------------------------------------------- the build-time check
template <class C>
constexpr bool complete_entry(const C& c) {
  using Options = typename C::options;
  using Returns = typename C::returns;
  static_assert(C::inputs_count >= 1 && C::inputs_count <= Samples::kMaxArguments,
                "a call takes 1 to 5 per-sample inputs");
  static_assert(std::is_same_v<decltype(c.shape(1, std::declval<const Options&>())), Shape>,
                "shape(n, options) -> Shape");
  if constexpr (std::is_same_v<Returns, ReturnsFloat>)
    static_assert(std::is_invocable_r_v<double, decltype(c.single), const Sample<Options>&>,
                  "single(sample) -> double");
  else
    static_assert(std::is_invocable_v<decltype(c.single), const Sample<Options>&, double*>,
                  "single(sample, result)");
  static_assert(
      std::is_same_v<std::invoke_result_t<decltype(c.batch), const Batch<Options>&, batch::Results>,
                     batch::Report>,
      "batch(batch, results) -> dynid::batch::Report");
  bool ok = c.name != nullptr && c.name[0] != '\0' && c.doc != nullptr && c.doc[0] != '\0';
  for (const char* input : c.inputs) ok = ok && input != nullptr && input[0] != '\0';
  return ok;
}

// Every entry complete, and no two entries with one name.
template <class Table, std::size_t... K>
constexpr bool check_table(const Table& table, std::index_sequence<K...>) {
  const bool complete = (complete_entry(std::get<K>(table)) && ...);
  const std::array<std::string_view, sizeof...(K)> names{std::get<K>(table).name...};
  for (std::size_t a = 0; a < names.size(); ++a)
    for (std::size_t b = a + 1; b < names.size(); ++b)
      if (names[a] == names[b]) return false;
  return complete;
}

}  // namespace dynid::binding

namespace dynid::binding {
// Defines Model's dynamics calls (call_table.hpp) on the class; called by bind_model.
void bind_calls(py::class_<PyModel>& cls);
}  // namespace dynid::binding
