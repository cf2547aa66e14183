#include "arrays.hpp"

#include <cmath>
#include <stdexcept>

namespace dynid::binding {

std::string shape_string(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) {
    if (k) s += ", ";
    s += std::to_string(a.shape(k));
  }
  if (a.ndim() == 1) s += ",";
  return s + ")";
}

Array as_real_array(py::handle obj, const char* name) {
  py::array raw = py::array::ensure(obj);
  if (!raw) {
    throw py::value_error(std::string(name) + ": expected an array of real numbers, got " +
                          std::string(py::str(py::type::of(obj).attr("__name__"))));
  }
  const char kind = raw.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::value_error(std::string(name) + ": expected real numbers, got dtype " +
                          std::string(py::str(raw.dtype())));
  }
  return Array::ensure(raw);
}

void require_finite(const Array& a, const char* name) {
  const double* data = a.data();
  for (py::ssize_t k = 0; k < a.size(); ++k) {
    if (!std::isfinite(data[k]))
      throw py::value_error(std::string(name) + ": contains NaN or inf (element " +
                            std::to_string(k) + ")");
  }
}

Samples parse_samples(const std::vector<std::pair<py::handle, const char*>>& args, int n) {
  Samples s;
  const std::string expected =
      "expected shape (" + std::to_string(n) + ",) or (T, " + std::to_string(n) + ")";
  for (std::size_t k = 0; k < args.size(); ++k) {
    const char* name = args[k].second;
    Array a = as_real_array(args[k].first, name);
    const bool ok = (a.ndim() == 1 || a.ndim() == 2) && a.shape(a.ndim() - 1) == n;
    if (!ok) throw py::value_error(std::string(name) + ": " + expected + ", got " + shape_string(a));
    if (k == 0) {
      s.single = a.ndim() == 1;
      s.count = s.single ? 1 : a.shape(0);
    } else if ((a.ndim() == 1) != s.single || (!s.single && a.shape(0) != s.count)) {
      throw py::value_error(std::string(name) + ": expected shape " + shape_string(s.arrays[0]) +
                            " like " + args[0].second + ", got " + shape_string(a));
    }
    require_finite(a, name);
    s.arrays.push_back(std::move(a));
  }
  return s;
}

Array parse_fixed(py::handle obj, const char* name, const std::vector<py::ssize_t>& shape) {
  Array a = as_real_array(obj, name);
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
  for (std::size_t k = 0; ok && k < shape.size(); ++k) ok = a.shape(k) == shape[k];
  if (!ok) {
    std::string want = "(";
    for (std::size_t k = 0; k < shape.size(); ++k) want += (k ? ", " : "") + std::to_string(shape[k]);
    if (shape.size() == 1) want += ",";
    throw py::value_error(std::string(name) + ": expected shape " + want + "), got " +
                          shape_string(a));
  }
  require_finite(a, name);
  return a;
}

}  // namespace dynid::binding
