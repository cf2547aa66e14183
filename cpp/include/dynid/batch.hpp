// Batch evaluation: one dynamics call on T samples at once, e.g. every sample of a log for the
// regressor of an identification, in C++ (the Python batch calls are these functions).
//
// Inputs are (T, n) row-major matrices, sample t in row t; each result is a (T, k) row-major
// matrix whose row t holds sample t's result (a matrix result row by row, e.g. M(q_t) as n * n
// entries). A BatchWorkspace holds one Workspace per thread; the samples are split over its
// threads in chunks, and where the CPU allows, rnea, gravity, mass_matrix and the regressor
// evaluate several samples at once in the SIMD lanes of one core (AVX-512: 8, AVX2: 4, SSE2: 2;
// models without a coupled transmission, rows stored contiguously). Each sample's result equals the
// per-sample call's (bit for bit on the scalar path, to a few ulp on the lanes).
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <vector>

#include "dynid/detail/batch_model.hpp"
#include "dynid/model.hpp"
#include "dynid/types.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

class BatchWorkspace;

// A check the calling thread of a batch runs between chunks, at most every 20 ms (e.g. for
// Ctrl-C in an interactive program): when check(context) returns true every thread stops after
// its current chunk and the batch call throws batch::Interrupted, its results partly written.
struct BatchInterrupt {
  bool (*check)(void* context) = nullptr;
  void* context = nullptr;
};

namespace detail {
struct BatchSlot {
  explicit BatchSlot(const Model& model) : ws(model) {}
  Workspace ws;
  std::vector<double> scratch;  // one sample's full regressor when only some columns are kept
};
std::vector<BatchSlot>& slots(BatchWorkspace& ws);
std::vector<BatchJoint>& lane_joints(BatchWorkspace& ws);
}  // namespace detail

// Everything a batch needs besides its inputs and results, sized once: a Workspace for each of
// up to `threads` threads (the calling thread is one of them). Like a Workspace it depends on n
// only. A batch call uses min(threads(), T / 512) threads (at least one): starting a thread costs
// about as much as a few hundred samples. One batch at a time per BatchWorkspace.
class BatchWorkspace {
 public:
  // threads >= 1 (std::invalid_argument naming threads). When memory runs out for some of the
  // workspaces, fewer threads (threads() says how many); std::bad_alloc when not even one fits.
  explicit BatchWorkspace(const Model& model, int threads = 1);

  int n() const { return n_; }
  int threads() const { return static_cast<int>(slots_.size()); }

  // The interrupt check of the batches run on this workspace (none by default).
  void set_interrupt(const BatchInterrupt& interrupt) { interrupt_ = interrupt; }
  const BatchInterrupt& interrupt() const { return interrupt_; }

 private:
  friend std::vector<detail::BatchSlot>& detail::slots(BatchWorkspace& ws);
  friend std::vector<detail::BatchJoint>& detail::lane_joints(BatchWorkspace& ws);
  int n_;
  std::vector<detail::BatchSlot> slots_;
  std::vector<detail::BatchJoint> joints_;  // the model as the lane kernels read it
  BatchInterrupt interrupt_;
};

namespace batch {

// (T, n) samples, one per row, and (T, k) results, one sample's per row. A column-major or
// non-double argument converts through a temporary (a copy per call): pass row-major matrices
// or Maps of row-major data.
using Samples = Eigen::Ref<const RowMajorMatrixX>;
using Results = Eigen::Ref<RowMajorMatrixX>;

// What a batch did: the first sample whose result is not finite (an overflow: values are not
// checked otherwise, NaN in gives NaN out), or -1; and the number of threads it ran on.
struct Report {
  Eigen::Index first_nonfinite = -1;
  int threads = 1;
};

// Thrown when the BatchWorkspace's interrupt check returned true.
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("batch interrupted") {}
};

// Each function checks first that ws was made for model.n() joints (names "ws"), that every
// input is T x n with the T of the first (names the input) and the result's shape (names it),
// and throws std::invalid_argument otherwise; "(in dynid::batch::rnea)" ends the message. An
// exception of a per-sample call (forward_dynamics' std::domain_error) stops every thread and
// is rethrown. Row t of each result is the per-sample function's result for row t of the inputs.

// T x n: rnea.hpp.
Report rnea(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
            const Samples& qdd, Results tau);
// T x n*n: crba.hpp (M row by row).
Report mass_matrix(const Model& model, BatchWorkspace& ws, const Samples& q, Results M);
// T x n: gravity.hpp.
Report gravity(const Model& model, BatchWorkspace& ws, const Samples& q, Results g);
// T x n: coriolis.hpp.
Report coriolis(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                Results c);
// T x n*n: coriolis_matrix.hpp.
Report coriolis_matrix(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                       Results S);
// T x n: friction.hpp.
Report friction(const Model& model, BatchWorkspace& ws, const Samples& qd, Results tau);
// T x n: forward_dynamics.hpp.
Report forward_dynamics(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                        const Samples& tau, Results qdd);
// T x 1: energy.hpp.
Report kinetic_energy(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                      Results energy);
Report potential_energy(const Model& model, BatchWorkspace& ws, const Samples& q, Results energy);
// T x 16 (4 x 4 poses) and T x 6n (6 x n Jacobians): kinematics.hpp.
Report fkine(const Model& model, BatchWorkspace& ws, const Samples& q, Results T);
Report jacobian(const Model& model, BatchWorkspace& ws, const Samples& q, Results J);
// T x 6n: jacobian_dot.hpp.
Report jacobian_dot(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                    Results Jdot);
// T x n*P, P = regressor_columns(n, rotor, friction): regressor.hpp. With `columns` (indices in
// [0, P), std::invalid_argument naming columns otherwise) only those C columns: T x n*C.
Report regressor(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                 const Samples& qdd, bool rotor, bool friction, Results Y);
Report regressor(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                 const Samples& qdd, bool rotor, bool friction, const std::vector<int>& columns,
                 Results Y);
// T x n*10n and T x n(n+1)/2*(10n [+ n]): regressor.hpp.
Report gravity_regressor(const Model& model, BatchWorkspace& ws, const Samples& q, Results Yg);
Report inertia_regressor(const Model& model, BatchWorkspace& ws, const Samples& q, bool rotor,
                         Results Ym);
// T x 2n*n: row t holds dtau/dq then dtau/dqd, each n x n row by row (rnea_derivatives.hpp).
Report rnea_derivatives(const Model& model, BatchWorkspace& ws, const Samples& q, const Samples& qd,
                        const Samples& qdd, Results dtau);
// T x 3n: row t holds tau, tau_dot, tau_ddot (rnea_time_derivatives.hpp).
Report rnea_time_derivatives(const Model& model, BatchWorkspace& ws, const Samples& q,
                             const Samples& qd, const Samples& qdd, const Samples& qddd,
                             const Samples& qdddd, Results tau);

}  // namespace batch
}  // namespace dynid
