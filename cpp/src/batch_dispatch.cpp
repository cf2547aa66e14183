// Selection of the batch kernels at load time (detail/batch.hpp). __builtin_cpu_supports also
// checks that the operating system saves the wide registers (XGETBV), so a listed path runs.
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "dynid/detail/batch.hpp"

namespace dynid::detail {
namespace {

struct Path {
  const char* name;
  const LaneKernels* kernels;  // nullptr: scalar
};

bool cpu_supports(const std::string& name) {
  if (name == "scalar" || name == "sse2") return true;  // sse2: generic 2-lane vectors
#if defined(DYNID_X86_LANES)
  __builtin_cpu_init();
  if (name == "avx2") return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (name == "avx512") return __builtin_cpu_supports("avx512f");
#endif
  return false;
}

const LaneKernels* kernels_of(const std::string& name) {
  if (name == "sse2") return &lanes_sse2;
#if defined(DYNID_X86_LANES)
  if (name == "avx2") return &lanes_avx2;
  if (name == "avx512") return &lanes_avx512;
#endif
  return nullptr;
}

const char* const kPaths[] = {"scalar", "sse2", "avx2", "avx512"};  // narrowest first

const LaneKernels* initial_choice() {
  if (const char* forced = std::getenv("DYNID_BATCH_ISA")) {
    const std::string name(forced);
    for (const char* path : kPaths)
      if (name == path && cpu_supports(name)) return kernels_of(name);
  }
  const LaneKernels* best = nullptr;
  for (const char* path : kPaths)
    if (cpu_supports(path)) best = kernels_of(path);
  return best;
}

std::atomic<const LaneKernels*>& selected() {
  static std::atomic<const LaneKernels*> choice{initial_choice()};
  return choice;
}

// The widest lanes the CPU runs, whatever path the batches are forced to.
const LaneKernels* widest_kernels() {
  static const LaneKernels* const widest = [] {
    const LaneKernels* best = nullptr;
    for (const char* path : kPaths)
      if (cpu_supports(path)) best = kernels_of(path);
    return best;
  }();
  return widest;
}

}  // namespace

void sincos_many(const double* x, double* s, double* c, int count) {
  if (const LaneKernels* lanes = widest_kernels()) return lanes->sincos(x, s, c, count);
  for (int k = 0; k < count; ++k) s[k] = std::sin(x[k]), c[k] = std::cos(x[k]);
}

bool all_finite_many(const double* x, long count) {
  if (const LaneKernels* lanes = widest_kernels()) return lanes->all_finite(x, count);
  for (long k = 0; k < count; ++k)
    if (!std::isfinite(x[k])) return false;
  return true;
}

const LaneKernels* batch_kernels() { return selected().load(std::memory_order_relaxed); }

std::string batch_isa() {
  const LaneKernels* k = batch_kernels();
  return k ? k->name : "scalar";
}

std::vector<std::string> supported_batch_isas() {
  std::vector<std::string> names;
  for (const char* path : kPaths)
    if (cpu_supports(path)) names.emplace_back(path);
  return names;
}

void set_batch_isa(const std::string& isa) {
  bool known = false;
  for (const char* path : kPaths) known = known || isa == path;
  if (!known)
    throw std::invalid_argument("isa: expected 'scalar', 'sse2', 'avx2' or 'avx512', got '" + isa +
                                "'");
  if (!cpu_supports(isa))
    throw std::invalid_argument("isa: '" + isa + "' is not supported by this CPU or build");
  selected().store(kernels_of(isa));
}

BatchModel batch_model(const Model& model, std::vector<BatchJoint>& joints) {
  const int n = model.n();
  joints.resize(n);
  for (int i = 0; i < n; ++i) {
    const JointGeometry& g = model.joint(i);
    const RigidBodyParameters& b = model.body(i);
    joints[i] = BatchJoint{g.cos_alpha,
                           g.sin_alpha,
                           g.a,
                           g.theta,
                           g.d,
                           g.revolute ? 1 : 0,
                           b.m,
                           {b.h.x(), b.h.y(), b.h.z()},
                           {b.I(0, 0), b.I(0, 1), b.I(0, 2), b.I(1, 1), b.I(1, 2), b.I(2, 2)},
                           model.rotor_inertia()[i],
                           model.viscous_friction()[i],
                           model.coulomb_friction()[i]};
    const LinkOffset& o = model.link_offset(i);
    joints[i].offset_identity = o.identity ? 1 : 0;
    joints[i].offset_cos_alpha = o.cos_alpha;
    joints[i].offset_sin_alpha = o.sin_alpha;
    joints[i].offset_a = o.a;
  }
  const Vector3 g = -model.gravity_base();
  return BatchModel{n, joints.data(), {g.x(), g.y(), g.z()}};
}

}  // namespace dynid::detail
