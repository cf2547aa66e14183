#include "dynid/detail/argument_checks.hpp"

#include <stdexcept>
#include <string>

namespace dynid::detail {

void throw_wrong_size(const char* function, const char* argument, Eigen::Index size,
                      Eigen::Index expected, const char* what) {
  throw std::invalid_argument(std::string(argument) + ": expected " + std::to_string(expected) +
                              " entries (" + what + "), got " + std::to_string(size) +
                              " (in dynid::" + function + ")");
}

void throw_wrong_shape(const char* function, const char* argument, Eigen::Index rows,
                       Eigen::Index cols, Eigen::Index expected_rows, Eigen::Index expected_cols) {
  throw std::invalid_argument(
      std::string(argument) + ": expected a " + std::to_string(expected_rows) + " x " +
      std::to_string(expected_cols) + " matrix, got " + std::to_string(rows) + " x " +
      std::to_string(cols) + " (in dynid::" + function + ")");
}

void throw_wrong_workspace(const char* function, int workspace_joints, int model_joints) {
  throw std::invalid_argument("ws: expected a Workspace made for a model with " +
                              std::to_string(model_joints) + " joints, got one for " +
                              std::to_string(workspace_joints) + " (in dynid::" + function + ")");
}

}  // namespace dynid::detail
