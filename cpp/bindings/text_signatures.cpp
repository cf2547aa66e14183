// pybind11 puts a typed signature on the first docstring line ("rnea(self: dynid._core.Model,
// q: object, ...) -> numpy.ndarray") but no __text_signature__ (pybind11 issue 945), so
// inspect.signature fails on its functions. CPython derives __text_signature__ from a docstring
// that starts with "name(params)\n--\n\n" and strips that part from __doc__; this file prepends
// such a line (names and literal defaults, no annotations, which the format does not allow), so
// __doc__ (which pybind11-stubgen reads) is unchanged.
#include "text_signatures.hpp"

#include <cstdlib>
#include <cstring>
#include <regex>
#include <string>
#include <vector>

namespace py = pybind11;

namespace dynid::binding {
namespace {

// Split at the commas outside brackets and quotes.
std::vector<std::string> split_parameters(const std::string& text) {
  std::vector<std::string> parts;
  int depth = 0;
  char quote = 0;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '(' || c == '[' || c == '{') {
      ++depth;
    } else if (c == ')' || c == ']' || c == '}') {
      --depth;
    } else if (c == ',' && depth == 0) {
      parts.push_back(text.substr(start, i - start));
      start = i + 1;
    }
  }
  if (start < text.size()) parts.push_back(text.substr(start));
  for (std::string& p : parts) {
    const auto first = p.find_first_not_of(' ');
    p = first == std::string::npos ? std::string() : p.substr(first);
  }
  return parts;
}

// "name: type = default" -> "name=default"; "*" and "/" pass through. Empty when the default is
// not a literal that inspect can evaluate (then the function keeps no text signature).
std::string plain_parameter(const std::string& parameter) {
  static const std::regex form(R"(^(\*{0,2}\w+)(?:: [^=]+?)?(?: = (.+))?$)");
  static const std::regex literal(
      R"(^(None|True|False|-?[0-9.e+-]+|'[^'\\]*'|\((-?[0-9.e+-]+, )*-?[0-9.e+-]+,?\))$)");
  if (parameter == "*" || parameter == "/") return parameter;
  std::smatch match;
  if (!std::regex_match(parameter, match, form)) return {};
  std::string out = match[1];
  if (match[2].matched) {
    const std::string value = match[2];
    if (!std::regex_match(value, literal)) return {};
    out += "=" + value;
  }
  return out;
}

void add_text_signature(PyObject* function) {
  if (!PyCFunction_Check(function)) return;
  PyMethodDef* def = reinterpret_cast<PyCFunctionObject*>(function)->m_ml;
  if (def == nullptr || def->ml_doc == nullptr || def->ml_name == nullptr) return;
  const std::string doc = def->ml_doc;
  const std::string name = def->ml_name;
  // Overloaded functions start "name(*args, **kwargs)\nOverloaded function."; skip them.
  if (doc.rfind(name + "(", 0) != 0 || doc.find("\nOverloaded function.") != std::string::npos ||
      doc.find("\n--\n\n") != std::string::npos)
    return;
  const std::size_t open = name.size();
  const std::size_t arrow = doc.find(") -> ", open);
  const std::size_t line_end = doc.find('\n');
  if (arrow == std::string::npos || (line_end != std::string::npos && arrow > line_end)) return;
  std::string signature = name + "(";
  bool first = true;
  for (const std::string& parameter : split_parameters(doc.substr(open + 1, arrow - open - 1))) {
    const std::string plain = plain_parameter(parameter);
    if (plain.empty()) return;
    signature += (first ? "" : ", ") + plain;
    first = false;
  }
  const std::string text = signature + ")\n--\n\n" + doc;
  char* copy = static_cast<char*>(std::malloc(text.size() + 1));
  if (copy == nullptr) return;  // keep the docstring as it is
  std::memcpy(copy, text.c_str(), text.size() + 1);
  // pybind11 allocated the old docstring with strdup and frees ml_doc with std::free when the
  // function is destroyed, so the replacement is malloc'ed as well.
  std::free(const_cast<char*>(def->ml_doc));
  def->ml_doc = copy;
}

}  // namespace

void add_text_signatures(py::module_& m) {
  const py::object module_name = m.attr("__name__");
  for (const auto item : py::reinterpret_borrow<py::dict>(m.attr("__dict__"))) {
    PyObject* value = item.second.ptr();
    add_text_signature(value);
    if (!PyType_Check(value)) continue;
    const py::object owner = py::handle(value).attr("__module__");
    if (!owner.equal(module_name)) continue;  // only the classes bound here
    // The type's own dict (its __dict__ attribute is a read-only mappingproxy).
    PyObject* members = reinterpret_cast<PyTypeObject*>(value)->tp_dict;
    if (members == nullptr || !PyDict_Check(members)) continue;
    for (const auto member : py::reinterpret_borrow<py::dict>(members)) {
      PyObject* method = member.second.ptr();
      if (PyInstanceMethod_Check(method)) add_text_signature(PyInstanceMethod_GET_FUNCTION(method));
    }
  }
}

}  // namespace dynid::binding
