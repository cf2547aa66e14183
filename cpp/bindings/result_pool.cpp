#include "result_pool.hpp"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace dynid::binding {

namespace {

constexpr std::size_t kAlignment = 64;
constexpr std::size_t kHugePage = std::size_t{2} << 20;

struct Block {
  void* data;
  std::size_t bytes;
};

class Pool {
 public:
  void* take(std::size_t bytes, std::size_t& capacity) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto best = blocks_.end();
      for (auto it = blocks_.begin(); it != blocks_.end(); ++it)
        if (it->bytes >= bytes && it->bytes <= 2 * bytes &&
            (best == blocks_.end() || it->bytes < best->bytes))
          best = it;
      if (best != blocks_.end()) {
        const Block block = *best;
        blocks_.erase(best);
        cached_ -= block.bytes;
        capacity = block.bytes;
        return block.data;
      }
    }
    capacity = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* data = std::aligned_alloc(kHugePage, capacity);
    if (data == nullptr) throw std::bad_alloc();
#if defined(MADV_HUGEPAGE)
    // As NumPy does for large arrays: fewer page faults where transparent huge pages are on
    // "madvise"; a hint only, so its result does not matter.
    madvise(data, capacity, MADV_HUGEPAGE);
#endif
    return data;
  }

  void give_back(void* data, std::size_t capacity) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (capacity > kMaxPooledBytes) {
      std::free(data);
      return;
    }
    blocks_.push_back({data, capacity});
    cached_ += capacity;
    while (cached_ > kMaxPooledBytes || blocks_.size() > kMaxPooledBlocks) {
      std::free(blocks_.front().data);  // the oldest goes first
      cached_ -= blocks_.front().bytes;
      blocks_.erase(blocks_.begin());
    }
  }

  std::pair<std::size_t, std::size_t> state() {
    std::lock_guard<std::mutex> lock(mutex_);
    return {blocks_.size(), cached_};
  }

 private:
  std::mutex mutex_;
  std::vector<Block> blocks_;  // oldest first
  std::size_t cached_ = 0;
};

// Never destroyed: arrays may outlive the module's static objects at interpreter exit.
Pool& pool() {
  static Pool* instance = new Pool;
  return *instance;
}

struct Owner {
  void* data;
  std::size_t capacity;
  std::size_t bytes;
};

}  // namespace

py::array_t<double> new_result_array(const std::vector<py::ssize_t>& shape) {
  std::size_t count = 1;
  for (py::ssize_t d : shape) {
    if (d < 0) throw py::value_error("result shape: negative dimension");
    const auto size = static_cast<std::size_t>(d);
    if (size != 0 && count > std::numeric_limits<std::size_t>::max() / sizeof(double) / size)
      throw std::bad_alloc();  // more bytes than the address space: MemoryError
    count *= size;
  }
  const std::size_t bytes = count * sizeof(double);
  if (bytes < kMinPooledBytes) return py::array_t<double>(shape);
  auto* owner = new Owner{nullptr, 0, bytes};
  try {
    owner->data = pool().take(bytes, owner->capacity);
  } catch (...) {
    delete owner;
    throw;
  }
  auto release = [](void* p) {
    auto* o = static_cast<Owner*>(p);
    pool().give_back(o->data, o->capacity);
    delete o;
  };
  py::capsule base;
  try {
    base = py::capsule(owner, release);
  } catch (...) {
    release(owner);  // the capsule never took ownership
    throw;
  }
  return py::array_t<double>(shape, static_cast<double*>(owner->data), base);
}

std::pair<std::size_t, std::size_t> pooled_blocks() { return pool().state(); }

}  // namespace dynid::binding
