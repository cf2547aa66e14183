// A fast path for single-sample calls: rnea(q, qd, qdd), mass_matrix(q) and gravity(q) with
// positional float64 vectors of length n, entered through CPython's vectorcall protocol
// (METH_FASTCALL) instead of pybind11's generic dispatch, with the result allocated by NumPy's
// C API directly. Everything else (keywords, out=, batches, lists, other dtypes, wrong shapes,
// non-finite values) goes to the pybind11 method unchanged, so behaviour and error messages are
// those of model.cpp; the fast path only skips work for the inputs that need none.
#include <Python.h>

#include <string>

#include "fast_calls.hpp"

namespace dynid::binding {
namespace {

namespace npy = py::detail;

// The pybind11 methods, called for everything the fast path does not take.
PyObject* g_rnea = nullptr;
PyObject* g_mass_matrix = nullptr;
PyObject* g_gravity = nullptr;

// `obj` as the data of a float64, aligned, C-contiguous, 1-D array of n finite values, or
// nullptr.
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

PyObject* new_array(int rows, int cols) {
  const auto& api = npy::npy_api::get();
  Py_intptr_t dims[2] = {rows, cols};
  return api.PyArray_NewFromDescr_(api.PyArray_Type_, api.PyArray_DescrFromType_(npy::npy_api::NPY_DOUBLE_),
                                   cols ? 2 : 1, dims, nullptr, nullptr, 0, nullptr);
}

// Calls the pybind11 method with the same arguments.
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

// The model behind `self` when the call fits the fast path (positional, `count` arguments).
PyModel* fast_model(PyObject* self, Py_ssize_t nargsf, PyObject* kwnames, Py_ssize_t count) {
  if (kwnames || PyVectorcall_NARGS(nargsf) != count) return nullptr;
  py::detail::make_caster<PyModel> caster;
  if (!caster.load(self, false)) return nullptr;
  return &py::detail::cast_op<PyModel&>(caster);
}

// Runs `kernel` on the single sample and returns the result, or nullptr with a Python error set
// (a non-finite result goes through the full path, which raises the named ValueError).
template <class Kernel>
PyObject* run(PyObject* method, PyObject* self, PyObject* const* args, Py_ssize_t nargsf,
              PyObject* kwnames, PyModel& model, int rows, int cols, Kernel kernel) {
  PyObject* out = new_array(rows, cols);
  if (!out) return nullptr;
  double* data = reinterpret_cast<double*>(npy::array_proxy(out)->data);
  try {
    kernel(*model.model, *model.ws, data);
  } catch (...) {
    Py_DECREF(out);
    return fallback(method, self, args, nargsf, kwnames);
  }
  if (!all_finite(data, static_cast<py::ssize_t>(rows) * (cols ? cols : 1))) {
    Py_DECREF(out);
    return fallback(method, self, args, nargsf, kwnames);
  }
  return out;
}

PyObject* fast_rnea(PyObject* self, PyObject* const* args, Py_ssize_t nargsf, PyObject* kwnames) {
  PyModel* m = fast_model(self, nargsf, kwnames, 3);
  const int n = m ? m->model->n() : 0;
  const double *q = nullptr, *qd = nullptr, *qdd = nullptr;
  if (!m || !(q = plain_vector(args[0], n)) || !(qd = plain_vector(args[1], n)) ||
      !(qdd = plain_vector(args[2], n)))
    return fallback(g_rnea, self, args, nargsf, kwnames);
  return run(g_rnea, self, args, nargsf, kwnames, *m, n, 0, [&](const Model& model, Workspace& ws, double* out) {
    OutVec tau(out, n);
    rnea(model, ws, ConstVec(q, n), ConstVec(qd, n), ConstVec(qdd, n), tau);
  });
}

PyObject* fast_mass_matrix(PyObject* self, PyObject* const* args, Py_ssize_t nargsf,
                           PyObject* kwnames) {
  PyModel* m = fast_model(self, nargsf, kwnames, 1);
  const int n = m ? m->model->n() : 0;
  const double* q = nullptr;
  if (!m || !(q = plain_vector(args[0], n))) return fallback(g_mass_matrix, self, args, nargsf, kwnames);
  return run(g_mass_matrix, self, args, nargsf, kwnames, *m, n, n, [&](const Model& model, Workspace& ws, double* out) {
    OutMat M = row_major(out, n, n);
    crba(model, ws, ConstVec(q, n), M);
  });
}

PyObject* fast_gravity(PyObject* self, PyObject* const* args, Py_ssize_t nargsf, PyObject* kwnames) {
  PyModel* m = fast_model(self, nargsf, kwnames, 1);
  const int n = m ? m->model->n() : 0;
  const double* q = nullptr;
  if (!m || !(q = plain_vector(args[0], n))) return fallback(g_gravity, self, args, nargsf, kwnames);
  return run(g_gravity, self, args, nargsf, kwnames, *m, n, 0, [&](const Model& model, Workspace& ws, double* out) {
    OutVec g(out, n);
    gravity(model, ws, ConstVec(q, n), g);
  });
}

PyMethodDef g_methods[] = {
    {"rnea", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(fast_rnea)),
     METH_FASTCALL | METH_KEYWORDS, nullptr},
    {"mass_matrix", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(fast_mass_matrix)),
     METH_FASTCALL | METH_KEYWORDS, nullptr},
    {"gravity", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(fast_gravity)),
     METH_FASTCALL | METH_KEYWORDS, nullptr},
};

}  // namespace

void bind_fast_calls(py::module_& m) {
  py::object cls = m.attr("Model");
  PyObject** originals[] = {&g_rnea, &g_mass_matrix, &g_gravity};
  for (std::size_t k = 0; k < 3; ++k) {
    PyMethodDef& def = g_methods[k];
    py::object original = cls.attr(def.ml_name);  // the pybind11 method (a plain function)
    static std::string docs[3];  // the pybind11 signature and docstring, for help()
    docs[k] = py::str(original.attr("__doc__"));
    def.ml_doc = docs[k].c_str();
    *originals[k] = original.release().ptr();  // kept for the module's lifetime
    PyObject* descriptor = PyDescr_NewMethod(reinterpret_cast<PyTypeObject*>(cls.ptr()), &def);
    if (!descriptor) throw py::error_already_set();
    py::object wrapped = py::reinterpret_steal<py::object>(descriptor);
    cls.attr((std::string("_") + def.ml_name + "_full").c_str()) = py::reinterpret_borrow<py::object>(*originals[k]);
    cls.attr(def.ml_name) = wrapped;
  }
}

}  // namespace dynid::binding
