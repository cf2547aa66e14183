// Recursive least squares with exponential forgetting, for online identification of the base
// parameters theta from blocks of the linear model tau_k = Y_k theta. It is the batch LS
// solution of the notes (p. 27, "Least Squares (LS) identification": a = (Y^T Y)^-1 Y^T u over the
// stacked samples) computed one sample at a time; the recursion is the standard one (Ljung &
// Soderstrom, "Theory and Practice of Recursive Identification", 1983, ch. 2; Hollerbach, Khalil &
// Gautier, "Model Identification", Springer Handbook of Robotics, 2016, the chapter the notes
// cite).
//
// One update with the m x p block Y_k and the m torques tau_k, forgetting factor lambda in (0, 1]:
//
//   K     = P Y_k^T (lambda I + Y_k P Y_k^T)^-1               (p x m gain)
//   theta = theta + K (tau_k - Y_k theta)
//   P     = (P - K Y_k P) / lambda
//
// With lambda = 1 and P_0 = c I this gives after any number of blocks exactly the regularised
// batch solution theta = (sum Y^T Y + I/c)^-1 (sum Y^T tau + theta_0 / c): the finite initial
// covariance is a ridge prior, which vanishes as c grows. With lambda < 1 a block k samples old
// weighs lambda^k, so the estimate follows parameters that change (e.g. a payload).
//
// Numerics: P is kept as P = U D U^T (U unit upper triangular, D diagonal > 0) and updated with
// Bierman's UD measurement update (G. J. Bierman, "Factorization Methods for Discrete Sequential
// Estimation", 1977, ch. V), so P is symmetric and positive definite by construction for any
// number of updates, where the covariance form P - K Y P loses both to rounding once P spans many
// orders of magnitude (P_0 = 1e6 I, well-excited directions at 1e-6). The block is taken row by
// row: dividing D by lambda first turns the block update into a Kalman update with unit
// measurement variance, and for a white (diagonal) measurement variance the rows can be processed
// one after the other with the same result as the block formula above.
//
// Covariance windup: with lambda < 1, P grows as lambda^-k in directions the data do not excite
// (a robot at rest) until it overflows. Each entry of D is therefore capped at max_variance()
// (by default the largest entry of D at the initial state, i.e. c for P_0 = c I: no direction
// becomes less certain than the prior);
// with lambda = 1 D only decreases and the cap never acts.
//
// Real-time use: every buffer is allocated by the constructor; update() and reset() perform no
// heap allocation for any block size m (tests/cpp/test_rls_no_allocation.cpp checks this). One
// object per estimator and thread.
#pragma once

#include "dynid/types.hpp"

namespace dynid {

class RecursiveLeastSquares {
 public:
  // Any strides, so that a row-major NumPy block (m, p) is read in place.
  using MatrixIn = Eigen::Ref<const MatrixX, 0, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;

  // p parameters, theta_0 = 0, P_0 = initial_covariance * I. Throws std::invalid_argument for
  // p < 1, forgetting outside (0, 1] or initial_covariance not finite and > 0.
  explicit RecursiveLeastSquares(int p, double forgetting = 1.0, double initial_covariance = 1e6);

  // Initial estimate theta_0 (p) and full initial covariance P_0 (p x p, see reset()).
  RecursiveLeastSquares(const VectorIn& theta0, const MatrixIn& P0, double forgetting = 1.0);

  // Back to the initial state (theta_0, P_0) of the constructor or of the last reset(...) below.
  void reset();
  // New initial state theta_0 = 0, P_0 = initial_covariance * I, and restart from it.
  void reset(double initial_covariance);
  // New initial state theta_0, P_0, and restart from it. P_0 must be symmetric (to 1e-10 of its
  // largest entry) and positive definite (UD pivots above 1e-14 times its largest entry);
  // otherwise std::invalid_argument is thrown and the estimator is left as it was. Allocates
  // temporaries, unlike the two forms above.
  void reset(const VectorIn& theta0, const MatrixIn& P0);

  // One block: Y_k is m x p, tau_k has m entries (any m >= 1). Throws std::invalid_argument on
  // mismatched sizes; the values are not checked here (the Python binding rejects NaN/inf).
  // Values too large for double precision (|Y|, |tau| around 1e150 and beyond) overflow the
  // estimate or the covariance factors to inf/NaN: check is_finite() after updates with data
  // that may be that large, and reset() when it is false (the Python binding checks after every
  // call and restores the state from before it).
  void update(const MatrixIn& Y_k, const VectorIn& tau_k);

  // True when theta and the covariance factors U, D are all finite (O(p^2) reads, no allocation).
  bool is_finite() const { return theta_.allFinite() && D_.allFinite() && U_.allFinite(); }

  int p() const { return p_; }
  double forgetting() const { return lambda_; }
  void set_forgetting(double forgetting);  // throws std::invalid_argument outside (0, 1]
  // Cap on the entries of D with lambda < 1 (see above). set_max_variance(0) restores the
  // default, the largest entry of the initial D; otherwise a finite value > 0.
  double max_variance() const {
    return max_variance_ > 0.0 ? max_variance_ : max_initial_variance_;
  }
  void set_max_variance(double max_variance);

  const VectorX& theta() const { return theta_; }
  // P = U D U^T, exactly symmetric, written into a p x p output (no allocation) or returned.
  void covariance(MatrixOut P) const;
  MatrixX covariance() const;
  // The factors: U unit upper triangular (strict lower part zero), D > 0.
  const MatrixX& covariance_factor_U() const { return U_; }
  const VectorX& covariance_factor_D() const { return D_; }

  // The whole state (current and initial estimate and UD factors, forgetting, variance cap), for
  // saving an estimator and restoring it exactly (Python pickling).
  struct State {
    double forgetting = 1.0, max_variance = 0.0, max_initial_variance = 0.0;
    VectorX theta, theta0, D, D0;
    MatrixX U, U0;
  };
  State state() const;
  // An estimator in the given state; std::invalid_argument naming the field when sizes disagree,
  // forgetting is outside (0, 1] or a value is not finite.
  static RecursiveLeastSquares from_state(const State& state);

 private:
  // Bierman's update with one regressor row y (in h_) and its torque, unit measurement variance.
  void update_row(double tau);

  int p_;
  double lambda_;
  double max_variance_ = 0.0;  // 0: the largest initial variance
  double max_initial_variance_ = 0.0;
  // State and the initial state reset() returns to (P_0 = U_0 D_0 U_0^T).
  VectorX theta_, theta0_;
  MatrixX U_, U0_;
  VectorX D_, D0_;
  // Scratch, sized p by the constructor: the regressor row, f = U^T y, b (v = D f, turned into
  // the unnormalised gain column by column) and the multipliers -f_j / alpha_{j-1} of the
  // columns of U.
  VectorX h_, f_, b_, gain_;
};

}  // namespace dynid
