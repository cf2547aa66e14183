// The model as plain numbers for the batch (SIMD lane) kernels of cpp/src/batch/. Those are
// compiled once per instruction set with their own flags, so they see no Eigen, no std:: template
// and no inline function shared with the rest of the library: an inline function compiled there
// could be merged by the linker with the baseline copy and run AVX-512 code on a CPU without it.
#pragma once

namespace dynid::detail {

// One joint in the modified form of joint_transform.hpp and its link's parameters about the
// origin of J_i (Model::body), plus the drive terms.
struct BatchJoint {
  double cos_alpha, sin_alpha, a, theta, d;  // q adds to theta (revolute) or d (prismatic)
  int revolute;
  double m, h[3];
  double I[6];  // xx, xy, xz, yy, yz, zz about the origin of J_i
  double Ia, Fv, Fs;
  // Link i's DH frame in J_i (Model::link_offset): identity (modified DH) or Tx(a) Rx(alpha).
  int offset_identity;
  double offset_cos_alpha, offset_sin_alpha, offset_a;
};

struct BatchModel {
  int n;
  const BatchJoint* joints;
  double base_acceleration[3];  // -gravity in frame 0: the fictitious upward acceleration
};

// Each kernel evaluates T samples stored row by row ((T, n) inputs, (T, n) or (T, n, n) outputs)
// and returns the index of the first sample whose output is not finite, or -1.
using BatchRnea = long (*)(const BatchModel&, const double* q, const double* qd, const double* qdd,
                           double* tau, long T);
using BatchGravity = long (*)(const BatchModel&, const double* q, double* g, long T);
using BatchMassMatrix = long (*)(const BatchModel&, const double* q, double* M, long T);
// The torque regressor (T, n, P) with P = 10n [+ n rotor] [+ 2n friction] columns, or only the
// C columns listed in `columns` ((T, n, C)) when it is not null.
using BatchRegressor = long (*)(const BatchModel&, const double* q, const double* qd,
                                const double* qdd, int rotor, int friction, const int* columns,
                                int C, double* Y, long T);

// sin and cos of `count` angles (the lane kernels' vectorised sincos, a few ulp).
using SinCos = void (*)(const double* x, double* s, double* c, int count);
// True when all `count` values are finite.
using AllFinite = bool (*)(const double* x, long count);

struct LaneKernels {
  const char* name;  // "sse2", "avx2", "avx512"
  int lanes;         // samples per SIMD vector
  BatchRnea rnea;
  BatchGravity gravity;
  BatchMassMatrix mass_matrix;
  BatchRegressor regressor;
  SinCos sincos;
  AllFinite all_finite;
};

// Defined in cpp/src/batch/lanes_*.cpp (the AVX ones on x86-64 only).
extern const LaneKernels lanes_sse2;
extern const LaneKernels lanes_avx2;
extern const LaneKernels lanes_avx512;

// Joints above this use the scalar kernels (the lane kernels keep per-link arrays on the stack).
constexpr int kMaxBatchJoints = 128;
// The regressor's lane kernel keeps n x P vectors on the stack: up to this many joints.
constexpr int kMaxRegressorLaneJoints = 16;

}  // namespace dynid::detail
