// A fast path for single-sample calls (rnea(q, qd, qdd), mass_matrix(q), gravity(q) and the
// other per-sample methods of model.cpp) with positional float64 vectors of length n, entered
// through CPython's vectorcall protocol (METH_FASTCALL) instead of pybind11's generic dispatch,
// with the result allocated by NumPy's C API directly. Everything else (keywords, out=, batches,
// lists, other dtypes, wrong shapes, non-finite values) goes to the pybind11 method unchanged, so
// behaviour and error messages are those of model.cpp; the fast path only skips work for the inputs
// that need none.
#include <Python.h>

#include <string>

#include "fast_calls.hpp"

namespace dynid::binding {
namespace {

namespace npy = py::detail;

// The pybind11 methods, called for everything the fast path does not take (index: g_methods).
constexpr int kMethods = 14;
PyObject* g_full[kMethods] = {};

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
  return api.PyArray_NewFromDescr_(api.PyArray_Type_,
                                   api.PyArray_DescrFromType_(npy::npy_api::NPY_DOUBLE_),
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
  try {  // an object made by __new__ without __init__: the full method raises the TypeError
    if (!caster.load(self, false)) return nullptr;
  } catch (...) {
    return nullptr;
  }
  return &py::detail::cast_op<PyModel&>(caster);
}

// Output of a method for n joints: rows x cols (cols 0: a vector; rows 0: a Python float).
struct Dims {
  int rows, cols;
};

// The fast path of method K: `Args` positional vectors, a result of dims(n), computed by
// kernel(model, workspace, inputs, output); anything else goes to the full method.
template <int K, int Args, class Shape, class Kernel>
PyObject* fast_call(PyObject* self, PyObject* const* args, Py_ssize_t nargsf, PyObject* kwnames,
                    Shape dims, Kernel kernel) {
  PyObject* full = g_full[K];
  PyModel* m = fast_model(self, nargsf, kwnames, Args);
  if (!m) return fallback(full, self, args, nargsf, kwnames);
  const int n = m->model->n();
  const double* in[3] = {nullptr, nullptr, nullptr};
  for (int k = 0; k < Args; ++k)
    if (!(in[k] = plain_vector(args[k], n))) return fallback(full, self, args, nargsf, kwnames);
  const Dims d = dims(n);
  double scalar = 0.0;
  PyObject* out = nullptr;
  if (d.rows > 0 && !(out = new_array(d.rows, d.cols))) return nullptr;
  double* data = out ? reinterpret_cast<double*>(npy::array_proxy(out)->data) : &scalar;
  const py::ssize_t size =
      d.rows > 0 ? static_cast<py::ssize_t>(d.rows) * (d.cols ? d.cols : 1) : 1;
  bool ok = true;
  try {
    kernel(*m->model, *m->ws, in, data, n);
  } catch (...) {  // the full method turns it into the named ValueError
    ok = false;
  }
  if (!ok || !all_finite(data, size)) {
    Py_XDECREF(out);
    return fallback(full, self, args, nargsf, kwnames);
  }
  return out ? out : PyFloat_FromDouble(scalar);
}

using In = const double* const*;
Dims vector_dims(int n) { return {n, 0}; }
Dims square_dims(int n) { return {n, n}; }

PyObject* fast_rnea(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<0, 3>(
      self, a, f, kw, vector_dims, [](const Model& m, Workspace& ws, In in, double* out, int n) {
        OutVec tau(out, n);
        rnea(m, ws, ConstVec(in[0], n), ConstVec(in[1], n), ConstVec(in[2], n), tau);
      });
}
PyObject* fast_mass_matrix(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<1, 1>(self, a, f, kw, square_dims,
                         [](const Model& m, Workspace& ws, In in, double* out, int n) {
                           OutMat M = row_major(out, n, n);
                           crba(m, ws, ConstVec(in[0], n), M);
                         });
}
PyObject* fast_gravity(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<2, 1>(self, a, f, kw, vector_dims,
                         [](const Model& m, Workspace& ws, In in, double* out, int n) {
                           OutVec g(out, n);
                           gravity(m, ws, ConstVec(in[0], n), g);
                         });
}
PyObject* fast_coriolis(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<3, 2>(self, a, f, kw, vector_dims,
                         [](const Model& m, Workspace& ws, In in, double* out, int n) {
                           OutVec c(out, n);
                           coriolis(m, ws, ConstVec(in[0], n), ConstVec(in[1], n), c);
                         });
}
PyObject* fast_coriolis_matrix(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<4, 2>(self, a, f, kw, square_dims,
                         [](const Model& m, Workspace& ws, In in, double* out, int n) {
                           OutMat S = row_major(out, n, n);
                           coriolis_matrix(m, ws, ConstVec(in[0], n), ConstVec(in[1], n), S);
                         });
}
PyObject* fast_friction(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<5, 1>(self, a, f, kw, vector_dims,
                         [](const Model& m, Workspace&, In in, double* out, int n) {
                           OutVec tau(out, n);
                           friction(m, ConstVec(in[0], n), tau);
                         });
}
PyObject* fast_forward_dynamics(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<6, 3>(
      self, a, f, kw, vector_dims, [](const Model& m, Workspace& ws, In in, double* out, int n) {
        OutVec qdd(out, n);
        forward_dynamics(m, ws, ConstVec(in[0], n), ConstVec(in[1], n), ConstVec(in[2], n), qdd);
      });
}
PyObject* fast_kinetic_energy(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<7, 2>(
      self, a, f, kw, [](int) { return Dims{0, 0}; },
      [](const Model& m, Workspace& ws, In in, double* out, int n) {
        *out = kinetic_energy(m, ws, ConstVec(in[0], n), ConstVec(in[1], n));
      });
}
PyObject* fast_potential_energy(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<8, 1>(
      self, a, f, kw, [](int) { return Dims{0, 0}; },
      [](const Model& m, Workspace& ws, In in, double* out, int n) {
        *out = potential_energy(m, ws, ConstVec(in[0], n));
      });
}
PyObject* fast_fkine(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<9, 1>(
      self, a, f, kw, [](int) { return Dims{4, 4}; },
      [](const Model& m, Workspace& ws, In in, double* out, int n) {
        OutMat T = row_major(out, 4, 4);
        fkine(m, ws, ConstVec(in[0], n), T);
      });
}
PyObject* fast_jacobian(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<10, 1>(
      self, a, f, kw, [](int n) { return Dims{6, n}; },
      [](const Model& m, Workspace& ws, In in, double* out, int n) {
        OutMat J = row_major(out, 6, n);
        jacobian(m, ws, ConstVec(in[0], n), J);
      });
}
PyObject* fast_regressor(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  // Positional (q, qd, qdd) only: the rigid-body columns (rotor=False, friction=False).
  return fast_call<11, 3>(
      self, a, f, kw, [](int n) { return Dims{n, 10 * n}; },
      [](const Model& m, Workspace& ws, In in, double* out, int n) {
        RowMajorMap Y(out, n, 10 * n);
        regressor(m, ws, ConstVec(in[0], n), ConstVec(in[1], n), ConstVec(in[2], n), false, false,
                  Y);
      });
}
PyObject* fast_gravity_regressor(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<12, 1>(
      self, a, f, kw, [](int n) { return Dims{n, 10 * n}; },
      [](const Model& m, Workspace& ws, In in, double* out, int n) {
        RowMajorMap Y(out, n, 10 * n);
        gravity_regressor(m, ws, ConstVec(in[0], n), Y);
      });
}
PyObject* fast_inertia_regressor(PyObject* self, PyObject* const* a, Py_ssize_t f, PyObject* kw) {
  return fast_call<13, 1>(
      self, a, f, kw, [](int n) { return Dims{n * (n + 1) / 2, 10 * n}; },
      [](const Model& m, Workspace& ws, In in, double* out, int n) {
        RowMajorMap Y(out, n * (n + 1) / 2, 10 * n);
        inertia_regressor(m, ws, ConstVec(in[0], n), false, Y);
      });
}

#define DYNID_FAST(name)                                                            \
  {#name, reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(fast_##name)), \
   METH_FASTCALL | METH_KEYWORDS, nullptr}

PyMethodDef g_methods[kMethods] = {
    DYNID_FAST(rnea),
    DYNID_FAST(mass_matrix),
    DYNID_FAST(gravity),
    DYNID_FAST(coriolis),
    DYNID_FAST(coriolis_matrix),
    DYNID_FAST(friction),
    DYNID_FAST(forward_dynamics),
    DYNID_FAST(kinetic_energy),
    DYNID_FAST(potential_energy),
    DYNID_FAST(fkine),
    DYNID_FAST(jacobian),
    DYNID_FAST(regressor),
    DYNID_FAST(gravity_regressor),
    DYNID_FAST(inertia_regressor),
};
#undef DYNID_FAST

}  // namespace

void bind_fast_calls(py::module_& m) {
  py::object cls = m.attr("Model");
  static std::string docs[kMethods];  // the pybind11 signatures and docstrings, for help()
  for (int k = 0; k < kMethods; ++k) {
    PyMethodDef& def = g_methods[k];
    py::object original = cls.attr(def.ml_name);  // the pybind11 method (a plain function)
    // The C function's own docstring: with the "name(params)\n--\n\n" line add_text_signatures
    // put there, so inspect.signature works on the fast method too.
    PyObject* function = PyInstanceMethod_Check(original.ptr())
                             ? PyInstanceMethod_GET_FUNCTION(original.ptr())
                             : original.ptr();
    const char* doc = PyCFunction_Check(function)
                          ? reinterpret_cast<PyCFunctionObject*>(function)->m_ml->ml_doc
                          : nullptr;
    docs[k] = doc ? std::string(doc) : std::string(py::str(original.attr("__doc__")));
    // A builtin method's text signature marks the bound argument "$self" (inspect drops it).
    const std::string plain = std::string(def.ml_name) + "(self";
    if (docs[k].rfind(plain, 0) == 0 && docs[k].find("\n--\n\n") != std::string::npos)
      docs[k].insert(plain.size() - 4, "$");
    def.ml_doc = docs[k].c_str();
    g_full[k] = original.release().ptr();  // kept for the module's lifetime
    PyObject* descriptor = PyDescr_NewMethod(reinterpret_cast<PyTypeObject*>(cls.ptr()), &def);
    if (!descriptor) throw py::error_already_set();
    py::object wrapped = py::reinterpret_steal<py::object>(descriptor);
    cls.attr((std::string("_") + def.ml_name + "_full").c_str()) =
        py::reinterpret_borrow<py::object>(g_full[k]);
    cls.attr(def.ml_name) = wrapped;
  }
}

}  // namespace dynid::binding
