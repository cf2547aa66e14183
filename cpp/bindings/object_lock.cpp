#include "object_lock.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>

#include <pybind11/pybind11.h>

namespace dynid::binding {
namespace {

// A fixed table of locks chosen by the object's address: no per-object state to add to the
// bound classes (RecursiveLeastSquares is bound as the core class itself). Two objects that share
// a lock only wait for each other, never deadlock: a call holds one lock at a time.
constexpr std::size_t kLocks = 64;
std::array<std::mutex, kLocks> locks;

}  // namespace

std::unique_lock<std::mutex> lock_object(const void* object) {
  const std::size_t slot = std::hash<const void*>{}(object) % kLocks;
  std::unique_lock<std::mutex> guard(locks[slot], std::try_to_lock);
  if (!guard.owns_lock()) {
    pybind11::gil_scoped_release release;  // the holder may need the GIL to finish
    guard.lock();
  }
  return guard;
}

}  // namespace dynid::binding
