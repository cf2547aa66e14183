// Recursive least squares in UD form (equations in recursive_least_squares.hpp): Bierman's scalar
// measurement update, applied to the rows of a block after the forgetting factor has scaled D.
#include "dynid/recursive_least_squares.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace dynid {
namespace {

// A value for an error message: "1e-09", not std::to_string's "0.000000".
std::string format(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", value);
  return text;
}

void check_forgetting(double forgetting) {
  if (!(forgetting > 0.0 && forgetting <= 1.0))  // also rejects NaN
    throw std::invalid_argument("forgetting: expected a value in (0, 1], got " +
                                format(forgetting));
}

int checked_dimension(int p) {
  if (p < 1)
    throw std::invalid_argument("p: expected at least 1 parameter, got " + std::to_string(p));
  return p;
}

// Smallest D entry kept: rounding must not turn a variance into 0 (P would lose positive
// definiteness and that direction would never be updated again).
constexpr double kMinVariance = std::numeric_limits<double>::min();

}  // namespace

RecursiveLeastSquares::RecursiveLeastSquares(int p, double forgetting, double initial_covariance)
    : p_(checked_dimension(p)), lambda_(forgetting) {
  check_forgetting(forgetting);
  for (VectorX* v : {&theta_, &theta0_, &D_, &D0_, &h_, &f_, &b_, &gain_}) v->setZero(p);
  U_.setIdentity(p, p);
  U0_.setIdentity(p, p);
  reset(initial_covariance);
}

RecursiveLeastSquares::RecursiveLeastSquares(const VectorIn& theta0, const MatrixIn& P0,
                                             double forgetting)
    : RecursiveLeastSquares(static_cast<int>(theta0.size()), forgetting) {
  reset(theta0, P0);
}

void RecursiveLeastSquares::reset() {
  theta_ = theta0_;
  U_ = U0_;
  D_ = D0_;
}

void RecursiveLeastSquares::reset(double initial_covariance) {
  if (!(std::isfinite(initial_covariance) && initial_covariance > 0.0))
    throw std::invalid_argument("initial_covariance: expected a finite value > 0, got " +
                                format(initial_covariance));
  theta0_.setZero();
  U0_.setIdentity();
  D0_.setConstant(initial_covariance);
  max_initial_variance_ = initial_covariance;
  reset();
}

void RecursiveLeastSquares::reset(const VectorIn& theta0, const MatrixIn& P0) {
  if (theta0.size() != p_)
    throw std::invalid_argument("theta0: expected " + std::to_string(p_) + " entries, got " +
                                std::to_string(theta0.size()));
  if (P0.rows() != p_ || P0.cols() != p_)
    throw std::invalid_argument("P0: expected a " + std::to_string(p_) + " x " +
                                std::to_string(p_) + " matrix, got " + std::to_string(P0.rows()) +
                                " x " + std::to_string(P0.cols()));
  if (!theta0.allFinite()) throw std::invalid_argument("theta0: contains NaN or inf");
  if (!P0.allFinite()) throw std::invalid_argument("P0: contains NaN or inf");
  const double scale = P0.cwiseAbs().maxCoeff();
  if (((P0 - P0.transpose()).cwiseAbs().array() > 1e-10 * scale).any())
    throw std::invalid_argument("P0: expected a symmetric matrix");

  // P0 = U D U^T from the last column back (Bierman 1977, ch. III), reading the upper triangle;
  // into temporaries, so that a failure leaves the estimator as it was.
  MatrixX U = MatrixX::Identity(p_, p_);
  VectorX D(p_);
  for (int j = p_ - 1; j >= 0; --j) {
    const int tail = p_ - 1 - j;
    const auto d_tail = D.tail(tail).transpose().array();  // a row, like the rows of U below
    D[j] = P0(j, j) - (U.row(j).tail(tail).array().square() * d_tail).sum();
    if (!(D[j] > 1e-14 * scale))
      throw std::invalid_argument("P0: expected a positive definite matrix (UD pivot " +
                                  std::to_string(j) + " is " + format(D[j]) + ")");
    for (int i = 0; i < j; ++i) {
      const double s = (U.row(i).tail(tail).array() * U.row(j).tail(tail).array() * d_tail).sum();
      U(i, j) = (P0(i, j) - s) / D[j];
    }
  }
  theta0_ = theta0;
  U0_ = U;
  D0_ = D;
  max_initial_variance_ = D.maxCoeff();
  reset();
}

void RecursiveLeastSquares::set_forgetting(double forgetting) {
  check_forgetting(forgetting);
  lambda_ = forgetting;
}

void RecursiveLeastSquares::set_max_variance(double max_variance) {
  if (!(std::isfinite(max_variance) && max_variance >= 0.0))
    throw std::invalid_argument(
        "max_variance: expected a finite value > 0 (or 0 for the default), got " +
        format(max_variance));
  max_variance_ = max_variance;
}

void RecursiveLeastSquares::update(const MatrixIn& Y_k, const VectorIn& tau_k) {
  if (Y_k.cols() != p_ || Y_k.rows() < 1)
    throw std::invalid_argument("Y_k: expected an m x " + std::to_string(p_) +
                                " block with m >= 1, got " + std::to_string(Y_k.rows()) + " x " +
                                std::to_string(Y_k.cols()));
  if (tau_k.size() != Y_k.rows())
    throw std::invalid_argument("tau_k: expected " + std::to_string(Y_k.rows()) +
                                " torques (one per row of Y_k), got " +
                                std::to_string(tau_k.size()));
  // P / lambda, capped against windup (header); then unit measurement variance per row.
  if (lambda_ != 1.0) D_ = (D_ / lambda_).cwiseMin(max_variance());
  for (Eigen::Index r = 0; r < Y_k.rows(); ++r) {
    h_ = Y_k.row(r).transpose();  // contiguous copy: the products below then need no temporary
    update_row(tau_k[r]);
  }
}

// Bierman's UD update for one row y = h_, measurement variance 1 (Bierman 1977, ch. V; Grewal &
// Andrews, "Kalman Filtering", 4th ed., sec. 7.5):
//   f = U^T y,  v = D f,  alpha_0 = 1,  alpha_j = alpha_{j-1} + f_j v_j,
//   D_j <- D_j alpha_{j-1} / alpha_j,
//   for i < j:  U_ij <- U_ij - b_i f_j / alpha_{j-1},  b_i <- b_i + U_ij(old) v_j   (b = v first),
//   K = b / alpha_p,  theta <- theta + K (tau - y^T theta).
// alpha_j >= 1 and each D_j is multiplied by alpha_{j-1} / alpha_j in (0, 1], so D stays > 0.
void RecursiveLeastSquares::update_row(double tau) {
  const double residual = tau - h_.dot(theta_);
  f_.noalias() = U_.triangularView<Eigen::UnitUpper>().transpose() * h_;
  b_ = D_.cwiseProduct(f_);
  // alpha_j depends on f and v only: D and the column multipliers first, in one pass with one
  // division per j, off the chain of additions.
  double alpha = 1.0;
  double inverse_prev = 1.0;  // 1 / alpha_{j-1}
  for (int j = 0; j < p_; ++j) {
    const double alpha_prev = alpha;
    alpha += f_[j] * b_[j];
    const double inverse = 1.0 / alpha;
    D_[j] = std::max(D_[j] * (alpha_prev * inverse), kMinVariance);
    gain_[j] = -f_[j] * inverse_prev;
    inverse_prev = inverse;
  }
  // Column j of U and the entries i < j of b, both from their old values, in one pass; restrict
  // pointers let the compiler vectorise it without aliasing checks.
  double* __restrict b = b_.data();
  for (int j = 1; j < p_; ++j) {
    double* __restrict u = U_.col(j).data();
    const double multiplier = gain_[j];
    const double v_j = b[j];  // columns < j leave b_j alone: it is still v_j
    for (int i = 0; i < j; ++i) {
      const double u_old = u[i];
      u[i] = u_old + multiplier * b[i];
      b[i] += v_j * u_old;
    }
  }
  theta_ += (residual * inverse_prev) * b_;  // inverse_prev = 1 / alpha_p now
}

void RecursiveLeastSquares::covariance(MatrixOut P) const {
  if (P.rows() != p_ || P.cols() != p_)
    throw std::invalid_argument("P: expected a " + std::to_string(p_) + " x " + std::to_string(p_) +
                                " output");
  // P_ij = sum_{k >= max(i, j)} U_ik D_k U_jk, once for i <= j and mirrored: exactly symmetric.
  for (int j = 0; j < p_; ++j) {
    for (int i = 0; i <= j; ++i) {
      double s = 0.0;
      for (int k = j; k < p_; ++k) s += U_(i, k) * D_[k] * U_(j, k);
      P(i, j) = s;
      P(j, i) = s;
    }
  }
}

MatrixX RecursiveLeastSquares::covariance() const {
  MatrixX P(p_, p_);
  covariance(P);
  return P;
}

RecursiveLeastSquares::State RecursiveLeastSquares::state() const {
  return State{lambda_, max_variance_, max_initial_variance_, theta_, theta0_, D_, D0_, U_, U0_};
}

RecursiveLeastSquares RecursiveLeastSquares::from_state(const State& state) {
  const auto p = state.theta.size();
  RecursiveLeastSquares rls(static_cast<int>(p), state.forgetting);
  const auto check = [p](bool ok, const char* name) {
    if (!ok)
      throw std::invalid_argument(std::string("state.") + name + ": expected " + std::to_string(p) +
                                  " entries (p x p for U), finite");
  };
  check(state.theta0.size() == p && state.theta0.allFinite(), "theta0");
  check(state.theta.allFinite(), "theta");
  check(state.D.size() == p && state.D.allFinite(), "D");
  check(state.D0.size() == p && state.D0.allFinite(), "D0");
  check(state.U.rows() == p && state.U.cols() == p && state.U.allFinite(), "U");
  check(state.U0.rows() == p && state.U0.cols() == p && state.U0.allFinite(), "U0");
  check(std::isfinite(state.max_variance) && state.max_variance >= 0.0, "max_variance");
  check(std::isfinite(state.max_initial_variance) && state.max_initial_variance >= 0.0,
        "max_initial_variance");
  rls.max_variance_ = state.max_variance;
  rls.max_initial_variance_ = state.max_initial_variance;
  rls.theta_ = state.theta;
  rls.theta0_ = state.theta0;
  rls.D_ = state.D;
  rls.D0_ = state.D0;
  rls.U_ = state.U;
  rls.U0_ = state.U0;
  return rls;
}

}  // namespace dynid
