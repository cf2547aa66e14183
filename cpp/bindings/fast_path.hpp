// CPython pieces of the fast path for single-sample calls (calls.cpp): Model's dynamics methods
// are vectorcall methods (METH_FASTCALL) that handle positional float64 vectors of length n
// themselves, with the result allocated by NumPy's C API directly, and pass every other call
// (keywords, out=, batches, lists, other dtypes, wrong shapes, non-finite values) to the pybind11
// method unchanged, so behaviour and error messages are the pybind11 method's; the fast path only
// skips work for the inputs that need none.
#pragma once

#include <Python.h>

#include "calls.hpp"
#include "model.hpp"

namespace dynid::binding {

// `obj` as the data of a float64, aligned, C-contiguous, 1-D array of n finite values, or
// nullptr.
const double* plain_vector(PyObject* obj, int n);

// A new uninitialised float64 array of `shape`; nullptr with a Python error set on failure.
PyObject* new_array(const Shape& shape);

// The model behind `self` when the call fits the fast path (positional, `count` arguments), or
// nullptr.
PyModel* fast_model(PyObject* self, Py_ssize_t nargsf, PyObject* kwnames, Py_ssize_t count);

// Calls `method` (the pybind11 method) with the same arguments.
PyObject* fallback(PyObject* method, PyObject* self, PyObject* const* args, Py_ssize_t nargsf,
                   PyObject* kwnames);

// Makes `function` the method `name` of `cls` with the docstring `doc` (its first part the text
// signature "name($self, ...)\n--\n\n"); the pybind11 method it replaces stays reachable as
// cls._<name>_full and is returned (a reference kept for the module's lifetime).
PyObject* install_fast_method(py::handle cls, PyMethodDef& def);

}  // namespace dynid::binding
