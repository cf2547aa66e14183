// Internal (dynid::detail, not API): the size checks every public algorithm runs first
// (docs/cpp.md, "Argument checks"), in the manner of Pinocchio's PINOCCHIO_CHECK_ARGUMENT_SIZE. A
// check is one integer comparison; the message is built only on failure, in a function kept out of
// line, so the checks cost nothing measurable on the hot path. The message names the argument
// first, as the Python errors do: "qd: expected 7 entries (one per joint), got 3 (in dynid::rnea)".
#pragma once

#include <Eigen/Core>

#include "dynid/workspace.hpp"

namespace dynid::detail {

[[noreturn]] void throw_wrong_size(const char* function, const char* argument, Eigen::Index size,
                                   Eigen::Index expected, const char* what);
[[noreturn]] void throw_wrong_shape(const char* function, const char* argument, Eigen::Index rows,
                                    Eigen::Index cols, Eigen::Index expected_rows,
                                    Eigen::Index expected_cols);
[[noreturn]] void throw_wrong_workspace(const char* function, int workspace_joints,
                                        int model_joints);

// A vector argument of `expected` entries; `what` says what they are ("one per joint").
inline void check_size(const char* function, const char* argument, Eigen::Index size,
                       Eigen::Index expected, const char* what) {
  if (size != expected) throw_wrong_size(function, argument, size, expected, what);
}

// A matrix argument of expected_rows x expected_cols.
inline void check_shape(const char* function, const char* argument, Eigen::Index rows,
                        Eigen::Index cols, Eigen::Index expected_rows, Eigen::Index expected_cols) {
  if (rows != expected_rows || cols != expected_cols)
    throw_wrong_shape(function, argument, rows, cols, expected_rows, expected_cols);
}

// The workspace must have been made for a model with as many joints; returns its buffers.
inline WorkspaceBuffers& checked_buffers(const char* function, const Model& model,
                                         Workspace& workspace) {
  if (workspace.n() != model.n()) throw_wrong_workspace(function, workspace.n(), model.n());
  return buffers(workspace);
}

}  // namespace dynid::detail

// Inside a public algorithm: the argument's name is its spelling, the function is __func__.
#define DYNID_CHECK_JOINT_VECTOR(argument, model) \
  ::dynid::detail::check_size(__func__, #argument, (argument).size(), (model).n(), "one per joint")
#define DYNID_CHECK_SHAPE(argument, expected_rows, expected_cols)                         \
  ::dynid::detail::check_shape(__func__, #argument, (argument).rows(), (argument).cols(), \
                               (expected_rows), (expected_cols))
#define DYNID_CHECKED_BUFFERS(model, workspace) \
  ::dynid::detail::checked_buffers(__func__, (model), (workspace))
