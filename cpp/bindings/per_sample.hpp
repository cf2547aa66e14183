// One definition for the Model's per-sample methods (rnea, mass_matrix, gravity, ...): each is
// "parse these length-n inputs (one sample or a batch), run this core call per sample, return an
// array of this shape", with the lane kernels for batches when the method has one. def_per_sample
// builds the pybind11 method, its arguments (the inputs, then out=None) and its docstring.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "lanes.hpp"
#include "model.hpp"

namespace dynid::binding {

// The shape of one sample's output, from the number of joints.
using OutputShape = std::vector<py::ssize_t> (*)(int n);

inline std::vector<py::ssize_t> per_joint(int n) { return {n}; }
inline std::vector<py::ssize_t> joint_by_joint(int n) { return {n, n}; }
inline std::vector<py::ssize_t> scalar(int) { return {}; }

// How a std::domain_error of the core call reaches Python: as pybind11 translates it, or as a
// ValueError naming the parameters (forward_dynamics: M(q) not positive definite).
enum class DomainError { AsIs, Params };

// No lane kernel: batches run the scalar kernel on batch_threads() threads.
struct NoLanes {};

template <std::size_t>
using InputHandle = py::handle;
template <std::size_t>
using InputVector = ConstVec;

// True when the kernel returns the sample's value (the energies) instead of writing an array.
template <class Kernel, std::size_t... I>
constexpr bool returns_scalar(std::index_sequence<I...>) {
  return std::is_invocable_r_v<double, Kernel, const Model&, Workspace&, InputVector<I>...>;
}

// The method (self, inputs..., out) -> array: kernel(model, workspace, input vectors..., output)
// is the core call on one sample, writing the row-major output of shape(n) doubles, or
// kernel(model, workspace, input vectors...) returning the sample's value; `lanes` is the
// LaneKernels member for batches, or NoLanes.
template <DomainError Errors, class Kernel, class Lanes, std::size_t... I>
auto per_sample_method(std::array<const char*, sizeof...(I)> names, OutputShape shape,
                       Kernel kernel, Lanes lanes, std::index_sequence<I...> inputs) {
  constexpr bool kScalar = returns_scalar<Kernel>(inputs);
  return [=](PyModel& self, InputHandle<I>... input, py::handle out) {
    const int n = self.model->n();
    const Samples s = parse_samples({{input, names[I]}...}, n);
    if constexpr (!std::is_same_v<Lanes, NoLanes>) {
      if (use_lanes(self, s))
        return evaluate_lanes(
            self, s, shape(n),
            [lanes](const detail::LaneKernels& k, const detail::BatchModel& bm,
                    const double* const* in, double* result,
                    long T) { return (k.*lanes)(bm, in[I]..., result, T); },
            out);
    }
    auto run = [&] {
      return evaluate(
          self, s, shape(n),
          [n, kernel](const Model& m, Workspace& ws, const double* const* in, double* result) {
            if constexpr (kScalar)
              *result = kernel(m, ws, ConstVec(in[I], n)...);
            else
              kernel(m, ws, ConstVec(in[I], n)..., result);
          },
          out);
    };
    if constexpr (Errors == DomainError::Params) {
      try {
        return run();
      } catch (const std::domain_error& e) {
        throw py::value_error(std::string("params: ") + e.what());
      }
    } else {
      return run();
    }
  };
}

// The energies: a float for one sample (the 0-d result), an array (T,) for a batch; no `out`.
template <class Method, std::size_t... I>
auto scalar_method(Method method, std::index_sequence<I...>) {
  return [method](PyModel& self, InputHandle<I>... input) -> py::object {
    py::array result = method(self, input..., py::none());
    if (result.ndim() == 0) return py::float_(*static_cast<const double*>(result.data()));
    return result;
  };
}

template <class Method, std::size_t N, std::size_t... I, class... Extra>
void def_with_inputs(py::class_<PyModel>& cls, const char* name, Method method,
                     const std::array<const char*, N>& names, std::index_sequence<I...>,
                     const Extra&... extra) {
  cls.def(name, method, py::arg(names[I])..., extra...);
}

// Defines `name(inputs..., out=None)` returning an array shape(n), or (T, *shape(n)) for a batch
// of T samples; a scalar kernel (the energies) gives `name(inputs...)` returning a float, or an
// array (T,) for a batch.
template <DomainError Errors = DomainError::AsIs, std::size_t N, class Kernel,
          class Lanes = NoLanes>
void def_per_sample(py::class_<PyModel>& cls, const char* name, const char* const (&inputs)[N],
                    OutputShape shape, Kernel kernel, const char* doc, Lanes lanes = {}) {
  std::array<const char*, N> names{};
  for (std::size_t k = 0; k < N; ++k) names[k] = inputs[k];
  const auto indices = std::make_index_sequence<N>();
  auto method = per_sample_method<Errors>(names, shape, kernel, lanes, indices);
  if constexpr (returns_scalar<Kernel>(std::make_index_sequence<N>())) {
    def_with_inputs(cls, name, scalar_method(method, indices), names, indices, doc);
  } else {
    def_with_inputs(cls, name, method, names, indices, py::arg("out") = py::none(), doc);
  }
}

}  // namespace dynid::binding
