// The batch kernels with 8 lanes, compiled with this file's own instruction-set flags
// (CMakeLists.txt); selected at load time by batch_dispatch.cpp when the CPU supports them.
#define DYNID_LANES 8
#define DYNID_LANES_NS lanes_avx512_impl
#include "lane_kernels.hpp"
#include "lane_regressor.hpp"

namespace dynid::detail {
const LaneKernels lanes_avx512 = {"avx512",
                                  8,
                                  &lanes_avx512_impl::rnea,
                                  &lanes_avx512_impl::gravity,
                                  &lanes_avx512_impl::mass_matrix,
                                  &lanes_avx512_impl::regressor,
                                  &lanes_avx512_impl::sincos_many,
                                  &lanes_avx512_impl::all_finite};
}  // namespace dynid::detail
