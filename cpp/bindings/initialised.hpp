// A type caster that refuses Python objects whose C++ value was never constructed.
//
// `Robot.__new__(Robot)` (or copy/pickle machinery that calls __new__ without __init__) makes a
// Python object whose C++ storage pybind11 allocates lazily and leaves uninitialised: a method
// called on it would read garbage (a segfault for Model, uninitialised numbers for the RLS).
// Every method receives `self` through this caster, which checks that the holder was
// constructed (i.e. that __init__ ran) and raises TypeError otherwise.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

namespace dynid::binding {

template <class T>
struct initialised_caster : pybind11::detail::type_caster_base<T> {
  bool load(pybind11::handle src, bool convert) {
    if (!pybind11::detail::type_caster_base<T>::load(src, convert)) return false;
    const pybind11::detail::type_info* info = this->typeinfo;  // looked up once per caster
    if (info && PyObject_TypeCheck(src.ptr(), info->type)) {
      auto* instance = reinterpret_cast<pybind11::detail::instance*>(src.ptr());
      if (!instance->get_value_and_holder(info, false).holder_constructed()) {
        std::string name = Py_TYPE(src.ptr())->tp_name;  // e.g. dynid._core.Model
        name = name.substr(name.rfind('.') + 1);
        throw pybind11::type_error(name +
                                   " object is not initialised (made by __new__ without "
                                   "__init__): create it by calling " +
                                   name + "(...)");
      }
    }
    return true;
  }
};

}  // namespace dynid::binding
