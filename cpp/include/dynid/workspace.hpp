// Every buffer an evaluation needs, sized once for a model. Algorithms write here instead of
// allocating, so a sample costs no heap allocation; give each thread its own Workspace
// (Pinocchio's Model/Data split). Its contents are internal (detail/workspace_buffers.hpp): a
// Workspace is only made, passed to the algorithms and asked for n().
#pragma once

#include "dynid/detail/workspace_buffers.hpp"
#include "dynid/model.hpp"

namespace dynid {

class Workspace;

namespace detail {
// The algorithms' access to the buffers (not API).
WorkspaceBuffers& buffers(Workspace& ws);
}  // namespace detail

class Workspace {
 public:
  // Allocates every buffer for a model of model.n() joints. The Workspace depends on n only: it
  // serves any Model with the same number of joints, and stays valid when the model's
  // parameters, gravity, base or tool change.
  explicit Workspace(const Model& model) : buffers_(model.n()) {}

  // Joints of the models this workspace serves; every algorithm checks it against model.n().
  int n() const { return buffers_.n; }

 private:
  friend detail::WorkspaceBuffers& detail::buffers(Workspace& ws);
  detail::WorkspaceBuffers buffers_;
};

inline detail::WorkspaceBuffers& detail::buffers(Workspace& ws) { return ws.buffers_; }

}  // namespace dynid
