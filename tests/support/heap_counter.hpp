// Counts every heap allocation of the process: malloc, calloc, realloc, memalign, aligned_alloc,
// posix_memalign are interposed (the executable's definitions win over glibc's for every caller,
// libstdc++'s operator new included) and forwarded to glibc's __libc_* entry points. Include it
// in exactly one translation unit of a test executable. Not with AddressSanitizer, which owns
// malloc itself: HeapCounter::available() is false there.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdlib>
#if defined(__x86_64__) || defined(__i386__)
// clang's <mm_malloc.h> (reached through Eigen's SSE headers) re-declares posix_memalign without
// noexcept; seen before the definition below it is accepted, seen after it is an error.
#include <mm_malloc.h>
#endif

// AddressSanitizer: gcc defines __SANITIZE_ADDRESS__, clang answers __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define GFINS_HEAP_COUNTER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GFINS_HEAP_COUNTER_ASAN 1
#endif
#endif

namespace gfins::testing {
inline std::atomic<long> g_heap_calls{0};
struct HeapCounter {
  static long calls() { return g_heap_calls.load(std::memory_order_relaxed); }
#if defined(GFINS_HEAP_COUNTER_ASAN)
  static constexpr bool available() { return false; }
#else
  static constexpr bool available() { return true; }
#endif
};
}  // namespace gfins::testing

#if !defined(GFINS_HEAP_COUNTER_ASAN)
extern "C" {
void* __libc_malloc(std::size_t) noexcept;
void* __libc_calloc(std::size_t, std::size_t) noexcept;
void* __libc_realloc(void*, std::size_t) noexcept;
void* __libc_memalign(std::size_t, std::size_t) noexcept;

void* malloc(std::size_t n) noexcept {
  gfins::testing::g_heap_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
  gfins::testing::g_heap_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) noexcept {
  gfins::testing::g_heap_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void* memalign(std::size_t align, std::size_t n) noexcept {
  gfins::testing::g_heap_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(align, n);
}
void* aligned_alloc(std::size_t align, std::size_t n) noexcept {
  gfins::testing::g_heap_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(align, n);
}
int posix_memalign(void** out, std::size_t align, std::size_t n) noexcept {
  gfins::testing::g_heap_calls.fetch_add(1, std::memory_order_relaxed);
  void* p = __libc_memalign(align, n);
  if (p == nullptr) return 12;  // ENOMEM
  *out = p;
  return 0;
}
}
#endif

namespace gfins::testing {

/// The heap calls of the whole process since it was made: the window of a no-heap check
/// (nav_core_no_malloc_check, calibration_no_malloc_check, firmware_no_alloc_check).
class HeapWindow {
 public:
  long allocations() const { return HeapCounter::calls() - start_; }

 private:
  long start_ = HeapCounter::calls();
};

}  // namespace gfins::testing
