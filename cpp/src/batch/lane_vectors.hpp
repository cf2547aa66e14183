// The lane types of the batch kernels and the moves between them and memory: W samples in the W
// lanes of a vector V, and the (T, width) row-major arrays of samples read and written a block of
// W rows at a time. Included by lane_kernels.hpp (same rules: no library header, internal
// linkage, DYNID_LANES and DYNID_LANES_NS defined by the including lanes_*.cpp).
//
// A full block of W samples is W consecutive rows: reading column c of it lane by lane costs one
// scalar load and one insert per lane, and writing it one extract and one store per lane. With 4
// and 8 lanes a group of G = 4 adjacent columns is moved instead with W vector loads (stores) of
// 4 doubles and in-register 4 x 4 transposes, about a third of the instructions; partial blocks
// (the last W - 1 samples at most), arrays narrower than G and 2 lanes keep the lane-by-lane
// moves.
#pragma once

namespace dynid::detail::DYNID_LANES_NS {
namespace {

constexpr int W = DYNID_LANES;
typedef double V __attribute__((vector_size(8 * W)));
typedef long long Bits __attribute__((vector_size(8 * W)));

// Two-vector shuffle with constant lane indices (GCC: __builtin_shuffle with an index vector,
// which GCC before 12 has and __builtin_shufflevector not; Clang: __builtin_shufflevector).
#if defined(__clang__)
#define DYNID_SHUFFLE(T, a, b, ...) __builtin_shufflevector(a, b, __VA_ARGS__)
#else
#define DYNID_SHUFFLE(T, a, b, ...) __builtin_shuffle(a, b, T{__VA_ARGS__})
#endif

// x in every lane. x - 0 is x exactly (also for -0), which GCC folds into one broadcast, where
// x + 0 (0 + -0 is +0) costs an addition more and a loop over the lanes builds the vector by
// inserts on AVX2.
inline V splat(double x) {
  const V zero = {};
  return x - zero;
}

// True when any lane of the mask is set: the lanes OR-ed pairwise by shuffles (log2 W steps), so
// that a test of all lanes costs one branch instead of one per lane.
inline bool any_lane(Bits m) {
#if DYNID_LANES == 8
  m |= DYNID_SHUFFLE(Bits, m, m, 4, 5, 6, 7, 0, 1, 2, 3);
  m |= DYNID_SHUFFLE(Bits, m, m, 2, 3, 0, 1, 6, 7, 4, 5);
  m |= DYNID_SHUFFLE(Bits, m, m, 1, 0, 3, 2, 5, 4, 7, 6);
#elif DYNID_LANES == 4
  m |= DYNID_SHUFFLE(Bits, m, m, 2, 3, 0, 1);
  m |= DYNID_SHUFFLE(Bits, m, m, 1, 0, 3, 2);
#elif DYNID_LANES == 2
  m |= DYNID_SHUFFLE(Bits, m, m, 1, 0);
#else
#error "DYNID_LANES: 2, 4 or 8"
#endif
  return m[0] != 0;
}

// ------------------------------------------------------------------- groups of columns
// load_group(p, stride, cols): cols[j][l] = p[l * stride + j] for j < G, l < W (all W rows);
// store_group(cols, p, stride) the converse. Both by transposes of 4 x 4 (or 2 x 2) blocks.
#if DYNID_LANES == 2
// Two lanes: a group would transpose 2 x 2 values, measured no faster than the lane-by-lane
// moves; they keep those.
constexpr bool kByGroups = false;
constexpr int G = 2;
inline void load_group(const double*, long, V*) {}
inline void store_group(const V*, double*, long) {}
#else
constexpr bool kByGroups = true;
constexpr int G = 4;
typedef double V4 __attribute__((vector_size(32)));
typedef long long Bits4 __attribute__((vector_size(32)));

inline V4 load4(const double* p) {
  V4 r;
  __builtin_memcpy(&r, p, sizeof r);
  return r;
}
inline void store4(double* p, const V4& r) { __builtin_memcpy(p, &r, sizeof r); }

// The transpose of the 4 x 4 block whose rows are r0..r3 (its own inverse).
inline void transpose4(const V4& r0, const V4& r1, const V4& r2, const V4& r3, V4& c0, V4& c1,
                       V4& c2, V4& c3) {
  const V4 t0 = DYNID_SHUFFLE(Bits4, r0, r1, 0, 4, 2, 6);
  const V4 t1 = DYNID_SHUFFLE(Bits4, r0, r1, 1, 5, 3, 7);
  const V4 t2 = DYNID_SHUFFLE(Bits4, r2, r3, 0, 4, 2, 6);
  const V4 t3 = DYNID_SHUFFLE(Bits4, r2, r3, 1, 5, 3, 7);
  c0 = DYNID_SHUFFLE(Bits4, t0, t2, 0, 1, 4, 5);
  c1 = DYNID_SHUFFLE(Bits4, t1, t3, 0, 1, 4, 5);
  c2 = DYNID_SHUFFLE(Bits4, t0, t2, 2, 3, 6, 7);
  c3 = DYNID_SHUFFLE(Bits4, t1, t3, 2, 3, 6, 7);
}

#if DYNID_LANES == 4
inline void load_group(const double* p, long stride, V* cols) {
  transpose4(load4(p), load4(p + stride), load4(p + 2 * stride), load4(p + 3 * stride), cols[0],
             cols[1], cols[2], cols[3]);
}
inline void store_group(const V* cols, double* p, long stride) {
  V4 r0, r1, r2, r3;
  transpose4(cols[0], cols[1], cols[2], cols[3], r0, r1, r2, r3);
  store4(p, r0), store4(p + stride, r1), store4(p + 2 * stride, r2), store4(p + 3 * stride, r3);
}
#else
// 8 lanes: rows 0-3 and rows 4-7 transposed apart, each column the two halves.
inline V join(const V4& lo, const V4& hi) {
  return V{lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]};
}
inline V4 low(const V& v) { return V4{v[0], v[1], v[2], v[3]}; }
inline V4 high(const V& v) { return V4{v[4], v[5], v[6], v[7]}; }
inline void load_group(const double* p, long stride, V* cols) {
  V4 a0, a1, a2, a3, b0, b1, b2, b3;
  transpose4(load4(p), load4(p + stride), load4(p + 2 * stride), load4(p + 3 * stride), a0, a1, a2,
             a3);
  const double* q = p + 4 * stride;
  transpose4(load4(q), load4(q + stride), load4(q + 2 * stride), load4(q + 3 * stride), b0, b1, b2,
             b3);
  cols[0] = join(a0, b0), cols[1] = join(a1, b1), cols[2] = join(a2, b2), cols[3] = join(a3, b3);
}
inline void store_group(const V* cols, double* p, long stride) {
  V4 r0, r1, r2, r3;
  transpose4(low(cols[0]), low(cols[1]), low(cols[2]), low(cols[3]), r0, r1, r2, r3);
  store4(p, r0), store4(p + stride, r1), store4(p + 2 * stride, r2), store4(p + 3 * stride, r3);
  double* q = p + 4 * stride;
  transpose4(high(cols[0]), high(cols[1]), high(cols[2]), high(cols[3]), r0, r1, r2, r3);
  store4(q, r0), store4(q + stride, r1), store4(q + 2 * stride, r2), store4(q + 3 * stride, r3);
}
#endif
#endif

// Columns [begin, end) of the W rows at p (row stride `stride`), end - begin >= G, moved by
// groups of G; the last group is shifted back to end at `end` (it overlaps the one before when
// G does not divide the count: those entries are moved twice, with the same values).
template <class Move>
inline void by_groups(int begin, int end, Move move) {
  for (int c0 = begin; c0 + G < end; c0 += G) move(c0);
  move(end - G);
}

// p[0 .. count) = 0 by stores of G doubles (a memset call per short run costs more).
inline void zero_fill(double* p, int count) {
  if (count < G) {
    for (int k = 0; k < count; ++k) p[k] = 0.0;
    return;
  }
  const V zero = {};
  by_groups(0, count, [&](int k) { __builtin_memcpy(p + k, &zero, sizeof(double) * G); });
}

// ------------------------------------------------------------------ loading and storing lanes
// Samples t0 .. t0 + count - 1 (count <= W) of a row-major (T, width) array as `width` vectors:
// column c in cols[c], sample t0 + l in lane l; lanes past the last sample hold zeros (evaluated,
// never stored).
inline void load_block(const double* data, long t0, int count, int width, V* cols) {
  const double* p = data + t0 * width;
  if (kByGroups && count == W && width >= G) {
    by_groups(0, width, [&](int c) { load_group(p + c, width, cols + c); });
    return;
  }
  for (int c = 0; c < width; ++c) {
    V v = {};
    for (int l = 0; l < count; ++l) v[l] = p[l * width + c];
    cols[c] = v;
  }
}

// Column `column` of the same block alone, lane by lane. rnea reads its three inputs so, joint by
// joint inside its recursion: measured 4-8 % faster there (AVX2 and AVX-512) than moving the
// block into arrays first, which gravity and the regressor gain from.
inline V load_column(const double* data, long t0, int count, int width, int column) {
  V v = {};
  const double* p = data + t0 * width + column;
  if (count == W) {
    for (int l = 0; l < W; ++l) v[l] = p[l * width];
  } else {
    for (int l = 0; l < count; ++l) v[l] = p[l * width];
  }
  return v;
}

// x * 0 is NaN exactly when x is not finite: `check` collects it per lane.
inline void add_check(V& check, const V& v) { check += v * 0.0; }

// The first sample of the block with a non-finite checked entry, or -1.
inline long first_nonfinite(const V& check, long t0, int count) {
  if (!any_lane(check != 0.0)) return -1;  // NaN != 0: true
  for (int l = 0; l < count; ++l)
    if (check[l] != 0.0) return t0 + l;
  return -1;  // only lanes past the last sample (never stored)
}

// Stores `values` (one vector per output entry) for the samples of the block and returns the
// first sample with a non-finite entry, or -1.
inline long store(const V* values, int width, double* out, long t0, int count) {
  V check = {};
  double* p = out + t0 * width;
  if (kByGroups && count == W && width >= G) {
    for (int k = 0; k < width; ++k) add_check(check, values[k]);
    by_groups(0, width, [&](int c) { store_group(values + c, p + c, width); });
  } else {
    for (int k = 0; k < width; ++k) {
      const V v = values[k];
      add_check(check, v);
      for (int l = 0; l < count; ++l) p[l * width + k] = v[l];
    }
  }
  return first_nonfinite(check, t0, count);
}

}  // namespace
}  // namespace dynid::detail::DYNID_LANES_NS
