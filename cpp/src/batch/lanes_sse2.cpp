// The batch kernels with 2 lanes, compiled with this file's own instruction-set flags
// (CMakeLists.txt); selected at load time by batch_dispatch.cpp when the CPU supports them.
#define DYNID_LANES 2
#define DYNID_LANES_NS lanes_sse2_impl
#include "lane_kernels.hpp"
#include "lane_regressor.hpp"

namespace dynid::detail {
const LaneKernels lanes_sse2 = {"sse2", 2, &lanes_sse2_impl::rnea, &lanes_sse2_impl::gravity,
                                &lanes_sse2_impl::mass_matrix,
                                &lanes_sse2_impl::regressor,
                                &lanes_sse2_impl::sincos_many};
}  // namespace dynid::detail
