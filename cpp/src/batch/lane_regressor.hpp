// The torque regressor across samples in SIMD lanes: regressor.cpp's recursion (joint axes
// carried outwards, each 1 x 10 block the axis applied to the link's body regressor) per lane.
// Included by cpp/src/batch/lanes_*.cpp after lane_kernels.hpp (same rules, same namespace).

namespace dynid::detail::DYNID_LANES_NS {
namespace {

// Link j's body regressor as a linear map of a joint axis [s; l] (regressor.cpp's BodyMap).
struct BodyMapLanes {
  V a[3], W[9], G[18];

  BodyMapLanes(const V3& w, const V3& wd, const V3& acc) {
    const V xx = w.x * w.x, yy = w.y * w.y, zz = w.z * w.z;
    const V xy = w.x * w.y, xz = w.x * w.z, yz = w.y * w.z;
    a[0] = acc.x, a[1] = acc.y, a[2] = acc.z;
    W[0] = -yy - zz, W[1] = xy + wd.z, W[2] = xz - wd.y;
    W[3] = xy - wd.z, W[4] = -xx - zz, W[5] = yz + wd.x;
    W[6] = xz + wd.y, W[7] = yz - wd.x, W[8] = -xx - yy;
    const V zero = {};
    G[0] = wd.x, G[1] = xz, G[2] = zero - xy;
    G[3] = wd.y - xz, G[4] = wd.x + yz, G[5] = xx - yy;
    G[6] = wd.z + xy, G[7] = zz - xx, G[8] = wd.x - yz;
    G[9] = zero - yz, G[10] = wd.y, G[11] = xy;
    G[12] = yy - zz, G[13] = wd.z - xy, G[14] = wd.y + xz;
    G[15] = yz, G[16] = zero - xz, G[17] = wd.z;
  }

  void row(const V* U, V* out) const {
    const V s0 = U[0], s1 = U[1], s2 = U[2], l0 = U[3], l1 = U[4], l2 = U[5];
    out[0] = a[0] * l0 + a[1] * l1 + a[2] * l2;
    out[1] = W[0] * l0 + W[1] * l1 + W[2] * l2 + a[1] * s2 - a[2] * s1;
    out[2] = W[3] * l0 + W[4] * l1 + W[5] * l2 + a[2] * s0 - a[0] * s2;
    out[3] = W[6] * l0 + W[7] * l1 + W[8] * l2 + a[0] * s1 - a[1] * s0;
    for (int r = 0; r < 6; ++r) out[4 + r] = G[3 * r] * s0 + G[3 * r + 1] * s1 + G[3 * r + 2] * s2;
  }
};

// x in J_j's axes to DH frame j's: Rx(alpha)^T x (LinkOffset::rotate_to_link).
inline V3 offset_to_link(const BatchJoint& J, const V3& x) {
  const double ca = J.offset_cos_alpha, sa = J.offset_sin_alpha;
  return {x.x, ca * x.y + sa * x.z, -sa * x.y + ca * x.z};
}

// regressor.cpp's axis_to_child: reference point to O_j, then R^T on both parts.
inline void axis_to_child(const Joint& X, V* U) {
  const V3 s = {U[0], U[1], U[2]};
  const V3 l = V3{U[3], U[4], U[5]} + cross(s, X.p);
  const V3 s2 = rotate_to_child(X, s), l2 = rotate_to_child(X, l);
  U[0] = s2.x, U[1] = s2.y, U[2] = s2.z, U[3] = l2.x, U[4] = l2.y, U[5] = l2.z;
}

// regressor.cpp's axis_through_joint_to_link (standard DH).
inline void axis_through_joint_to_link(const Joint& X, const V& d, const BatchJoint& J, V* U) {
  const V c = X.ct, sn = X.st;
  const V l0 = U[3] + d * U[1], l1 = U[4] - d * U[0];
  const V s0 = c * U[0] + sn * U[1], s1 = -sn * U[0] + c * U[1], s2 = U[2];
  const V m0 = c * l0 + sn * l1, m1 = -sn * l0 + c * l1, m2 = U[5];
  const double ca = J.offset_cos_alpha, sa = J.offset_sin_alpha, a = J.offset_a;
  const V n1 = m1 + a * s2, n2 = m2 - a * s1;
  U[0] = s0;
  U[1] = ca * s1 + sa * s2;
  U[2] = -sa * s1 + ca * s2;
  U[3] = m0;
  U[4] = ca * n1 + sa * n2;
  U[5] = -sa * n1 + ca * n2;
}

// Stores entries (i, columns[k]) of the lane matrix `values` (n x P) as row-major (n, C) per
// sample; returns the first sample with a non-finite stored entry, or -1.
inline long store_columns(const V* values, int n, int P, const int* columns, int C, double* out,
                          long t0, int count) {
  V check = {};
  const long stride = static_cast<long>(n) * C;
  double* p = out + t0 * stride;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < C; ++k) {
      const V v = values[i * P + columns[k]];
      add_check(check, v);
      for (int l = 0; l < count; ++l) p[l * stride + i * C + k] = v[l];
    }
  return first_nonfinite(check, t0, count);
}

// Stores the full regressor of the block: per sample and row i, the structural zeros (links
// j < i, the other joints' drive columns) by memset, the rest from the lanes (by groups of
// columns for a full block, lane_vectors.hpp), so that about half of the 10n^2 + ... entries
// cost no store from a vector. Returns the first non-finite sample, or -1.
inline long store_regressor(const V* values, int n, int P, int rotor, int friction, double* out,
                            long t0, int count) {
  V check = {};
  const long stride = static_cast<long>(n) * P;
  double* base = out + t0 * stride;
  const int drive = 10 * n;
  for (int i = 0; i < n; ++i) {
    const V* row = values + i * P;
    double* first = base + i * P;  // row i of the block's first sample
    for (int l = 0; l < count; ++l) {
      double* r = first + l * stride;
      zero_fill(r, 10 * i);
      zero_fill(r + drive, P - drive);
    }
    if (kByGroups && count == W) {  // 10 (n - i) >= 10 >= G columns
      by_groups(10 * i, drive, [&](int k) {
        for (int g = 0; g < G; ++g) add_check(check, row[k + g]);
        store_group(row + k, first + k, stride);
      });
    } else {
      for (int k = 10 * i; k < drive; ++k) {
        add_check(check, row[k]);
        for (int l = 0; l < count; ++l) first[l * stride + k] = row[k][l];
      }
    }
    int diagonal[3], entries = 0, column = drive;  // row i's own Ia, Fv, Fs columns
    if (rotor) diagonal[entries++] = column + i, column += n;
    if (friction) diagonal[entries++] = column + i, diagonal[entries++] = column + n + i;
    for (int e = 0; e < entries; ++e) {
      const int k = diagonal[e];
      const V v = row[k];
      add_check(check, v);
      for (int l = 0; l < count; ++l) first[l * stride + k] = v[l];
    }
  }
  return first_nonfinite(check, t0, count);
}

long regressor(const BatchModel& bm, const double* q, const double* qd, const double* qdd,
               int rotor, int friction, const int* columns, int C, double* Y, long T) {
  const int n = bm.n;
  const int P = 10 * n + (rotor ? n : 0) + (friction ? 2 * n : 0);
  Joint X[n + 1];
  V d[n + 1];     // joint offsets along z (prismatic: q + d)
  V U[n + 1][6];  // joint axes in the current link's parameter frame
  V out[n * P], qv[n], qdv[n], qddv[n];
  const V zero = {};
  // Every block writes the same entries of `out` (blocks Y_ij, i <= j, and the drive diagonals):
  // the structural zeros, which store_columns may read, are set once.
  for (int k = 0; k < n * P; ++k) out[k] = zero;
  for (long t0 = 0; t0 < T; t0 += W) {
    const int count = T - t0 < W ? static_cast<int>(T - t0) : W;
    load_block(q, t0, count, n, qv);
    load_block(qd, t0, count, n, qdv);
    load_block(qdd, t0, count, n, qddv);
    V3 w = {zero, zero, zero}, wd = w, a = splat3(bm.base_acceleration);
    for (int j = 1; j <= n; ++j) {
      const BatchJoint& J = bm.joints[j - 1];
      const V qj = qv[j - 1], qdj = qdv[j - 1], qddj = qddv[j - 1];
      set_joint(J, qj, X[j]);
      d[j] = J.revolute ? splat(J.d) : qj + J.d;
      // Forward pass (propagate_motion): link j's w, wd and origin acceleration in J_j.
      const V3 origin_acc = origin_acceleration(J, X[j], w, wd, a);
      const V3 w_in = rotate_to_child(X[j], w), wd_in = rotate_to_child(X[j], wd);
      const V3 acc = rotate_to_child(X[j], origin_acc);
      if (J.revolute) {
        w = {w_in.x, w_in.y, w_in.z + qdj};
        wd = {wd_in.x + qdj * w_in.y, wd_in.y - qdj * w_in.x, wd_in.z + qddj};
        a = acc;
      } else {
        w = w_in;
        wd = wd_in;
        const V twice = 2.0 * qdj;
        a = {acc.x + twice * w_in.y, acc.y - twice * w_in.x, acc.z + qddj};
      }
      // Axes of joints 1..j-1 moved to link j's parameter frame, joint j's own added.
      V* own = U[j];
      for (int e = 0; e < 6; ++e) own[e] = zero;
      own[J.revolute ? 2 : 5] = splat(1.0);
      if (J.offset_identity) {
        for (int i = 1; i < j; ++i) axis_to_child(X[j], U[i]);
      } else {
        for (int i = 1; i < j; ++i) axis_through_joint_to_link(X[j], d[j], J, U[i]);
        // axis_to_link: reference point to (a, 0, 0), then Rx(-alpha).
        const V3 s = offset_to_link(J, {own[0], own[1], own[2]});
        const V3 l =
            offset_to_link(J, {own[3], own[4] + J.offset_a * own[2], own[5] - J.offset_a * own[1]});
        own[0] = s.x, own[1] = s.y, own[2] = s.z, own[3] = l.x, own[4] = l.y, own[5] = l.z;
      }
      // Link j's motion in its parameter frame (motion_in_link_frame) and its blocks Y_ij.
      V3 lw = w, lwd = wd, la = a;
      if (!J.offset_identity) {
        const V3 po = {splat(J.offset_a), zero, zero};
        lw = offset_to_link(J, w);
        lwd = offset_to_link(J, wd);
        la = offset_to_link(J, a + cross(wd, po) + cross(w, cross(w, po)));
      }
      const BodyMapLanes map(lw, lwd, la);
      for (int i = 1; i <= j; ++i) map.row(U[i], out + (i - 1) * P + 10 * (j - 1));
      int column = 10 * n;
      if (rotor) {
        out[(j - 1) * P + column + (j - 1)] = qddj;
        column += n;
      }
      if (friction) {
        out[(j - 1) * P + column + (j - 1)] = qdj;
        out[(j - 1) * P + column + n + (j - 1)] = sign(qdj);
      }
    }
    const long bad = columns ? store_columns(out, n, P, columns, C, Y, t0, count)
                             : store_regressor(out, n, P, rotor, friction, Y, t0, count);
    if (bad >= 0) return bad;
  }
  return -1;
}

}  // namespace
}  // namespace dynid::detail::DYNID_LANES_NS
