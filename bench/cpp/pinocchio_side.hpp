// The Pinocchio side of the benchmark. Declared without Pinocchio's headers: they are heavy
// (minutes to compile), so they live in pinocchio_side.cpp alone and a change to dynid does not
// recompile them. Each method evaluates state k into Pinocchio's Data and returns one number of
// the result; it is an out-of-line call, as dynid's functions are (compiled in a static library).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>

#include "bench_inputs.hpp"

namespace bench {

class PinocchioSide {
 public:
  PinocchioSide(const ModelFile& arm, const States& states);
  ~PinocchioSide();

  double rnea(int k);
  double crba(int k);  // full symmetric M: the lower triangle copied from the upper, timed
  double gravity(int k);
  double coriolis_matrix(int k);
  double regressor(int k);
  double forward_dynamics(int k);  // aba on (q, qd, tau)
  double rnea_derivatives(int k);  // computeRNEADerivatives (dtau/dq, dtau/dv, dtau/da)

  // The last results (Pinocchio's Data members).
  const Eigen::VectorXd& tau() const;
  const Eigen::MatrixXd& M() const;
  const Eigen::VectorXd& g() const;
  const Eigen::MatrixXd& C() const;
  const Eigen::MatrixXd& Y() const;
  const Eigen::VectorXd& qdd() const;
  // Pinocchio stores the derivatives row-major (Data::RowMatrixXs).
  using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMatrixXd& dtau_dq() const;
  const RowMatrixXd& dtau_dqd() const;

  // blockdiag(T_1..T_n), T_i mapping link i's dynid parameters (standard order
  // (docs/conventions.md), about DH frame i) to Pinocchio's (its order, about joint frame i):
  // Y_dynid == Y_pinocchio * regressor_map().
  Eigen::MatrixXd regressor_map() const;

  static std::string version();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bench
