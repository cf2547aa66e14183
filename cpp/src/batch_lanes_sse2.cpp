// The batch kernels with 2 lanes, compiled with the baseline flags (SSE2 on x86-64; GCC/Clang
// vector extensions elsewhere), so any build of cpp/src/*.cpp has them; selected at load time
// by batch_dispatch.cpp (the widest path the CPU supports).
#define DYNID_LANES 2
#define DYNID_LANES_NS lanes_sse2_impl
#include "batch/lane_kernels.hpp"
#include "batch/lane_regressor.hpp"

namespace dynid::detail {
const LaneKernels lanes_sse2 = {"sse2",
                                2,
                                &lanes_sse2_impl::rnea,
                                &lanes_sse2_impl::gravity,
                                &lanes_sse2_impl::mass_matrix,
                                &lanes_sse2_impl::regressor,
                                &lanes_sse2_impl::sincos_many,
                                &lanes_sse2_impl::all_finite};
}  // namespace dynid::detail
