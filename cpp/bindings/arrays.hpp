// Conversion and validation of NumPy inputs for the binding: every check names the argument,
// says what was expected and what was given (docs/conventions.md, "Bad input"), and nothing reaches
// the core unless it is finite and shaped right.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace dynid::binding {

namespace py = pybind11;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string shape_string(const py::array& a);

// Any array-like of real numbers as a C-contiguous float64 array; ValueError otherwise.
Array as_real_array(py::handle obj, const char* name);

// Raises ValueError when the array holds NaN or inf.
void require_finite(const Array& a, const char* name);

// One to five per-sample arguments (q, qd, ...): each (n,) for one sample or (T, n) for T.
// Fixed-size storage: parsing a single sample allocates nothing beyond NumPy's own objects.
struct Samples {
  static constexpr std::size_t kMaxArguments = 5;
  py::object owners[kMaxArguments];  // keep converted arrays alive
  const double* data[kMaxArguments] = {};
  std::string names;  // "q, qd, qdd": for errors about the result
  std::size_t size = 0;
  py::ssize_t count = 1;  // T
  bool single = true;
  const double* row(std::size_t k, py::ssize_t t, int n) const { return data[k] + t * n; }
};

Samples parse_samples(std::initializer_list<std::pair<py::handle, const char*>> args, int n);

// Scalars with the type checks of docs/conventions.md, "Bad input" (a wrong type is a ValueError
// naming the argument, not pybind11's TypeError). NumPy scalars and 0-d arrays count as scalars.
int parse_count(py::handle obj, const char* name);      // an integer >= 1
double parse_number(py::handle obj, const char* name);  // a real number
bool parse_flag(py::handle obj, const char* name);      // True or False

// Raises ValueError naming `names` when the n values at `data` are not all finite: an overflow
// from inputs (or parameters) too large for the arithmetic, never returned as NaN.
void require_finite_result(const double* data, py::ssize_t n, const char* names);

// True when the n values at `data` are all finite.
bool all_finite(const double* data, py::ssize_t n);

// The result array of a call: a new one of `shape`, or the caller's `out` when given, which must
// be a writable, C-contiguous float64 array of exactly that shape (ValueError naming `out`).
py::array_t<double> output_array(py::handle out, const std::vector<py::ssize_t>& shape);

// A 1-D, non-empty array of integer column indices, each in [0, count) (ValueError naming
// `columns` otherwise).
std::vector<int> parse_columns(py::handle obj, int count);

// A fixed-size array argument (e.g. gravity (3,), base (4, 4)).
Array parse_fixed(py::handle obj, const char* name, const std::vector<py::ssize_t>& shape);

}  // namespace dynid::binding
