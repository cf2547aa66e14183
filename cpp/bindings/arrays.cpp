#include "arrays.hpp"

#include "dynid/detail/batch.hpp"
#include "result_pool.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace dynid::binding {

namespace {
// Inputs of at least this many values are checked by the SIMD lanes (the call through a function
// pointer and the vectors' set-up cost more than they save on a single sample's few values).
constexpr py::ssize_t kLanesCheckSize = 64;
}  // namespace

std::string shape_string(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) {
    if (k) s += ", ";
    s += std::to_string(a.shape(k));
  }
  if (a.ndim() == 1) s += ",";
  return s + ")";
}

namespace {

// NumPy's conversion of obj (PyArray_FromAny, as py::array::ensure, which however discards the
// error): to float64 C-contiguous when as_double, else to an array of any dtype. A null result
// leaves NumPy's error pending.
py::object numpy_array(py::handle obj, bool as_double) {
  auto& api = py::detail::npy_api::get();
  PyObject* descr = as_double ? py::dtype::of<double>().release().ptr() : nullptr;
  const int flags = py::detail::npy_api::NPY_ARRAY_ENSUREARRAY_ |
                    (as_double ? py::array::c_style | py::array::forcecast : 0);
  return py::reinterpret_steal<py::object>(
      api.PyArray_FromAny_(obj.ptr(), descr, 0, 0, flags, nullptr));
}

// A conversion that failed for lack of memory (a huge list, or the float64 copy of a broadcast
// view) is a MemoryError naming the argument, never a null array dereferenced later.
void raise_if_out_of_memory(const char* name) {
  if (!PyErr_Occurred() || !PyErr_ExceptionMatches(PyExc_MemoryError)) return;
  const py::error_already_set numpy_error;  // fetches and clears it
  PyErr_Format(PyExc_MemoryError, "%s: not enough memory to convert it to a float64 array (%s)",
               name, numpy_error.what());
  throw py::error_already_set();
}

}  // namespace

Array as_real_array(py::handle obj, const char* name) {
  // Fast path: already a C-contiguous float64 array (no conversion, no dtype inspection).
  if (py::isinstance<Array>(obj)) return py::reinterpret_borrow<Array>(obj);
  py::object converted = numpy_array(obj, false);
  if (!converted) {
    raise_if_out_of_memory(name);
    PyErr_Clear();
    throw py::value_error(std::string(name) + ": expected an array of real numbers, got " +
                          std::string(py::str(py::type::of(obj).attr("__name__"))));
  }
  const py::array raw = py::reinterpret_borrow<py::array>(converted);
  const char kind = raw.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::value_error(std::string(name) + ": expected real numbers, got dtype " +
                          std::string(py::str(raw.dtype())));
  }
  converted = numpy_array(raw, true);
  if (!converted) {
    raise_if_out_of_memory(name);
    throw py::error_already_set();  // NumPy's own error (always set when the result is null)
  }
  return py::reinterpret_steal<Array>(converted.release());
}

void require_finite(const Array& a, const char* name) {
  const double* data = a.data();
  const py::ssize_t size = a.size();
  // The common case, without a branch per value; large inputs by the SIMD lanes (the three
  // 10^4 x 7 inputs of a batch rnea: 19 us instead of 44 us, a twentieth of the call's time).
  if (size >= kLanesCheckSize ? detail::all_finite_many(data, size) : all_finite(data, size))
    return;
  for (py::ssize_t k = 0; k < size; ++k) {
    if (!std::isfinite(data[k]))
      throw py::value_error(std::string(name) + ": contains NaN or inf (element " +
                            std::to_string(k) + ")");
  }
}

Samples parse_samples(std::initializer_list<std::pair<py::handle, const char*>> args, int n) {
  Samples s;
  const char* first_name = nullptr;
  py::ssize_t first_ndim = 0;
  for (const auto& [obj, name] : args) {
    Array a = as_real_array(obj, name);
    const bool ok = (a.ndim() == 1 || a.ndim() == 2) && a.shape(a.ndim() - 1) == n;
    if (!ok)
      throw py::value_error(std::string(name) + ": expected shape (" + std::to_string(n) +
                            ",) or (T, " + std::to_string(n) + "), got " + shape_string(a));
    if (s.size == 0) {
      first_name = name;
      first_ndim = a.ndim();
      s.single = a.ndim() == 1;
      s.count = s.single ? 1 : a.shape(0);
    } else if (a.ndim() != first_ndim || (!s.single && a.shape(0) != s.count)) {
      const std::string expected =
          s.single ? "(" + std::to_string(n) + ",)"
                   : "(" + std::to_string(s.count) + ", " + std::to_string(n) + ")";
      throw py::value_error(std::string(name) + ": expected shape " + expected + " like " +
                            first_name + ", got " + shape_string(a));
    }
    require_finite(a, name);
    if (s.size) s.names += ", ";
    s.names += name;
    s.data[s.size] = a.data();
    s.owners[s.size] = std::move(a);
    ++s.size;
  }
  return s;
}

// The dtype kind of a scalar argument ('i', 'u', 'f', 'b', ...), '\0' when it is not a scalar;
// NumPy scalars and 0-d arrays count as scalars.
namespace {
char scalar_kind(py::handle obj) {
  py::array a = py::array::ensure(obj);
  if (!a) PyErr_Clear();
  return a && a.ndim() == 0 ? a.dtype().kind() : '\0';
}
}  // namespace

int parse_count(py::handle obj, const char* name) {
  const char kind = scalar_kind(obj);
  if (kind != 'i' && kind != 'u')
    throw py::value_error(std::string(name) + ": expected an integer, got " +
                          std::string(py::repr(obj)));
  const py::int_ value(py::reinterpret_borrow<py::object>(obj));  // __index__
  if (value < py::int_(1))
    throw py::value_error(std::string(name) + ": expected an integer >= 1, got " +
                          std::string(py::repr(obj)));
  if (value > py::int_(std::numeric_limits<int>::max()))
    throw py::value_error(std::string(name) + ": too large, got " + std::string(py::repr(obj)));
  return value.cast<int>();
}

double parse_number(py::handle obj, const char* name) {
  const char kind = scalar_kind(obj);
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::value_error(std::string(name) + ": expected a number, got " +
                          std::string(py::repr(obj)));
  return py::float_(py::reinterpret_borrow<py::object>(obj)).cast<double>();
}

bool parse_flag(py::handle obj, const char* name) {
  if (scalar_kind(obj) != 'b')
    throw py::value_error(std::string(name) + ": expected True or False, got " +
                          std::string(py::repr(obj)));
  return PyObject_IsTrue(obj.ptr()) == 1;
}

void require_finite_result(const double* data, py::ssize_t n, const char* names) {
  for (py::ssize_t k = 0; k < n; ++k) {
    if (!std::isfinite(data[k]))
      throw py::value_error(std::string(names) +
                            ": the result overflowed to inf/NaN (inputs or parameters too large "
                            "for double precision arithmetic)");
  }
}

bool all_finite(const double* data, py::ssize_t n) {
  // x * 0 is 0 for finite x and NaN otherwise: one branch for the whole block. Four sums, so that
  // the additions do not wait for each other (a single sum is bound by the adder's latency).
  double c0 = 0.0, c1 = 0.0, c2 = 0.0, c3 = 0.0;
  py::ssize_t k = 0;
  for (; k + 4 <= n; k += 4) {
    c0 += data[k] * 0.0;
    c1 += data[k + 1] * 0.0;
    c2 += data[k + 2] * 0.0;
    c3 += data[k + 3] * 0.0;
  }
  for (; k < n; ++k) c0 += data[k] * 0.0;
  return (c0 + c1) + (c2 + c3) == 0.0;
}

py::array_t<double> output_array(py::handle out, const std::vector<py::ssize_t>& shape) {
  if (out.is_none()) return new_result_array(shape);
  std::string want = "(";
  for (std::size_t k = 0; k < shape.size(); ++k) want += (k ? ", " : "") + std::to_string(shape[k]);
  want += shape.size() == 1 ? ",)" : ")";
  if (!py::isinstance<py::array>(out))
    throw py::value_error("out: expected a NumPy float64 array of shape " + want + ", got " +
                          std::string(py::str(py::type::of(out).attr("__name__"))));
  py::array a = py::reinterpret_borrow<py::array>(out);
  if (!a.dtype().equal(py::dtype::of<double>()))
    throw py::value_error("out: expected dtype float64, got " + std::string(py::str(a.dtype())));
  bool same = a.ndim() == static_cast<py::ssize_t>(shape.size());
  for (std::size_t k = 0; same && k < shape.size(); ++k) same = a.shape(k) == shape[k];
  if (!same) throw py::value_error("out: expected shape " + want + ", got " + shape_string(a));
  if (!(a.flags() & py::array::c_style))
    throw py::value_error("out: expected a C-contiguous array");
  if (!a.writeable()) throw py::value_error("out: expected a writable array");
  return py::reinterpret_borrow<py::array_t<double>>(out);
}

std::vector<int> parse_columns(py::handle obj, int count) {
  py::array raw = py::array::ensure(obj);
  if (!raw) PyErr_Clear();
  const char kind = raw ? raw.dtype().kind() : '\0';
  if (!raw || raw.ndim() != 1 || raw.size() == 0 || (kind != 'i' && kind != 'u'))
    throw py::value_error(
        "columns: expected a non-empty 1-D array of integer column indices, got " +
        std::string(py::repr(obj)));
  const auto values =
      py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(raw);
  std::vector<int> columns(static_cast<std::size_t>(values.size()));
  for (py::ssize_t k = 0; k < values.size(); ++k) {
    const long long c = values.data()[k];
    if (c < 0 || c >= count)
      throw py::value_error("columns: expected indices in [0, " + std::to_string(count) +
                            "), got " + std::to_string(c) + " at position " + std::to_string(k));
    columns[static_cast<std::size_t>(k)] = static_cast<int>(c);
  }
  return columns;
}

Array parse_fixed(py::handle obj, const char* name, const std::vector<py::ssize_t>& shape) {
  Array a = as_real_array(obj, name);
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
  for (std::size_t k = 0; ok && k < shape.size(); ++k) ok = a.shape(k) == shape[k];
  if (!ok) {
    std::string want = "(";
    for (std::size_t k = 0; k < shape.size(); ++k)
      want += (k ? ", " : "") + std::to_string(shape[k]);
    if (shape.size() == 1) want += ",";
    throw py::value_error(std::string(name) + ": expected shape " + want + "), got " +
                          shape_string(a));
  }
  require_finite(a, name);
  return a;
}

}  // namespace dynid::binding
