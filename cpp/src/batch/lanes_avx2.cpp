// The batch kernels with 4 lanes, compiled with this file's own instruction-set flags
// (CMakeLists.txt); selected at load time by batch_dispatch.cpp when the CPU supports them.
#define DYNID_LANES 4
#define DYNID_LANES_NS lanes_avx2_impl
#include "lane_kernels.hpp"
#include "lane_regressor.hpp"

namespace dynid::detail {
const LaneKernels lanes_avx2 = {"avx2",
                                4,
                                &lanes_avx2_impl::rnea,
                                &lanes_avx2_impl::gravity,
                                &lanes_avx2_impl::mass_matrix,
                                &lanes_avx2_impl::regressor,
                                &lanes_avx2_impl::sincos_many,
                                &lanes_avx2_impl::all_finite};
}  // namespace dynid::detail
