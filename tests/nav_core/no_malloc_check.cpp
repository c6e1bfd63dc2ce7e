// Proves the navigation core never touches the heap: the whole core is compiled into this test
// with EIGEN_RUNTIME_NO_MALLOC (Eigen asserts on any allocation while forbidden), and the global
// operator new is replaced by a counting one, which catches allocations outside Eigen too.
// Neither check is active while GoogleTest itself runs; only the windows marked below count.
#ifndef EIGEN_RUNTIME_NO_MALLOC
#error "this test must be compiled with EIGEN_RUNTIME_NO_MALLOC"
#endif

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "gfins/nav_core/pipeline.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// The replacements pair malloc with free; GCC's -Wmismatched-new-delete cannot see that the
// operator new it inlines next to them is this malloc-based one, so it is silenced here only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace gfins::nav {
namespace {

// RAII window in which neither Eigen nor anything else may allocate.
class NoAllocWindow {
 public:
  NoAllocWindow() : start_(g_allocations.load()) { Eigen::internal::set_is_malloc_allowed(false); }
  ~NoAllocWindow() { Eigen::internal::set_is_malloc_allowed(true); }
  long allocations() const { return g_allocations.load() - start_; }

 private:
  long start_;
};

template <typename T>
long allocations_for_full_run(CompensatorKind kind) {
  static PipelineConfig<T> config;  // static: the test owns no large stack objects either
  static NavPipeline<T> pipeline;
  config.front_end.volts_per_count.fill(T(10.0 / 8388608.0));
  config.front_end.scale_v_per_g.fill(T(1));
  config.compensator = kind;
  config.misalignment.orientation.beta[0] = T(0.01);
  config.misalignment.drho_b[2] = Vec3<T>(T(0.001), T(0), T(0));
  config.alignment_samples = 10;
  NoAllocWindow window;
  if (!pipeline.configure(config).is_ok()) return -1;
  std::array<std::int32_t, 6> counts = {10, -20, 30000, -400000, 5000, 600000};
  for (std::uint32_t k = 0; k < 200; ++k) {
    counts[k % 6] += static_cast<std::int32_t>(k);
    pipeline.process(counts, static_cast<std::int64_t>(k) * 1000000, k);
  }
  if (pipeline.phase() != PipelinePhase::kNavigating) return -2;
  return window.allocations();
}

TEST(NoMallocTest, ConfigureAlignAndStepNeverAllocateFloat) {
  EXPECT_EQ(allocations_for_full_run<float>(CompensatorKind::kNone), 0);
  EXPECT_EQ(allocations_for_full_run<float>(CompensatorKind::kPaper), 0);
  EXPECT_EQ(allocations_for_full_run<float>(CompensatorKind::kExact), 0);
}

TEST(NoMallocTest, ConfigureAlignAndStepNeverAllocateDouble) {
  EXPECT_EQ(allocations_for_full_run<double>(CompensatorKind::kPaper), 0);
}

// The detector itself must be able to fail: an Eigen dynamic matrix inside a window is caught.
TEST(NoMallocTest, CounterSeesAnAllocation) {
  long seen = 0;
  {
    const long before = g_allocations.load();
    void* p = ::operator new(sizeof(int));  // a new-expression may be elided; this call not
    seen = g_allocations.load() - before;
    ::operator delete(p);
  }
  EXPECT_EQ(seen, 1);
  EXPECT_DEATH(
      {
        NoAllocWindow w;
        Eigen::MatrixXd m(50, 50);
        m.setZero();
      },
      "is_malloc_allowed");
}

}  // namespace
}  // namespace gfins::nav
