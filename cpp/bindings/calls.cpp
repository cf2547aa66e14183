// Model's dynamics calls generated from their table (call_table.hpp). For entry K:
// - the pybind11 method name(inputs..., options..., [out=None]): one sample or a batch (the
//   batch through dynid::batch with the GIL released), kept as Model._<name>_full;
// - the fast path (fast_path.hpp), which becomes Model.<name>;
// - the text signature "name($self, inputs..., options=defaults..., [out=None])" and the
//   docstring, pybind11's typed signature line followed by the entry's text.
#include "calls.hpp"

#include <stdexcept>
#include <string>

#include "call_table.hpp"
#include "fast_path.hpp"
#include "without_gil.hpp"

namespace dynid::binding {
namespace {

template <std::size_t K>
using Entry = std::decay_t<decltype(std::get<K>(kCalls))>;
template <std::size_t K>
constexpr std::size_t kInputs = Entry<K>::inputs_count;
template <std::size_t K>
constexpr std::size_t kOptions = Entry<K>::options::args.size();

template <class Returns>
constexpr bool kTakesOut = std::is_same_v<Returns, ReturnsArrayOrOut>;
template <class Returns>
constexpr bool kFloat = std::is_same_v<Returns, ReturnsFloat>;
template <class Returns>
struct IsParts : std::false_type {};
template <int P>
struct IsParts<ReturnsParts<P>> : std::true_type {};

// What the pybind11 method returns (its signature shows it): an array, a float or an array
// (object), or a tuple of arrays.
template <class Returns, class = std::make_index_sequence < IsParts<Returns>::value
                                     ? 3
                                     : 0 >> struct PythonResult {
  using type = std::conditional_t<kFloat<Returns>, py::object, py::array>;
};
template <int P, std::size_t... I>
struct PythonResult<ReturnsParts<P>, std::index_sequence<I...>> {
  template <std::size_t>
  using Array = py::array;
  template <class Seq>
  struct Tuple;
  template <std::size_t... J>
  struct Tuple<std::index_sequence<J...>> {
    using type = std::tuple<Array<J>...>;
  };
  using type = typename Tuple<std::make_index_sequence<P>>::type;
};

// A result of shape (P, ...) (one sample) or (T, P, ...) as its P parts along that axis.
template <int P, std::size_t... J>
std::tuple<decltype(J, py::array())...> split(const py::array& all, bool single,
                                              std::index_sequence<J...>) {
  auto part = [&](int k) {
    return py::array(single ? all[py::int_(k)] : all[py::make_tuple(py::slice(), k)]);
  };
  return {part(static_cast<int>(J))...};
}

// The pybind11 method's work for entry K.
template <std::size_t K, std::size_t... I>
auto evaluate(PyModel& self, const std::array<py::handle, kInputs<K>>& input,
              const py::handle* option, py::handle out_arg, std::index_sequence<I...>) {
  const auto& c = std::get<K>(kCalls);
  using Options = typename Entry<K>::options;
  using Returns = typename Entry<K>::returns;
  const int n = self.model->n();
  const Options options = Options::parse(option, n);
  const Samples s = parse_samples({{input[I], c.inputs[I]}...}, n);
  const Shape shape = c.shape(n, options);
  const py::ssize_t size = shape.size();
  std::vector<py::ssize_t> dims(shape.dims, shape.dims + shape.ndim);
  if (!s.single) dims.insert(dims.begin(), s.count);
  py::array_t<double> out = output_array(out_arg, dims);
  double* data = out.mutable_data();
  auto run = [&] {
    if (s.single) {
      const double* in[] = {s.data[I]...};
      const Sample<Options> sample{*self.model, *self.ws, in, options};
      if constexpr (kFloat<Returns>)
        *data = c.single(sample);
      else
        c.single(sample, data);
      if (!all_finite(data, size)) require_finite_result(data, size, s.names.c_str());
      return;
    }
    // The model snapshot stays alive while the batch runs without the GIL.
    const std::shared_ptr<const Model> model = self.model;
    BatchWorkspace ws(*model, batch_workspace_threads(s.count));
    ws.set_interrupt(python_interrupt());
    const std::array<Eigen::Map<const RowMajorMatrixX>, kInputs<K>> samples{
        Eigen::Map<const RowMajorMatrixX>(s.data[I], s.count, n)...};
    const Batch<Options> b{*model, ws, samples.data(), options};
    Eigen::Map<RowMajorMatrixX> results(data, s.count, size);
    const batch::Report report = without_gil([&] { return c.batch(b, results); });
    last_batch_threads = report.threads;
    if (report.first_nonfinite >= 0)
      require_finite_result(data + report.first_nonfinite * size, size, s.names.c_str());
  };
  if (c.params_error) {
    try {
      run();
    } catch (const std::domain_error& e) {  // M(q) not positive definite
      throw py::value_error(std::string("params: ") + e.what());
    }
  } else {
    run();
  }
  using Result = typename PythonResult<Returns>::type;
  if constexpr (IsParts<Returns>::value) {
    return split<Returns::parts>(out, s.single, std::make_index_sequence<Returns::parts>());
  } else if constexpr (kFloat<Returns>) {
    return s.single ? Result(py::float_(*data)) : Result(out);
  } else {
    return Result(out);
  }
}

template <std::size_t>
using Handle = py::handle;

py::arg_v option_arg(const OptionArg& option) {
  if (std::string(option.literal) == "None") return py::arg(option.name) = py::none();
  return py::arg(option.name) = false;  // "False": the flags
}

// The pybind11 method of entry K: (self, inputs..., options..., [out]).
template <std::size_t K, std::size_t... I, std::size_t... J>
void define_method(py::class_<PyModel>& cls, std::index_sequence<I...>, std::index_sequence<J...>) {
  const auto& c = std::get<K>(kCalls);
  using Options = typename Entry<K>::options;
  using Returns = typename Entry<K>::returns;
  using Result = typename PythonResult<Returns>::type;
  if constexpr (kTakesOut<Returns>) {
    cls.def(
        c.name,
        [](PyModel& self, Handle<I>... input, Handle<J>... option, py::handle out) -> Result {
          const py::handle options[] = {option..., py::handle()};
          return evaluate<K>(self, {input...}, options, out, std::index_sequence<I...>());
        },
        py::arg(c.inputs[I])..., option_arg(Options::args[J])..., py::arg("out") = py::none(),
        c.doc);
  } else {
    cls.def(
        c.name,
        [](PyModel& self, Handle<I>... input, Handle<J>... option) -> Result {
          const py::handle options[] = {option..., py::handle()};
          return evaluate<K>(self, {input...}, options, py::none(), std::index_sequence<I...>());
        },
        py::arg(c.inputs[I])..., option_arg(Options::args[J])..., c.doc);
  }
}

// The pybind11 methods, called for everything the fast paths do not take.
template <std::size_t K>
PyObject* g_full = nullptr;

// The fast path of entry K: positional vectors, the options' defaults.
template <std::size_t K>
PyObject* fast_call(PyObject* self, PyObject* const* args, Py_ssize_t nargsf, PyObject* kwnames) {
  const auto& c = std::get<K>(kCalls);
  using Options = typename Entry<K>::options;
  using Returns = typename Entry<K>::returns;
  PyModel* m = fast_model(self, nargsf, kwnames, kInputs<K>);
  if (!m) return fallback(g_full<K>, self, args, nargsf, kwnames);
  const int n = m->model->n();
  const double* in[kInputs<K>];
  for (std::size_t k = 0; k < kInputs<K>; ++k)
    if (!(in[k] = plain_vector(args[k], n)))
      return fallback(g_full<K>, self, args, nargsf, kwnames);
  const Options options{};
  const Shape shape = c.shape(n, options);
  double scalar = 0.0;
  PyObject* out = nullptr;
  if constexpr (!kFloat<Returns>) {
    if (!(out = new_array(shape))) return nullptr;
  }
  double* data = out ? reinterpret_cast<double*>(py::detail::array_proxy(out)->data) : &scalar;
  bool ok = true;
  try {
    const Sample<Options> sample{*m->model, *m->ws, in, options};
    if constexpr (kFloat<Returns>)
      scalar = c.single(sample);
    else
      c.single(sample, data);
  } catch (...) {  // the full method turns it into the named ValueError
    ok = false;
  }
  if (!ok || !all_finite(data, shape.size())) {
    Py_XDECREF(out);
    return fallback(g_full<K>, self, args, nargsf, kwnames);
  }
  if constexpr (kFloat<Returns>) {
    return PyFloat_FromDouble(scalar);
  } else if constexpr (IsParts<Returns>::value) {
    PyObject* parts = PyTuple_New(Returns::parts);
    for (int k = 0; parts && k < Returns::parts; ++k) {
      PyObject* part = PySequence_GetItem(out, k);  // a view, as all[k] of the full method
      if (!part) {
        Py_CLEAR(parts);
        break;
      }
      PyTuple_SET_ITEM(parts, k, part);
    }
    Py_DECREF(out);
    return parts;
  } else {
    return out;
  }
}

// "name($self, q, qd, rotor=False, out=None)": the text signature of entry K.
template <std::size_t K>
std::string text_signature() {
  const auto& c = std::get<K>(kCalls);
  std::string text = std::string(c.name) + "($self";
  for (const char* input : c.inputs) text += std::string(", ") + input;
  for (const OptionArg& option : Entry<K>::options::args)
    text += std::string(", ") + option.name + "=" + option.literal;
  if (kTakesOut<typename Entry<K>::returns>) text += ", out=None";
  return text + ")";
}

// The Python types of the table's arguments and results, for the typed signature line.
constexpr const char* kArrayLike = "numpy.typing.ArrayLike";
constexpr const char* kArray = "numpy.typing.NDArray[numpy.float64]";

// The type of an option from its default: a flag (False/True) or an optional array (None).
std::string option_type(const OptionArg& option) {
  const std::string literal = option.literal;
  if (literal == "False" || literal == "True") return "bool";
  return std::string(kArrayLike) + " | None";
}

template <class Returns>
std::string result_type() {
  if constexpr (kFloat<Returns>) {
    return std::string("float | ") + kArray;  // a float per sample, an array for T samples
  } else if constexpr (IsParts<Returns>::value) {
    std::string parts = "tuple[";
    for (int k = 0; k < Returns::parts; ++k) parts += (k ? ", " : "") + std::string(kArray);
    return parts + "]";
  } else {
    return kArray;
  }
}

// "name(self: dynid._core.Model, q: numpy.typing.ArrayLike, ...) -> numpy.typing.NDArray[...]":
// the typed signature line of entry K, the one pybind11-stubgen reads (tools/generate_stubs.py),
// written from the table so that the stub follows it.
template <std::size_t K>
std::string typed_signature() {
  const auto& c = std::get<K>(kCalls);
  using Returns = typename Entry<K>::returns;
  std::string text = std::string(c.name) + "(self: dynid._core.Model";
  for (const char* input : c.inputs) text += std::string(", ") + input + ": " + kArrayLike;
  for (const OptionArg& option : Entry<K>::options::args)
    text += std::string(", ") + option.name + ": " + option_type(option) + " = " + option.literal;
  if (kTakesOut<Returns>) text += std::string(", out: ") + kArray + " | None = None";
  return text + ") -> " + result_type<Returns>();
}

template <std::size_t K>
void bind_call(py::class_<PyModel>& cls) {
  define_method<K>(cls, std::make_index_sequence<kInputs<K>>(),
                   std::make_index_sequence<kOptions<K>>());
  // The docstring: the text signature, the typed signature line, then the entry's text; all
  // three from the table (pybind11's own line would type the arguments as `object`).
  static const std::string doc =
      text_signature<K>() + "\n--\n\n" + typed_signature<K>() + "\n\n" + std::get<K>(kCalls).doc;
  static PyMethodDef def{std::get<K>(kCalls).name,
                         reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(fast_call<K>)),
                         METH_FASTCALL | METH_KEYWORDS, doc.c_str()};
  g_full<K> = install_fast_method(cls, def);
}

template <std::size_t... K>
void bind_all(py::class_<PyModel>& cls, std::index_sequence<K...>) {
  (bind_call<K>(cls), ...);
}

}  // namespace

void bind_calls(py::class_<PyModel>& cls) {
  bind_all(cls, std::make_index_sequence<std::tuple_size_v<decltype(kCalls)>>());
}

}  // namespace dynid::binding
