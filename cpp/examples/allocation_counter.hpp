// Allocation counting for the zero-allocation proofs (cpp/examples/realtime_loop.cpp and
// tests/cpp/test_rls_no_allocation.cpp). Include it in exactly ONE translation unit of a program:
// it replaces the global allocation functions. Set `counting = true` around the code under test
// and read `allocations`.
#pragma once

#include <cerrno>
#include <cstdlib>
#include <new>

// ------------------------------------------------------------------------ allocation counting
//
// Every global operator new / new[] (plain, nothrow, aligned, aligned nothrow) is replaced, and
// every operator delete form with it. Eigen does not use operator new for its dynamic matrices: it
// calls std::malloc (aligned_malloc). On glibc, malloc and its relatives are therefore replaced
// too, forwarding to glibc's own __libc_* entry points, so that an Eigen temporary in the loop
// would be counted as well. The program is single-threaded, so plain variables suffice.

namespace {
bool counting = false;
long allocations = 0;
inline void count() {
  if (counting) ++allocations;
}
}  // namespace

// Under AddressSanitizer (tests/cpp built with -fsanitize=address) the allocation functions
// belong to the sanitizer's runtime and must not be replaced; its allocator calls a hook for
// every allocation instead (malloc, operator new, aligned forms alike), which counts the same.
#if defined(__SANITIZE_ADDRESS__)
#define DYNID_COUNT_WITH_SANITIZER_HOOK 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DYNID_COUNT_WITH_SANITIZER_HOOK 1
#endif
#endif

#if defined(DYNID_COUNT_WITH_SANITIZER_HOOK)
// From <sanitizer/allocator_interface.h>, declared here: not every compiler installs that header.
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*,
                                                                             std::size_t),
                                                         void (*free_hook)(const volatile void*));

namespace {
void count_allocation_hook(const volatile void*, std::size_t) { count(); }
void ignore_free_hook(const volatile void*) {}
const int allocation_hook_installed =
    __sanitizer_install_malloc_and_free_hooks(count_allocation_hook, ignore_free_hook);
}  // namespace

#else  // replace the allocation functions

#if defined(__GLIBC__)
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t size) {
  count();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  count();
  return __libc_calloc(n, size);
}
void* realloc(void* ptr, std::size_t size) {
  count();
  return __libc_realloc(ptr, size);
}
void* memalign(std::size_t alignment, std::size_t size) {
  count();
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  count();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  count();
  *out = __libc_memalign(alignment, size);
  return *out ? 0 : ENOMEM;
}
void free(void* ptr) { __libc_free(ptr); }
}
#define RAW_MALLOC(size) __libc_malloc(size)
#define RAW_ALIGNED(alignment, size) __libc_memalign(alignment, size)
#define RAW_FREE(ptr) __libc_free(ptr)
#else
#define RAW_MALLOC(size) std::malloc(size)
#define RAW_ALIGNED(alignment, size) \
  std::aligned_alloc(alignment, ((size) + (alignment) - 1) / (alignment) * (alignment))
#define RAW_FREE(ptr) std::free(ptr)
#endif

void* operator new(std::size_t size) {
  count();
  if (void* p = RAW_MALLOC(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  count();
  return RAW_MALLOC(size ? size : 1);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return operator new(size, tag);
}
void* operator new(std::size_t size, std::align_val_t alignment) {
  count();
  if (void* p = RAW_ALIGNED(static_cast<std::size_t>(alignment), size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  return operator new(size, alignment);
}
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  count();
  return RAW_ALIGNED(static_cast<std::size_t>(alignment), size ? size : 1);
}
void* operator new[](std::size_t size, std::align_val_t alignment,
                     const std::nothrow_t& tag) noexcept {
  return operator new(size, alignment, tag);
}
void operator delete(void* p) noexcept { RAW_FREE(p); }
void operator delete[](void* p) noexcept { RAW_FREE(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { RAW_FREE(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { RAW_FREE(p); }
void operator delete(void* p, std::size_t) noexcept { RAW_FREE(p); }
void operator delete[](void* p, std::size_t) noexcept { RAW_FREE(p); }
void operator delete(void* p, std::align_val_t) noexcept { RAW_FREE(p); }
void operator delete[](void* p, std::align_val_t) noexcept { RAW_FREE(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { RAW_FREE(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { RAW_FREE(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { RAW_FREE(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { RAW_FREE(p); }

#endif  // DYNID_COUNT_WITH_SANITIZER_HOOK
