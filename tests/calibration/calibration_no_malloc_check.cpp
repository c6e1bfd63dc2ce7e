// Proves the multi-attitude solver and the static detector never touch the heap (they must run
// on the board): the solvers as they ship (gfins::nav_calib) run inside windows in which every
// heap call of the process is counted (support/heap_counter.hpp: malloc and the aligned
// allocators interposed, Eigen's and operator new's included). Only the marked windows count.
#include <gtest/gtest.h>

#include "gfins/nav_core/calibration/multi_attitude.hpp"
#include "gfins/nav_core/calibration/static_detector.hpp"
#include "support/heap_counter.hpp"

namespace gfins::calib {
namespace {

using gfins::testing::HeapCounter;
using gfins::testing::HeapWindow;

template <typename T>
long allocations_for_calibration() {
  // static: a 64-attitude observation list and the result are kilobytes; keep them off the stack
  static std::array<AttitudeObservation<T>, kMaxAttitudes> obs;
  static PaperTableOutputs<T> paper;
  for (std::size_t j = 0; j < kMaxAttitudes; ++j) {
    const T a = static_cast<T>(j) * T(0.7);
    const T b = static_cast<T>(j) * T(1.3);
    obs[j].f_b_g = {std::cos(a) * std::cos(b), std::sin(a) * std::cos(b), std::sin(b)};
    for (std::size_t i = 0; i < 6; ++i) {
      obs[j].mean_v[i] = T(0.5) * obs[j].f_b_g[i % 3] + T(0.01) * static_cast<T>(i);
      obs[j].sample_std_v[i] = T(1e-3);
    }
    obs[j].sample_count = 100;
  }
  for (std::size_t i = 0; i < 6; ++i) {
    for (std::size_t j = 0; j < 6; ++j) paper.mean_v[i][j] = (j % 2 == 0 ? T(0.3) : T(-0.3));
  }
  const HeapWindow window;
  const auto r = calibrate_multi_attitude<T>(std::span<const AttitudeObservation<T>>(obs));
  const auto p = calibrate_paper_procedure<T>(paper);
  (void)r;
  (void)p;
  return window.allocations();
}

template <typename T>
long allocations_for_detection() {
  static StaticDetector<T> detector;
  StaticDetectorConfig<T> cfg;
  cfg.sample_rate_hz = T(500);
  cfg.max_std_v.fill(T(3e-3));
  const HeapWindow window;
  auto d = StaticDetector<T>::create(cfg);
  if (!d.is_ok()) return -1;
  detector = d.value();
  std::array<T, 6> v{};
  for (int k = 0; k < 20000; ++k) {
    v.fill((k / 3000) % 2 == 0 ? T(0.1) : T(0.4));
    (void)detector.push(v);
  }
  (void)detector.finish();
  static std::array<AttitudeObservation<T>, kMaxAttitudes> obs;
  static std::array<int, kMaxAttitudes> which;
  PoseAssignmentConfig<T> pc;
  pc.nominal_scale_v_per_g.fill(T(1));
  const auto n = intervals_to_observations<T>(detector.intervals(), {}, pc, obs, which);
  (void)n;
  return window.allocations();
}

TEST(CalibrationNoMalloc, SolverNeverAllocates) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  EXPECT_EQ(allocations_for_calibration<float>(), 0);
  EXPECT_EQ(allocations_for_calibration<double>(), 0);
}

TEST(CalibrationNoMalloc, DetectorNeverAllocates) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  EXPECT_EQ(allocations_for_detection<float>(), 0);
  EXPECT_EQ(allocations_for_detection<double>(), 0);
}

}  // namespace
}  // namespace gfins::calib
