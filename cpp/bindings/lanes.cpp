// Python access to the batch path selection (tests run every path the CPU supports).
#include "lanes.hpp"

#include <stdexcept>
#include <string>

#include "arrays.hpp"
#include "dynid/detail/batch.hpp"
#include "result_pool.hpp"

namespace dynid::binding {

void bind_lanes(py::module_& m) {
  m.def(
      "_batch_isa", [] { return detail::batch_isa(); },
      "The path batch calls of rnea, gravity and mass_matrix run on: 'scalar' (the per-sample "
      "kernels), 'sse2', 'avx2' or 'avx512' (SIMD lanes across samples).");
  m.def(
      "_set_batch_isa",
      [](const std::string& isa) {
        try {
          detail::set_batch_isa(isa);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("isa"),
      "Force a batch path (for tests); also DYNID_BATCH_ISA at import. ValueError when the CPU "
      "cannot run it.");
  m.def(
      "_sincos",
      [](py::handle x_arg) {
        Array x = as_real_array(x_arg, "x");
        require_finite(x, "x");
        py::array_t<double> s(x.size()), c(x.size());
        detail::sincos_many(x.data(), s.mutable_data(), c.mutable_data(),
                            static_cast<int>(x.size()));
        return py::make_tuple(s, c);
      },
      py::arg("x"),
      "sin and cos of the flattened x by the vectorised sincos the kernels use (tests).");
  m.def(
      "_result_pool",
      [] {
        const auto [blocks, bytes] = pooled_blocks();
        return py::make_tuple(blocks, bytes);
      },
      "(blocks, bytes) of large batch results' memory waiting for reuse (result_pool.hpp; "
      "tests).");
  m.def(
      "_supported_batch_isas",
      [] {
        py::list names;
        for (const std::string& name : detail::supported_batch_isas()) names.append(name);
        return names;
      },
      "The batch paths this CPU and build can run.");
}

}  // namespace dynid::binding
