// Allocation detector for the no-heap tests. Include it in exactly ONE translation unit of a test
// executable: it replaces the global operator new/delete with counting versions. Together with
// EIGEN_RUNTIME_NO_MALLOC (and -UNDEBUG, since Eigen's check is an eigen_assert) on the whole
// executable, NoAllocWindow makes both Eigen and any other heap use visible.
#pragma once

#ifndef EIGEN_RUNTIME_NO_MALLOC
#error "compile the no-heap tests with EIGEN_RUNTIME_NO_MALLOC"
#endif

#include <Eigen/Core>
#include <atomic>
#include <cstdlib>
#include <new>

namespace gfins::testing {
inline std::atomic<long> g_allocations{0};
}  // namespace gfins::testing

// The replacements pair malloc with free; GCC's -Wmismatched-new-delete cannot see that the
// operator new it inlines next to them is this malloc-based one, so it is silenced here only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  gfins::testing::g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace gfins::testing {

/// RAII window in which neither Eigen nor anything else may allocate.
class NoAllocWindow {
 public:
  NoAllocWindow() : start_(g_allocations.load()) { Eigen::internal::set_is_malloc_allowed(false); }
  ~NoAllocWindow() { Eigen::internal::set_is_malloc_allowed(true); }
  NoAllocWindow(const NoAllocWindow&) = delete;
  NoAllocWindow& operator=(const NoAllocWindow&) = delete;
  long allocations() const { return g_allocations.load() - start_; }

 private:
  long start_;
};

}  // namespace gfins::testing
