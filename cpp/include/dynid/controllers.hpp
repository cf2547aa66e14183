// Built-in joint-space control laws for the Simulator (notes, "Use of the dynamic model"). Each
// controller reads the desired trajectory sampled at the control instants and, where it uses a
// model, evaluates its own Model (possibly not the plant's, to show the effect of a mismatch) in
// its own Workspace: a command allocates nothing. A controller keeps references to its Model and
// to the reference arrays: both must outlive it.
#pragma once

#include "dynid/model.hpp"
#include "dynid/simulator.hpp"
#include "dynid/workspace.hpp"

namespace dynid {

// Desired q_d, qd_d, qdd_d at the control instants t_k = k dt: row-major (samples x n) views of
// memory the caller keeps alive while the controller is used.
struct ReferenceTrajectory {
  const double* q = nullptr;
  const double* qd = nullptr;
  const double* qdd = nullptr;
  int samples = 0;
  int n = 0;
};

// tau = Kp (q_d - q) + Kd (qd_d - qd).
class PDController : public Controller {
 public:
  // Throws std::invalid_argument naming kp, kd or the reference when the sizes do not match.
  PDController(const VectorIn& kp, const VectorIn& kd, const ReferenceTrajectory& reference);
  void command(int k, double t, const VectorIn& q, const VectorIn& qd, VectorOut tau) override;

 protected:
  // e = q_d - q, ed = qd_d - qd at sample k into e_, ed_, after checking the sizes of q, qd and
  // tau (std::invalid_argument naming them); throws std::out_of_range past the reference's end.
  void errors(int k, const VectorIn& q, const VectorIn& qd, Eigen::Index tau_size);

  VectorX kp_, kd_, e_, ed_;
  ReferenceTrajectory reference_;
};

// PD with gravity compensation (Takegaki-Arimoto): tau = Kp e + Kd ed + g_model(q). For a constant
// q_d and an exact g the energy V = T + 1/2 e^T Kp e never increases and q -> q_d (LaSalle).
class PDGravityController : public PDController {
 public:
  PDGravityController(const Model& model, const VectorIn& kp, const VectorIn& kd,
                      const ReferenceTrajectory& reference);
  void command(int k, double t, const VectorIn& q, const VectorIn& qd, VectorOut tau) override;

 private:
  const Model& model_;
  Workspace ws_;
  VectorX g_;
};

// Computed torque (feedback linearisation): tau = M(q) (qdd_d + Kd ed + Kp e) + c(q, qd) + g(q) +
// F(qd), all of the controller's model, as one Newton-Euler call (its friction with sign(), as a
// model-based controller would compensate it). With the plant's exact model the error obeys
// edd + Kd ed + Kp e = 0 up to the zero-order hold.
class ComputedTorqueController : public PDController {
 public:
  ComputedTorqueController(const Model& model, const VectorIn& kp, const VectorIn& kd,
                           const ReferenceTrajectory& reference);
  void command(int k, double t, const VectorIn& q, const VectorIn& qd, VectorOut tau) override;

 private:
  const Model& model_;
  Workspace ws_;
  VectorX v_;
};

}  // namespace dynid
