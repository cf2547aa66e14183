// Memory for large batch results, recycled. A fresh block of tens of MB costs the kernel's page
// faults and page clearing on first touch: for a 10^4-sample regressor (39 MB) that was 0.26 of
// its 0.69 µs per state (issue 13). Results of at least kMinPooledBytes are therefore allocated
// from blocks that earlier results gave back when NumPy freed them; a caller that computes
// batch after batch (chunks of a log, an optimisation loop) then writes into memory that is
// already mapped, as with `out=`. (Python's tracemalloc does not see these blocks.)
#pragma once

#include <pybind11/numpy.h>

#include <cstddef>
#include <vector>

namespace dynid::binding {

namespace py = pybind11;

// Smaller results come from NumPy's allocator (glibc keeps such blocks mapped between calls).
constexpr std::size_t kMinPooledBytes = std::size_t{4} << 20;
// At most this many bytes in at most kMaxPooledBlocks blocks wait for reuse; a block larger
// than the limit is returned to the system when its array dies.
constexpr std::size_t kMaxPooledBytes = std::size_t{256} << 20;
constexpr std::size_t kMaxPooledBlocks = 4;

// A new C-contiguous float64 array of `shape`, uninitialised (the caller writes every element),
// its memory from the pool when large (a block of at least the size and at most twice it).
// MemoryError when it cannot be allocated.
py::array_t<double> new_result_array(const std::vector<py::ssize_t>& shape);

// Blocks waiting for reuse and their bytes (tests).
std::pair<std::size_t, std::size_t> pooled_blocks();

}  // namespace dynid::binding
