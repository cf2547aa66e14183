// Runtime dispatch of the batch (SIMD lane) kernels: the widest instruction set the CPU supports
// among those compiled in (AVX-512, AVX2+FMA, SSE2), chosen at load time; the environment
// variable DYNID_BATCH_ISA or set_batch_isa() can force one ("scalar": the per-sample reference
// kernels), e.g. for tests of every path.
#pragma once

#include <string>
#include <vector>

#include "dynid/detail/batch_model.hpp"
#include "dynid/model.hpp"

namespace dynid::detail {

// The lane kernels in use, or nullptr when batches run the scalar kernels sample by sample.
const LaneKernels* batch_kernels();

// "scalar", "sse2", "avx2" or "avx512".
std::string batch_isa();

// Forces a path; throws std::invalid_argument naming `isa` when it is unknown or this CPU (or
// this build) cannot run it.
void set_batch_isa(const std::string& isa);

// The paths this CPU and build can run, "scalar" first.
std::vector<std::string> supported_batch_isas();

// sin and cos of `count` angles by the widest vectorised sincos the CPU runs (whatever the batch
// path forced), or libm's when there is none; a few ulp (tests/test_batch_lanes.py).
void sincos_many(const double* x, double* s, double* c, int count);

// True when all `count` values are finite, by the widest lanes the CPU runs (a pass over large
// inputs at the memory's speed; the scalar loop when there are none).
bool all_finite_many(const double* x, long count);

// The model as plain numbers; `joints` is the storage the result points into.
BatchModel batch_model(const Model& model, std::vector<BatchJoint>& joints);

}  // namespace dynid::detail
