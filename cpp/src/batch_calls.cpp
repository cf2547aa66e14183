// dynid::batch (batch.hpp): each call checks its arguments, then runs the SIMD lane kernel when
// there is one for it and this model and layout (cpp/src/batch/), or else the per-sample
// function on every row, over the threads of the BatchWorkspace (batch_runner.cpp).
#include "dynid/batch.hpp"

#include <algorithm>
#include <initializer_list>
#include <string>

#include "dynid/coriolis.hpp"
#include "dynid/coriolis_matrix.hpp"
#include "dynid/crba.hpp"
#include "dynid/detail/argument_checks.hpp"
#include "dynid/detail/batch.hpp"
#include "dynid/detail/batch_runner.hpp"
#include "dynid/energy.hpp"
#include "dynid/forward_dynamics.hpp"
#include "dynid/friction.hpp"
#include "dynid/gravity.hpp"
#include "dynid/jacobian_dot.hpp"
#include "dynid/kinematics.hpp"
#include "dynid/regressor.hpp"
#include "dynid/rnea.hpp"
#include "dynid/rnea_derivatives.hpp"
#include "dynid/rnea_time_derivatives.hpp"

namespace dynid::batch {
namespace {

using Index = Eigen::Index;
using detail::check_shape;
using ConstVec = Eigen::Map<const VectorX>;
using Strided = Eigen::Map<MatrixX, 0, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;
using RowMap = Eigen::Map<RowMajorMatrixX>;

// The shared checks: the workspace's joints, then each input T x n (T from the first), then the
// result T x width. Returns T.
Index check_arguments(const char* function, const Model& model, const BatchWorkspace& ws,
                      std::initializer_list<std::pair<const char*, const Samples*>> inputs,
                      const char* result_name, const Results& result, Index width) {
  if (ws.n() != model.n()) detail::throw_wrong_workspace(function, ws.n(), model.n());
  const Index T = inputs.begin()->second->rows();
  for (const auto& [name, x] : inputs)
    check_shape(function, name, x->rows(), x->cols(), T, model.n());
  check_shape(function, result_name, result.rows(), result.cols(), T, width);
  return T;
}

// Sample t of x (its row) as a vector.
ConstVec row(const Samples& x, Index t) {
  return ConstVec(x.data() + t * x.outerStride(), x.cols());
}

// x * 0 is 0 for finite x and NaN otherwise: one branch per sample. Four sums, so that the
// additions do not wait for each other (a single sum is bound by the adder's latency).
bool all_finite(const double* data, Index count) {
  double c0 = 0.0, c1 = 0.0, c2 = 0.0, c3 = 0.0;
  Index k = 0;
  for (; k + 4 <= count; k += 4) {
    c0 += data[k] * 0.0;
    c1 += data[k + 1] * 0.0;
    c2 += data[k + 2] * 0.0;
    c3 += data[k + 3] * 0.0;
  }
  for (; k < count; ++k) c0 += data[k] * 0.0;
  return (c0 + c1) + (c2 + c3) == 0.0;
}

// sample(thread's slot, t, result row t) for every t, each result checked while it is in cache.
template <class Sample>
Report per_sample(const Model& model, BatchWorkspace& ws, Index T, Results& result, Sample sample) {
  const Index width = result.cols();
  std::vector<detail::BatchSlot>& slots = detail::slots(ws);
  auto work = [&](int slot, Index begin, Index end) -> Index {
    detail::BatchSlot& s = slots[static_cast<std::size_t>(slot)];
    for (Index t = begin; t < end; ++t) {
      double* out = result.data() + t * result.outerStride();
      sample(s, t, out);
      if (!all_finite(out, width)) return t;
    }
    return -1;
  };
  const double n = model.n();
  const double cost = std::max(n * n, static_cast<double>(width));
  return detail::run_chunks(T, detail::batch_threads(ws, T), detail::chunk_for_work(cost), work,
                            ws.interrupt());
}

// True when the lane kernels can run this batch: a CPU path, few enough joints, drive terms per
// joint (T = I: detail/drive_terms.hpp) and rows stored one after the other.
bool use_lanes(const Model& model, Index T, int max_joints,
               std::initializer_list<const Samples*> inputs, const Results& result) {
  if (T == 0 || detail::batch_kernels() == nullptr || model.n() > max_joints ||
      !model.transmission_is_identity() || result.outerStride() != result.cols())
    return false;
  for (const Samples* x : inputs)
    if (x->outerStride() != x->cols()) return false;
  return true;
}

// kernel(kernels, batch model, begin, count) runs the lane kernel on samples [begin, begin +
// count) and returns the first non-finite one relative to begin, or -1.
template <class Kernel>
Report lanes(const Model& model, BatchWorkspace& ws, Index T, Kernel kernel) {
  const detail::BatchModel bm = detail::batch_model(model, detail::lane_joints(ws));
  const detail::LaneKernels& k = *detail::batch_kernels();
  auto work = [&](int, Index begin, Index end) -> Index {
    const long bad = kernel(k, bm, begin, static_cast<long>(end - begin));
    return bad >= 0 ? begin + bad : -1;
  };
  return detail::run_chunks(T, detail::batch_threads(ws, T), detail::kChunk, work, ws.interrupt());
}

Strided row_major(double* data, int rows, int cols) {
  return Strided(data, rows, cols, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(1, cols));
}

}  // namespace

Report rnea(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
            const Samples& qdd, Results tau) {
  const int n = model.n();
  const Index T = check_arguments("batch::rnea", model, ws, {{"q", &q}, {"qd", &qd}, {"qdd", &qdd}},
                                  "tau", tau, n);
  if (use_lanes(model, T, detail::kMaxBatchJoints, {&q, &qd, &qdd}, tau))
    return lanes(
        model, ws, T,
        [&](const detail::LaneKernels& k, const detail::BatchModel& bm, Index b, long count) {
          return k.rnea(bm, q.data() + b * n, qd.data() + b * n, qdd.data() + b * n,
                        tau.data() + b * n, count);
        });
  return per_sample(model, ws, T, tau, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::rnea(model, s.ws, row(q, t), row(qd, t), row(qdd, t),
                VectorOut(Eigen::Map<VectorX>(out, n)));
  });
}

Report mass_matrix(const Model& model, BatchWorkspace& ws, const Samples& q, Results M) {
  const int n = model.n();
  const Index T = check_arguments("batch::mass_matrix", model, ws, {{"q", &q}}, "M", M, n * n);
  if (use_lanes(model, T, detail::kMaxBatchJoints, {&q}, M))
    return lanes(
        model, ws, T,
        [&](const detail::LaneKernels& k, const detail::BatchModel& bm, Index b, long count) {
          return k.mass_matrix(bm, q.data() + b * n, M.data() + b * n * n, count);
        });
  return per_sample(model, ws, T, M, [&](detail::BatchSlot& s, Index t, double* out) {
    crba(model, s.ws, row(q, t), row_major(out, n, n));
  });
}

Report gravity(const Model& model, BatchWorkspace& ws, const Samples& q, Results g) {
  const int n = model.n();
  const Index T = check_arguments("batch::gravity", model, ws, {{"q", &q}}, "g", g, n);
  if (use_lanes(model, T, detail::kMaxBatchJoints, {&q}, g))
    return lanes(
        model, ws, T,
        [&](const detail::LaneKernels& k, const detail::BatchModel& bm, Index b, long count) {
          return k.gravity(bm, q.data() + b * n, g.data() + b * n, count);
        });
  return per_sample(model, ws, T, g, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::gravity(model, s.ws, row(q, t), Eigen::Map<VectorX>(out, n));
  });
}

Report coriolis(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                Results c) {
  const int n = model.n();
  const Index T =
      check_arguments("batch::coriolis", model, ws, {{"q", &q}, {"qd", &qd}}, "c", c, n);
  return per_sample(model, ws, T, c, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::coriolis(model, s.ws, row(q, t), row(qd, t), Eigen::Map<VectorX>(out, n));
  });
}

Report coriolis_matrix(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                       Results S) {
  const int n = model.n();
  const Index T =
      check_arguments("batch::coriolis_matrix", model, ws, {{"q", &q}, {"qd", &qd}}, "S", S, n * n);
  return per_sample(model, ws, T, S, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::coriolis_matrix(model, s.ws, row(q, t), row(qd, t), row_major(out, n, n));
  });
}

Report friction(const Model& model, BatchWorkspace& ws, const Samples& qd, Results tau) {
  const int n = model.n();
  const Index T = check_arguments("batch::friction", model, ws, {{"qd", &qd}}, "tau", tau, n);
  return per_sample(model, ws, T, tau, [&](detail::BatchSlot&, Index t, double* out) {
    dynid::friction(model, row(qd, t), Eigen::Map<VectorX>(out, n));
  });
}

Report forward_dynamics(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                        const Samples& tau, Results qdd) {
  const int n = model.n();
  const Index T = check_arguments("batch::forward_dynamics", model, ws,
                                  {{"q", &q}, {"qd", &qd}, {"tau", &tau}}, "qdd", qdd, n);
  return per_sample(model, ws, T, qdd, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::forward_dynamics(model, s.ws, row(q, t), row(qd, t), row(tau, t),
                            Eigen::Map<VectorX>(out, n));
  });
}

Report kinetic_energy(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                      Results energy) {
  const Index T = check_arguments("batch::kinetic_energy", model, ws, {{"q", &q}, {"qd", &qd}},
                                  "energy", energy, 1);
  return per_sample(model, ws, T, energy, [&](detail::BatchSlot& s, Index t, double* out) {
    *out = dynid::kinetic_energy(model, s.ws, row(q, t), row(qd, t));
  });
}

Report potential_energy(const Model& model, BatchWorkspace& ws, const Samples& q, Results energy) {
  const Index T =
      check_arguments("batch::potential_energy", model, ws, {{"q", &q}}, "energy", energy, 1);
  return per_sample(model, ws, T, energy, [&](detail::BatchSlot& s, Index t, double* out) {
    *out = dynid::potential_energy(model, s.ws, row(q, t));
  });
}

Report fkine(const Model& model, BatchWorkspace& ws, const Samples& q, Results T_out) {
  const Index T = check_arguments("batch::fkine", model, ws, {{"q", &q}}, "T", T_out, 16);
  return per_sample(model, ws, T, T_out, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::fkine(model, s.ws, row(q, t), row_major(out, 4, 4));
  });
}

Report jacobian(const Model& model, BatchWorkspace& ws, const Samples& q, Results J) {
  const int n = model.n();
  const Index T = check_arguments("batch::jacobian", model, ws, {{"q", &q}}, "J", J, 6 * n);
  return per_sample(model, ws, T, J, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::jacobian(model, s.ws, row(q, t), row_major(out, 6, n));
  });
}

Report jacobian_dot(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                    Results Jdot) {
  const int n = model.n();
  const Index T = check_arguments("batch::jacobian_dot", model, ws, {{"q", &q}, {"qd", &qd}},
                                  "Jdot", Jdot, 6 * n);
  return per_sample(model, ws, T, Jdot, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::jacobian_dot(model, s.ws, row(q, t), row(qd, t), row_major(out, 6, n));
  });
}

Report regressor(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                 const Samples& qdd, bool rotor, bool friction, Results Y) {
  const int n = model.n(), P = regressor_columns(n, rotor, friction);
  const Index T = check_arguments("batch::regressor", model, ws,
                                  {{"q", &q}, {"qd", &qd}, {"qdd", &qdd}}, "Y", Y, Index{n} * P);
  if (use_lanes(model, T, detail::kMaxRegressorLaneJoints, {&q, &qd, &qdd}, Y))
    return lanes(
        model, ws, T,
        [&](const detail::LaneKernels& k, const detail::BatchModel& bm, Index b, long count) {
          return k.regressor(bm, q.data() + b * n, qd.data() + b * n, qdd.data() + b * n, rotor,
                             friction, nullptr, P, Y.data() + b * n * P, count);
        });
  return per_sample(model, ws, T, Y, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::regressor(model, s.ws, row(q, t), row(qd, t), row(qdd, t), rotor, friction,
                     RowMap(out, n, P));
  });
}

Report regressor(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                 const Samples& qdd, bool rotor, bool friction, const std::vector<int>& columns,
                 Results Y) {
  const int n = model.n(), P = regressor_columns(n, rotor, friction);
  const int C = static_cast<int>(columns.size());
  if (C == 0)
    throw std::invalid_argument(
        "columns: expected at least one column (in dynid::batch::regressor)");
  for (int k = 0; k < C; ++k)
    if (columns[k] < 0 || columns[k] >= P)
      throw std::invalid_argument("columns: expected indices in [0, " + std::to_string(P) +
                                  "), got " + std::to_string(columns[k]) + " at position " +
                                  std::to_string(k) + " (in dynid::batch::regressor)");
  const Index T = check_arguments("batch::regressor", model, ws,
                                  {{"q", &q}, {"qd", &qd}, {"qdd", &qdd}}, "Y", Y, Index{n} * C);
  if (use_lanes(model, T, detail::kMaxRegressorLaneJoints, {&q, &qd, &qdd}, Y))
    return lanes(
        model, ws, T,
        [&](const detail::LaneKernels& k, const detail::BatchModel& bm, Index b, long count) {
          return k.regressor(bm, q.data() + b * n, qd.data() + b * n, qdd.data() + b * n, rotor,
                             friction, columns.data(), C, Y.data() + b * n * C, count);
        });
  // Each sample's full regressor goes to its thread's buffer (in cache) and the selected
  // columns are copied out of it; the buffers are sized here, before any thread starts.
  std::vector<detail::BatchSlot>& slots = detail::slots(ws);
  for (detail::BatchSlot& slot : slots) slot.scratch.resize(static_cast<std::size_t>(n) * P);
  return per_sample(model, ws, T, Y, [&](detail::BatchSlot& s, Index t, double* out) {
    std::vector<double>& full = s.scratch;
    RowMap Yfull(full.data(), n, P);
    dynid::regressor(model, s.ws, row(q, t), row(qd, t), row(qdd, t), rotor, friction, Yfull);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < C; ++k)
        out[i * C + k] = full[static_cast<std::size_t>(i) * P + columns[k]];
  });
}

Report gravity_regressor(const Model& model, BatchWorkspace& ws, const Samples& q, Results Yg) {
  const int n = model.n();
  const Index T = check_arguments("batch::gravity_regressor", model, ws, {{"q", &q}}, "Yg", Yg,
                                  Index{n} * 10 * n);
  return per_sample(model, ws, T, Yg, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::gravity_regressor(model, s.ws, row(q, t), RowMap(out, n, 10 * n));
  });
}

Report inertia_regressor(const Model& model, BatchWorkspace& ws, const Samples& q, bool rotor,
                         Results Ym) {
  const int n = model.n(), rows = n * (n + 1) / 2, P = 10 * n + (rotor ? n : 0);
  const Index T = check_arguments("batch::inertia_regressor", model, ws, {{"q", &q}}, "Ym", Ym,
                                  Index{rows} * P);
  return per_sample(model, ws, T, Ym, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::inertia_regressor(model, s.ws, row(q, t), rotor, RowMap(out, rows, P));
  });
}

Report rnea_derivatives(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                        const Samples& qdd, Results dtau) {
  const int n = model.n();
  const Index T = check_arguments("batch::rnea_derivatives", model, ws,
                                  {{"q", &q}, {"qd", &qd}, {"qdd", &qdd}}, "dtau", dtau, 2 * n * n);
  return per_sample(model, ws, T, dtau, [&](detail::BatchSlot& s, Index t, double* out) {
    dynid::rnea_derivatives(model, s.ws, row(q, t), row(qd, t), row(qdd, t), row_major(out, n, n),
                            row_major(out + n * n, n, n));
  });
}

Report rnea_time_derivatives(const Model& model, BatchWorkspace& ws, const Samples& q,
                             const Samples& qd, const Samples& qdd, const Samples& qddd,
                             const Samples& qdddd, Results tau) {
  const int n = model.n();
  const Index T =
      check_arguments("batch::rnea_time_derivatives", model, ws,
                      {{"q", &q}, {"qd", &qd}, {"qdd", &qdd}, {"qddd", &qddd}, {"qdddd", &qdddd}},
                      "tau", tau, 3 * n);
  return per_sample(model, ws, T, tau, [&](detail::BatchSlot& s, Index t, double* out) {
    Eigen::Map<VectorX> tau0(out, n), tau1(out + n, n), tau2(out + 2 * n, n);
    dynid::rnea_time_derivatives(model, s.ws, row(q, t), row(qd, t), row(qdd, t), row(qddd, t),
                                 row(qdddd, t), tau0, tau1, tau2);
  });
}

}  // namespace dynid::batch
