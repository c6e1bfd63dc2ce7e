// Proves the navigation core never touches the heap: the core as it ships (gfins::nav_core, the
// release build's objects) runs inside windows in which every heap call of the process is counted
// (malloc, calloc, realloc and the aligned allocators interposed: support/heap_counter.hpp), so
// Eigen's allocations, operator new and anything else are seen alike. Only the windows count, not
// GoogleTest around them.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "gfins/nav_core/filter/error_state_filter.hpp"
#include "gfins/nav_core/filter/standstill_detector.hpp"
#include "gfins/nav_core/pipeline.hpp"
#include "support/heap_counter.hpp"

namespace gfins::nav {
namespace {

using gfins::testing::HeapCounter;
using gfins::testing::HeapWindow;

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
  const HeapWindow window;
  if (!pipeline.configure(config).is_ok()) return -1;
  RawSample s;
  s.counts = {10, -20, 30000, -400000, 5000, 600000};
  for (std::uint32_t k = 0; k < 200; ++k) {
    s.counts[k % 6] += static_cast<std::int32_t>(k);
    s.t_ns = static_cast<std::int64_t>(k) * 1000000;
    s.seq = k;
    pipeline.process(s);
  }
  if (pipeline.phase() != PipelinePhase::kNavigating) return -2;
  return window.allocations();
}

TEST(NoMallocTest, ConfigureAlignAndStepNeverAllocateFloat) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  EXPECT_EQ(allocations_for_full_run<float>(CompensatorKind::kNone), 0);
  EXPECT_EQ(allocations_for_full_run<float>(CompensatorKind::kPaper), 0);
  EXPECT_EQ(allocations_for_full_run<float>(CompensatorKind::kExact), 0);
}

TEST(NoMallocTest, ConfigureAlignAndStepNeverAllocateDouble) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  EXPECT_EQ(allocations_for_full_run<double>(CompensatorKind::kPaper), 0);
}

// The aided filter: configure, start, propagate and every kind of update (accepted, rejected,
// reset before heading alignment), the accuracy outputs and the standstill detector.
template <typename T>
long allocations_for_filter() {
  static ErrorStateFilter<T> filter;
  static StandstillDetector<T> detector;
  const auto solver = ArraySolver<T, 6>::create(table1_geometry(T(0.1))).value();
  const auto gravity = GravityModel<T>::constant(T(9.80665));
  static Strapdown<T, 6> nav;
  nav = Strapdown<T, 6>(solver, gravity);
  Vec6<T> s = solver.predict(Vec3<T>::Zero(), Vec3<T>(T(0), T(0), T(-9.80665)), Vec3<T>::Zero());
  NavState<T> init;
  init.status = nav_status::kAligned;
  FilterConfig<T> config;
  config.heading_known = false;
  config.gnss_lever_arm_b = Vec3<T>(T(0.5), T(0), T(-0.3));
  const HeapWindow window;
  nav.initialize(init, s);
  if (!filter.configure(config).is_ok()) return -1;
  if (!detector.configure(solver, StandstillConfig<T>{}).is_ok()) return -1;
  filter.start(nav);
  GnssFix<T> fix;
  fix.sigma = Vec3<T>::Constant(T(1));
  std::uint32_t outcomes = 0;
  for (std::uint32_t k = 1; k <= 400; ++k) {
    nav.step(s, T(0.001), static_cast<std::int64_t>(k) * 1000000, k);
    const Vec6<T> u = solver.linear_part(s);
    detector.add(u.template head<3>(), u.template tail<3>());
    if (k % 10 != 0) continue;
    if (!filter.propagate(nav, T(0.01)).is_ok()) return -2;
    outcomes += static_cast<std::uint32_t>(filter.update_zupt(nav).status);
    outcomes += static_cast<std::uint32_t>(filter.update_zaru(nav).status);
    fix.t_valid_ns = nav.state().t_ns - 5000000;  // latency: interpolated in the history
    fix.value_n = Vec3<T>(T(0), T(0), T(0.3)) + Vec3<T>::Constant(k == 200 ? T(100) : T(0));
    outcomes += static_cast<std::uint32_t>(filter.update_gnss_position(nav, fix).status);
    fix.value_n = k == 100 ? Vec3<T>(T(5), T(0), T(0)) : Vec3<T>::Zero();
    outcomes += static_cast<std::uint32_t>(filter.update_gnss_velocity(nav, fix).status);
    outcomes += static_cast<std::uint32_t>(
        filter.update_heading(nav, HeadingFix<T>{nav.state().t_ns, T(0), T(0.1)}).status);
    if (filter.accuracy(nav.state()).valid == 0xff) return -3;
  }
  if (!filter.heading_aligned() || outcomes == 0) return -4;
  return window.allocations();
}

TEST(NoMallocTest, FilterPropagationAndEveryUpdateNeverAllocate) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  EXPECT_EQ(allocations_for_filter<float>(), 0);
  EXPECT_EQ(allocations_for_filter<double>(), 0);
}

// The counter itself must be able to fail: operator new and an Eigen dynamic matrix inside a
// window are both seen.
TEST(NoMallocTest, CounterSeesAnAllocation) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  long by_new = 0;
  {
    const HeapWindow w;
    void* p = ::operator new(sizeof(int));  // a new-expression may be elided; this call not
    by_new = w.allocations();
    ::operator delete(p);
  }
  EXPECT_EQ(by_new, 1);
  long by_eigen = 0;
  {
    const HeapWindow w;
    Eigen::MatrixXd m(50, 50);
    m.setZero();
    by_eigen = w.allocations();
    EXPECT_EQ(m.sum(), 0.0);
  }
  EXPECT_GE(by_eigen, 1);
}

}  // namespace
}  // namespace gfins::nav
