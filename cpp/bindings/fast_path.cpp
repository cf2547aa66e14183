#include "fast_path.hpp"

#include <string>

namespace dynid::binding {

namespace npy = py::detail;

const double* plain_vector(PyObject* obj, int n) {
  const auto& api = npy::npy_api::get();
  if (!api.PyArray_Check_(obj)) return nullptr;
  const auto* a = npy::array_proxy(obj);
  if (a->nd != 1 || a->dimensions[0] != n) return nullptr;
  const int need = npy::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | npy::npy_api::NPY_ARRAY_ALIGNED_;
  if ((a->flags & need) != need) return nullptr;
  const auto* d = npy::array_descriptor_proxy(a->descr);
  if (d->type_num != npy::npy_api::NPY_DOUBLE_ || d->byteorder == '>') return nullptr;
  const auto* data = reinterpret_cast<const double*>(a->data);
  if (!all_finite(data, n)) return nullptr;  // the full path names the argument
  return data;
}

PyObject* new_array(const Shape& shape) {
  const auto& api = npy::npy_api::get();
  Py_intptr_t dims[3] = {shape.dims[0], shape.dims[1], shape.dims[2]};
  return api.PyArray_NewFromDescr_(api.PyArray_Type_,
                                   api.PyArray_DescrFromType_(npy::npy_api::NPY_DOUBLE_),
                                   shape.ndim, dims, nullptr, nullptr, 0, nullptr);
}

PyObject* fallback(PyObject* method, PyObject* self, PyObject* const* args, Py_ssize_t nargsf,
                   PyObject* kwnames) {
  const Py_ssize_t nargs = PyVectorcall_NARGS(nargsf);
  const Py_ssize_t total = nargs + (kwnames ? PyTuple_GET_SIZE(kwnames) : 0);
  PyObject* stack[16];
  if (total + 1 > 16) {
    PyErr_SetString(PyExc_TypeError, "too many arguments");
    return nullptr;
  }
  stack[0] = self;
  for (Py_ssize_t k = 0; k < total; ++k) stack[k + 1] = args[k];
  return PyObject_Vectorcall(method, stack, nargs + 1, kwnames);
}

PyModel* fast_model(PyObject* self, Py_ssize_t nargsf, PyObject* kwnames, Py_ssize_t count) {
  if (kwnames || PyVectorcall_NARGS(nargsf) != count) return nullptr;
  py::detail::make_caster<PyModel> caster;
  try {  // an object made by __new__ without __init__: the full method raises the TypeError
    if (!caster.load(self, false)) return nullptr;
  } catch (...) {
    return nullptr;
  }
  return &py::detail::cast_op<PyModel&>(caster);
}

PyObject* install_fast_method(py::handle cls, PyMethodDef& def) {
  py::object full = cls.attr(def.ml_name);  // the pybind11 method (a plain function)
  PyObject* descriptor = PyDescr_NewMethod(reinterpret_cast<PyTypeObject*>(cls.ptr()), &def);
  if (!descriptor) throw py::error_already_set();
  py::object fast = py::reinterpret_steal<py::object>(descriptor);
  cls.attr((std::string("_") + def.ml_name + "_full").c_str()) = full;
  cls.attr(def.ml_name) = fast;
  return full.release().ptr();
}

}  // namespace dynid::binding
