// Batch kernels across samples: W samples evaluated at once, one per SIMD lane (structure of
// arrays: every quantity of the scalar kernels becomes a vector of W values). The arithmetic is
// that of the scalar reference kernels (rnea.cpp, gravity.cpp, crba.cpp), written per component.
//
// Included only by cpp/src/batch/lanes_*.cpp, each compiled with its own instruction-set flags,
// with DYNID_LANES (W) and DYNID_LANES_NS (a namespace unique to that translation unit) defined.
// GCC/Clang vector extensions compile to the instruction set of the translation unit. Nothing
// here includes a library header (see batch_model.hpp: no inline function may be shared with the
// baseline code), and everything has internal linkage.
#include "dynid/detail/batch_model.hpp"
#include "lane_vectors.hpp"

namespace dynid::detail::DYNID_LANES_NS {
namespace {

// ------------------------------------------------------------------------ sin and cos per lane
// Cody-Waite reduction x = k pi/2 + r, |r| <= pi/4, with pi/2 split into two 33-bit parts and a
// remainder, so that k * C1 and k * C2 are exact for |k| < 2^20; then the minimax polynomials of
// Cephes (sin.c, about 1 ulp on [-pi/4, pi/4]) and the quadrant of k. Lanes with |x| above
// kReductionLimit (where k * C1 would no longer be exact) take libm's sin and cos instead.
constexpr double kTwoOverPi = 0x1.45f306dc9c883p-1;
constexpr double kPiOver2Part1 = 0x1.921fb544p+0;
constexpr double kPiOver2Part2 = 0x1.0b4611a6p-34;
constexpr double kPiOver2Part3 = 0x1.3198a2e037073p-69;
constexpr double kRoundMagic = 0x1.8p52;  // (x + 1.5 2^52) - 1.5 2^52 rounds to an integer
constexpr double kReductionLimit = 1e6;

inline void sincos_lanes(V x, V& s, V& c) {
  // shifted = 1.5 2^52 + k exactly, so its low mantissa bits are k mod 2^51: the quadrant without
  // a conversion to integers (which AVX2 does not have for doubles: one scalar per lane).
  const V shifted = x * kTwoOverPi + kRoundMagic;
  const V k = shifted - kRoundMagic;
  V r = x - k * kPiOver2Part1;
  r = r - k * kPiOver2Part2;
  r = r - k * kPiOver2Part3;
  const V z = r * r;
  const V ps = ((((1.58962301576546568060E-10 * z - 2.50507477628578072866E-8) * z +
                  2.75573136213857245213E-6) *
                     z -
                 1.98412698295895385996E-4) *
                    z +
                8.33333333332211858878E-3) *
                   z -
               1.66666666666666307295E-1;
  const V pc = ((((-1.13585365213876817300E-11 * z + 2.08757008419747316778E-9) * z -
                  2.75573141792967388112E-7) *
                     z +
                 2.48015872888517045348E-5) *
                    z -
                1.38888888888730564116E-3) *
                   z +
               4.16666666666665929218E-2;
  const V sr = r + r * z * ps;
  const V cr = (1.0 - 0.5 * z) + z * z * pc;
  // Quadrant k mod 4: sin = (s, c, -s, -c), cos = (c, -s, -c, s).
  const Bits quadrant = (Bits)shifted;
  const Bits swap = -(quadrant & 1);  // all ones where k is odd
  const Bits sb = (Bits)sr, cb = (Bits)cr;
  Bits sin_bits = (swap & cb) | (~swap & sb);
  Bits cos_bits = (swap & sb) | (~swap & cb);
  sin_bits ^= (quadrant & 2) << 62;
  cos_bits ^= ((quadrant + 1) & 2) << 62;
  s = (V)sin_bits;
  c = (V)cos_bits;
  const Bits inside = (x <= kReductionLimit) & (x >= -kReductionLimit);  // false for NaN
  if (any_lane(~inside)) {
    for (int l = 0; l < W; ++l) {
      if (!inside[l]) {
        s[l] = __builtin_sin(x[l]);
        c[l] = __builtin_cos(x[l]);
      }
    }
  }
}

// sin and cos of `count` angles, W at a time (for the joint transforms of single calls).
void sincos_many(const double* x, double* s, double* c, int count) {
  for (int k = 0; k < count; k += W) {
    const int m = count - k < W ? count - k : W;
    V v = {}, sv, cv;
    for (int l = 0; l < m; ++l) v[l] = x[k + l];
    sincos_lanes(v, sv, cv);
    for (int l = 0; l < m; ++l) s[k + l] = sv[l], c[k + l] = cv[l];
  }
}

// True when every x[k], k < count, is finite (x * 0 is 0 for finite x, NaN otherwise), four
// vector sums at a time; for the checks of large inputs (a pass over 10^5 values).
bool all_finite(const double* x, long count) {
  V s0 = {}, s1 = {}, s2 = {}, s3 = {};
  long k = 0;
  for (; k + 4 * W <= count; k += 4 * W) {
    V a, b, c, d;
    __builtin_memcpy(&a, x + k, sizeof a);
    __builtin_memcpy(&b, x + k + W, sizeof b);
    __builtin_memcpy(&c, x + k + 2 * W, sizeof c);
    __builtin_memcpy(&d, x + k + 3 * W, sizeof d);
    s0 += a * 0.0, s1 += b * 0.0, s2 += c * 0.0, s3 += d * 0.0;
  }
  double tail = 0.0;
  for (; k < count; ++k) tail += x[k] * 0.0;
  return !any_lane((s0 + s1) + (s2 + s3) != 0.0) && tail == 0.0;
}

// ------------------------------------------------------------------------------ 3-vectors
struct V3 {
  V x, y, z;
};

inline V3 operator+(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3& operator+=(V3& a, const V3& b) {
  a.x += b.x, a.y += b.y, a.z += b.z;
  return a;
}
inline V3 operator*(const V& s, const V3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline V3 splat3(const double* v) { return {splat(v[0]), splat(v[1]), splat(v[2])}; }

// I v for a symmetric I given as (xx, xy, xz, yy, yz, zz).
inline V3 times_inertia(const double* I, const V3& v) {
  return {I[0] * v.x + I[1] * v.y + I[2] * v.z, I[1] * v.x + I[3] * v.y + I[4] * v.z,
          I[2] * v.x + I[4] * v.y + I[5] * v.z};
}

// ----------------------------------------------------------- joint transform (joint_transform.hpp)
struct Joint {
  double ca, sa;
  V ct, st;
  V3 p;
};

inline void set_joint(const BatchJoint& j, const V& q, Joint& X) {
  X.ca = j.cos_alpha;
  X.sa = j.sin_alpha;
  V d;
  if (j.revolute) {
    sincos_lanes(q + j.theta, X.st, X.ct);
    d = splat(j.d);
  } else {
    X.ct = splat(__builtin_cos(j.theta));
    X.st = splat(__builtin_sin(j.theta));
    d = q + j.d;
  }
  X.p = {splat(j.a), -j.sin_alpha * d, j.cos_alpha * d};
}

inline V3 rotate_to_child(const Joint& X, const V3& v) {
  const V y1 = X.ca * v.y + X.sa * v.z;
  const V y2 = -X.sa * v.y + X.ca * v.z;
  return {X.ct * v.x + X.st * y1, -X.st * v.x + X.ct * y1, y2};
}

inline V3 rotate_to_parent(const Joint& X, const V3& v) {
  const V y0 = X.ct * v.x - X.st * v.y;
  const V y1 = X.st * v.x + X.ct * v.y;
  return {y0, X.ca * y1 - X.sa * v.z, X.sa * y1 + X.ca * v.z};
}

// True when the origin of link i's frame is that of J_{i-1} (revolute, a = d = 0: X.p = 0), as
// for 5 of the LWR-IV's 7 joints: the terms in p, exact zeros then, are skipped (x + 0 is x, so
// no finite result changes; 0 * inf is NaN, but an overflow is reported from the other terms).
inline bool at_parent_origin(const BatchJoint& j) { return j.revolute && j.a == 0.0 && j.d == 0.0; }

// The acceleration of the origin of J_i, a + wd x p + w x (w x p) (propagate_motion), in J_{i-1}.
inline V3 origin_acceleration(const BatchJoint& j, const Joint& X, const V3& w, const V3& wd,
                              const V3& a) {
  if (at_parent_origin(j)) return a;
  return a + cross(wd, X.p) + cross(w, cross(w, X.p));
}

// sign(x) per lane, 0 for 0 and NaN (drive_terms.hpp): the bits of +1 and -1 selected by the
// comparisons' masks (no integer to double conversion, which AVX2 lacks).
inline V sign(const V& x) {
  const Bits plus = (Bits)splat(1.0), minus = (Bits)splat(-1.0);
  return (V)(((Bits)(x > 0.0) & plus) | ((Bits)(x < 0.0) & minus));
}

// ------------------------------------------------------------------------------- the kernels
// Backward pass of accumulate_wrenches (rnea.cpp): link i's wrench added to its parent's, and
// each projected on its joint axis.
inline void accumulate(const BatchModel& bm, int n, const Joint* X, V3* f, V3* mu, V* out) {
  for (int i = n; i >= 1; --i) {
    out[i - 1] = bm.joints[i - 1].revolute ? mu[i].z : f[i].z;
    if (i > 1) {
      const V3 f_parent = rotate_to_parent(X[i], f[i]);
      f[i - 1] += f_parent;
      V3 moment = rotate_to_parent(X[i], mu[i]);
      if (!at_parent_origin(bm.joints[i - 1])) moment += cross(X[i].p, f_parent);
      mu[i - 1] += moment;
    }
  }
}

// rnea and gravity take the number of joints N as a compile-time constant for the common arms
// (6 and 7 joints; N = 0: n from the model, any n): the compiler then unrolls the recursions over
// the links and indexes the per-link arrays statically, measured 10-25 % faster on AVX2 and
// AVX-512 (the same operations in the same order: the same results).
template <int N>
long rnea_of(const BatchModel& bm, const double* q, const double* qd, const double* qdd,
             double* tau, long T) {
  const int n = N > 0 ? N : bm.n;
  Joint X[n + 1];
  V3 f[n + 1], mu[n + 1];
  V out[n], drive[n];
  for (long t0 = 0; t0 < T; t0 += W) {
    const int count = T - t0 < W ? static_cast<int>(T - t0) : W;
    const V zero = {};
    V3 w = {zero, zero, zero}, wd = w, a = splat3(bm.base_acceleration);
    for (int i = 1; i <= n; ++i) {  // forward pass (propagate_motion) and link wrenches
      const BatchJoint& J = bm.joints[i - 1];
      const V qi = load_column(q, t0, count, n, i - 1), qdi = load_column(qd, t0, count, n, i - 1),
              qddi = load_column(qdd, t0, count, n, i - 1);
      set_joint(J, qi, X[i]);
      const V3 origin_acc = origin_acceleration(J, X[i], w, wd, a);
      const V3 w_in = rotate_to_child(X[i], w), wd_in = rotate_to_child(X[i], wd);
      const V3 acc = rotate_to_child(X[i], origin_acc);
      if (J.revolute) {
        w = {w_in.x, w_in.y, w_in.z + qdi};
        wd = {wd_in.x + qdi * w_in.y, wd_in.y - qdi * w_in.x, wd_in.z + qddi};
        a = acc;
      } else {
        w = w_in;
        wd = wd_in;
        const V twice = 2.0 * qdi;
        a = {acc.x + twice * w_in.y, acc.y - twice * w_in.x, acc.z + qddi};
      }
      const V3 h = splat3(J.h);
      f[i] = splat(J.m) * a + cross(wd, h) + cross(w, cross(w, h));
      mu[i] = times_inertia(J.I, wd) + cross(w, times_inertia(J.I, w)) + cross(h, a);
      drive[i - 1] = J.Ia * qddi + (J.Fv * qdi + J.Fs * sign(qdi));
    }
    accumulate(bm, n, X, f, mu, out);
    for (int i = 0; i < n; ++i) out[i] += drive[i];
    const long bad = store(out, n, tau, t0, count);
    if (bad >= 0) return bad;
  }
  return -1;
}

long rnea(const BatchModel& bm, const double* q, const double* qd, const double* qdd, double* tau,
          long T) {
  if (bm.n == 7) return rnea_of<7>(bm, q, qd, qdd, tau, T);
  if (bm.n == 6) return rnea_of<6>(bm, q, qd, qdd, tau, T);
  return rnea_of<0>(bm, q, qd, qdd, tau, T);
}

template <int N>
long gravity_of(const BatchModel& bm, const double* q, double* g, long T) {
  const int n = N > 0 ? N : bm.n;
  Joint X[n + 1];
  V3 f[n + 1], mu[n + 1];
  V out[n], qv[n];
  for (long t0 = 0; t0 < T; t0 += W) {
    const int count = T - t0 < W ? static_cast<int>(T - t0) : W;
    load_block(q, t0, count, n, qv);
    V3 a = splat3(bm.base_acceleration);
    for (int i = 1; i <= n; ++i) {
      const BatchJoint& J = bm.joints[i - 1];
      set_joint(J, qv[i - 1], X[i]);
      a = rotate_to_child(X[i], a);
      f[i] = splat(J.m) * a;
      mu[i] = cross(splat3(J.h), a);
    }
    accumulate(bm, n, X, f, mu, out);
    const long bad = store(out, n, g, t0, count);
    if (bad >= 0) return bad;
  }
  return -1;
}

long gravity(const BatchModel& bm, const double* q, double* g, long T) {
  if (bm.n == 7) return gravity_of<7>(bm, q, g, T);
  if (bm.n == 6) return gravity_of<6>(bm, q, g, T);
  return gravity_of<0>(bm, q, g, T);
}

// Composite bodies (crba.cpp): mass, first moment, inertia (xx, xy, xz, yy, yz, zz).
struct Composite {
  V m;
  V3 h;
  V I[6];
};

// crba.cpp's add_to_parent per lane: the composite of J_i seen from J_{i-1}, added to `parent`.
inline void add_to_parent(const Joint& X, const Composite& c, Composite& parent) {
  const V* I = c.I;
  const V C = X.ct, S = X.st, CC = C * C, SS = S * S, CS = C * S;
  const V xx = CC * I[0] - 2.0 * CS * I[1] + SS * I[3];
  const V yy = SS * I[0] + 2.0 * CS * I[1] + CC * I[3];
  const V xy = CS * (I[0] - I[3]) + (CC - SS) * I[1];
  const V xz = C * I[2] - S * I[4];
  const V yz = S * I[2] + C * I[4];
  const V zz = I[5];
  const double ca = X.ca, sa = X.sa, aa = ca * ca, bb = sa * sa, ab = ca * sa;
  V R[6] = {xx,
            ca * xy - sa * xz,
            sa * xy + ca * xz,
            aa * yy - 2.0 * ab * yz + bb * zz,
            ab * (yy - zz) + (aa - bb) * yz,
            bb * yy + 2.0 * ab * yz + aa * zz};
  const V3 hr = rotate_to_parent(X, c.h);
  const V3& p = X.p;
  const V m = c.m;
  const V k =
      2.0 * (p.x * hr.x + p.y * hr.y + p.z * hr.z) + m * (p.x * p.x + p.y * p.y + p.z * p.z);
  R[0] += k - 2.0 * hr.x * p.x - m * p.x * p.x;
  R[3] += k - 2.0 * hr.y * p.y - m * p.y * p.y;
  R[5] += k - 2.0 * hr.z * p.z - m * p.z * p.z;
  R[1] -= hr.x * p.y + p.x * hr.y + m * p.x * p.y;
  R[2] -= hr.x * p.z + p.x * hr.z + m * p.x * p.z;
  R[4] -= hr.y * p.z + p.y * hr.z + m * p.y * p.z;
  parent.m += m;
  parent.h += hr + m * p;
  for (int e = 0; e < 6; ++e) parent.I[e] += R[e];
}

template <int N>  // as rnea_of
long mass_matrix_of(const BatchModel& bm, const double* q, double* M, long T) {
  const int n = N > 0 ? N : bm.n;
  Joint X[n + 1];
  Composite C[n + 1];
  V B[n * n], qv[n];
  for (long t0 = 0; t0 < T; t0 += W) {
    const int count = T - t0 < W ? static_cast<int>(T - t0) : W;
    load_block(q, t0, count, n, qv);
    for (int i = 1; i <= n; ++i) {
      const BatchJoint& J = bm.joints[i - 1];
      set_joint(J, qv[i - 1], X[i]);
      C[i].m = splat(J.m);
      C[i].h = splat3(J.h);
      for (int e = 0; e < 6; ++e) C[i].I[e] = splat(J.I[e]);
    }
    for (int i = n; i >= 2; --i) add_to_parent(X[i], C[i], C[i - 1]);
    for (int i = 1; i <= n; ++i) {
      const Composite& c = C[i];
      const V zero = {};
      V3 f, mu;  // wrench about the origin of J_i for a unit acceleration along z
      if (bm.joints[i - 1].revolute) {
        mu = {c.I[2], c.I[4], c.I[5]};
        f = {-c.h.y, c.h.x, zero};
      } else {
        mu = {c.h.y, -c.h.x, zero};
        f = {zero, zero, c.m};
      }
      B[(i - 1) * n + (i - 1)] = (bm.joints[i - 1].revolute ? mu.z : f.z) + bm.joints[i - 1].Ia;
      for (int j = i - 1; j >= 1; --j) {
        const Joint& Xj = X[j + 1];
        f = rotate_to_parent(Xj, f);
        mu = rotate_to_parent(Xj, mu) + cross(Xj.p, f);
        const V bji = bm.joints[j - 1].revolute ? mu.z : f.z;
        B[(j - 1) * n + (i - 1)] = bji;
        B[(i - 1) * n + (j - 1)] = bji;
      }
    }
    const long bad = store(B, n * n, M, t0, count);
    if (bad >= 0) return bad;
  }
  return -1;
}

long mass_matrix(const BatchModel& bm, const double* q, double* M, long T) {
  if (bm.n == 7) return mass_matrix_of<7>(bm, q, M, T);
  if (bm.n == 6) return mass_matrix_of<6>(bm, q, M, T);
  return mass_matrix_of<0>(bm, q, M, T);
}

}  // namespace
}  // namespace dynid::detail::DYNID_LANES_NS
