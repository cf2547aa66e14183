// The description of a serial arm: its name, DH table, gravity, base and tool transforms, joint
// limits, standard inertial parameters (docs/conventions.md) and drive terms. This is the whole
// robot: the Python Robot keeps no state of its own, and python/dynid/robot_fields.py lists these
// fields once for copies, pickles, equality, model and result files and `dynid info`. Every
// per-call buffer lives in a Workspace, so one Model serves many threads.
//
// Mutability and threads. A Model is a value: it is built from a DH table and completed with the
// setters below (set_link, set_parameters, set_rotor_inertia, ...), each of which checks its
// argument (std::invalid_argument naming it) and recomputes the derived quantities. The number
// of joints never changes. The algorithms take it by const reference and only read it, so any
// number of threads may evaluate the same Model at once, each with its own Workspace. A setter
// is a write: calling one while another thread evaluates the same Model is a data race (nothing
// inside is locked or atomic). To change a model that other threads are using, change a copy and
// hand the copy over between calls (the Python binding does exactly this: a setter replaces a
// std::shared_ptr<const Model>, so a batch already running keeps the model it started with). A
// Workspace depends only on n() and stays valid across every setter.
#pragma once

#include <string>
#include <vector>

#include "dynid/detail/joint_geometry.hpp"
#include "dynid/rigid_body.hpp"
#include "dynid/types.hpp"

namespace dynid {

enum class Convention { Standard, Modified };
enum class JointType { Revolute, Prismatic };

// One DH row. Standard: A_{i-1,i} = Rz(theta) Tz(d) Tx(a) Rx(alpha).
// Modified: the row holds (a_{i-1}, alpha_{i-1}, d_i, theta_i), A = Rx(alpha) Tx(a) Rz(theta)
// Tz(d). The joint variable adds to theta (revolute) or d (prismatic).
struct DHRow {
  double a = 0.0;
  double alpha = 0.0;
  double d = 0.0;
  double theta = 0.0;
  JointType type = JointType::Revolute;
};

class Model {
 public:
  Model(std::vector<DHRow> rows, Convention convention,
        const Vector3& gravity = Vector3(0, 0, -9.81), const Matrix4& base = Matrix4::Identity(),
        const Matrix4& tool = Matrix4::Identity());

  int n() const { return n_; }
  Convention convention() const { return convention_; }
  const std::vector<DHRow>& dh() const { return rows_; }
  const Vector3& gravity() const { return gravity_; }
  const Matrix4& base() const { return base_; }
  const Matrix4& tool() const { return tool_; }
  void set_gravity(const Vector3& gravity);
  void set_base(const Matrix4& base);
  void set_tool(const Matrix4& tool);

  // A label for printing ("<n>-dof arm" by default). Any text.
  const std::string& name() const { return name_; }
  void set_name(std::string name);

  // One name per joint, "q1".."qn" by default (a URDF's joint names through Robot.from_urdf):
  // what a log that names its joints (a sensor_msgs/JointState) is matched against. Data for
  // the user of the model; no algorithm reads them. set_joint_names throws
  // std::invalid_argument naming `joint_names` unless there are n names, none empty, no two
  // alike.
  const std::vector<std::string>& joint_names() const { return joint_names_; }
  void set_joint_names(std::vector<std::string> joint_names);

  // One name per link (the body moved by joint i), "link1".."linkn" by default (a URDF's link
  // names through Robot.from_urdf): what the URDF and MJCF writers call the bodies. Same rules
  // as joint_names (std::invalid_argument naming `link_names`).
  const std::vector<std::string>& link_names() const { return link_names_; }
  void set_link_names(std::vector<std::string> link_names);

  // Joint limits, n x 2 rows [lower, upper] (rad or m): (-pi, pi) for a revolute and (-1, 1) m
  // for a prismatic joint by default. Data for the user of the model (random configurations,
  // excitation, bounds); no algorithm reads them. set_joint_limits throws std::invalid_argument
  // naming `qlim` unless the matrix is n x 2, finite and every lower limit is below its upper.
  const MatrixX& joint_limits() const { return qlim_; }
  void set_joint_limits(const Eigen::Ref<const MatrixX>& qlim);

  // Velocity and effort limits, n each (rad/s or m/s; N m or N): a URDF's <limit velocity
  // effort>, written back into URDF and MJCF files. +infinity (not known, not limited) by
  // default, so a model without them never claims a limit of 0. Data for the user of the model
  // (excitation bounds, exported files); no algorithm reads them. The setters throw
  // std::invalid_argument naming `velocity_limits` / `effort_limits` unless n values > 0
  // (+infinity allowed, NaN not).
  const VectorX& velocity_limits() const { return velocity_limits_; }
  const VectorX& effort_limits() const { return effort_limits_; }
  void set_velocity_limits(const VectorIn& limits);
  void set_effort_limits(const VectorIn& limits);

  // Standard parameters, n x 10, row i about the origin of DH frame i (standard order
  // (docs/conventions.md)).
  const MatrixX& parameters() const { return parameters_; }
  void set_parameters(const Eigen::Ref<const MatrixX>& parameters);
  void set_link(int i, const RigidBodyParameters& body);
  // Why link i (0-based) cannot exist as a rigid body ("" when it can): its standard parameters
  // checked by physical_inconsistency (rigid_body.hpp). std::invalid_argument for i out of range.
  std::string link_inconsistency(int i) const;

  // Drive terms (n each): rotor inertia reflected to the link side, viscous and Coulomb friction.
  // With a transmission T (below) they are per MOTOR: motor k spins at theta_dot_k = (T qd)_k
  // (after its gear) and the drive torque is T^T (Ia . T qdd + Fv . T qd + Fs . sign(T qd)).
  const VectorX& rotor_inertia() const { return Ia_; }
  const VectorX& viscous_friction() const { return Fv_; }
  const VectorX& coulomb_friction() const { return Fs_; }
  void set_rotor_inertia(const VectorIn& Ia);
  void set_viscous_friction(const VectorIn& Fv);
  void set_coulomb_friction(const VectorIn& Fs);

  // Transmission coupling (notes p. 11-13): motor velocities after the gears theta_dot = T qd,
  // T a constant invertible n x n matrix (coupled wrists). Identity by default: the decoupled
  // model, evaluated by the same code as before T existed. set_transmission throws
  // std::invalid_argument naming `transmission` unless T is n x n, finite and well conditioned
  // (sigma_min / sigma_max > kTransmissionMinRcond); an exact identity restores the decoupled
  // path. The rotor kinetic energy 1/2 theta_dot^T diag(Ia) theta_dot makes the drive part of
  // M(q) T^T diag(Ia) T (constant: no Coriolis term) and the motor-side friction reaches the
  // joints as T^T tau_F (virtual work).
  static constexpr double kTransmissionMinRcond = 1e-12;
  const MatrixX& transmission() const { return T_; }
  bool transmission_is_identity() const { return transmission_identity_; }
  void set_transmission(const Eigen::Ref<const MatrixX>& T);
  // T^T diag(Ia) T and T^T diag(Fv) T (kept up to date by the setters; read by
  // detail/drive_terms.hpp for a coupled transmission).
  const MatrixX& drive_inertia() const { return drive_inertia_; }
  const MatrixX& drive_damping() const { return drive_damping_; }

  // How a motor-side recording maps to the joints (issue 20; docs/data.md, "Motor-side logs"):
  // motor angles theta = R (q + joint_offsets) with R = diag(gear_ratios) T, so that
  // q = R^-1 theta - joint_offsets and tau = R^T tau_m (virtual work, as for T above). Gear
  // ratios are ones and offsets zeros by default. Data for the user of the model, like qlim: no
  // algorithm reads them (the drive terms above are already in joint units). set_gear_ratios
  // throws std::invalid_argument naming `gear_ratios` unless it holds n finite non-zero values
  // (R must be invertible); set_joint_offsets naming `joint_offsets` unless n finite values.
  const VectorX& gear_ratios() const { return gear_ratios_; }
  const VectorX& joint_offsets() const { return joint_offsets_; }
  void set_gear_ratios(const VectorIn& gear_ratios);
  void set_joint_offsets(const VectorIn& joint_offsets);

  // ---- derived quantities: the algorithms' view (unchecked index; its types are in
  // dynid::detail and may change between releases) ----
  const detail::JointGeometry& joint(int i) const { return joints_[i]; }
  // Link i's parameters about the origin of its joint frame J_i.
  const RigidBodyParameters& body(int i) const { return bodies_[i]; }
  // DH frame i = J_i * link_offset(i): identity for modified DH, Tx(a_i) Rx(alpha_i) for standard.
  const detail::LinkOffset& link_offset(int i) const { return offsets_[i]; }
  // Gravity expressed in frame 0 (the base frame).
  const Vector3& gravity_base() const { return gravity_base_; }
  // Frame J_n -> tool: link_offset(n-1) * tool.
  const Matrix4& flange_to_tool() const { return flange_to_tool_; }

 private:
  void update_bodies();
  void update_frames();
  void update_drive_matrices();

  int n_;
  Convention convention_;
  std::vector<DHRow> rows_;
  Vector3 gravity_;
  Matrix4 base_, tool_;
  std::string name_;
  std::vector<std::string> joint_names_, link_names_;
  MatrixX qlim_;
  VectorX velocity_limits_, effort_limits_;
  MatrixX parameters_;
  VectorX Ia_, Fv_, Fs_;
  MatrixX T_, drive_inertia_, drive_damping_;
  bool transmission_identity_ = true;
  VectorX gear_ratios_, joint_offsets_;

  std::vector<detail::JointGeometry> joints_;
  std::vector<RigidBodyParameters> bodies_;
  std::vector<detail::LinkOffset> offsets_;
  Vector3 gravity_base_;
  Matrix4 flange_to_tool_;
};

}  // namespace dynid
