// The standstill detector (filter/standstill_detector.hpp): its false-alarm rate at rest against
// the configured one, and detection of motion, from the array's forward physics (filter_truth.hpp).
#include "gfins/nav_core/filter/standstill_detector.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "nav_core/filter_truth.hpp"

namespace gfins::nav {
namespace {

using testing::SensorErrors;
using testing::Truth;

constexpr double kRhoM = 0.1;
constexpr double kRateHz = 200;
constexpr double kNoise = 3e-4;  // per-sensor white σ, m/s² (≈ 30 µg at 200 Hz)
constexpr std::uint32_t kWindow = 50;
constexpr double kPfa = 0.01;

struct Rig {
  ArraySolver<double, 6> solver = ArraySolver<double, 6>::create(table1_geometry(kRhoM)).value();
  StandstillDetector<double> det;
  Rig() {
    StandstillConfig<double> c;
    c.window = kWindow;
    c.false_alarm_probability = kPfa;
    c.white_sigma_mps2 = kNoise;
    c.gravity_mps2 = testing::kG;
    EXPECT_TRUE(det.configure(solver, c).is_ok());
  }
  /// Feeds one sample of the truth x; true when a window completed.
  bool feed(const Truth& x, SensorErrors& e) {
    const Vec6<double> s = e.apply(testing::ideal_outputs(solver.geometry(), x));
    const Vec6<double> u = solver.linear_part(s);
    return det.add(u.head<3>(), u.tail<3>());
  }
};

// For Table 1, σ² M Mᵀ is block diagonal and isotropic per block: the statistic's components
// are independent with the variances it divides by, so W·T is exactly χ²(6W − 3) under H0.
TEST(StandstillDetectorTest, Table1NoiseThroughMIsIsotropicPerBlock) {
  const Rig rig;
  const auto m = rig.solver.m();
  const Mat6<double> c = m * m.transpose();
  constexpr double kRounding = 1e-12;  // double rounding of the SVD-built M
  EXPECT_NEAR((c.topRightCorner<3, 3>()).norm(), 0.0, kRounding);
  EXPECT_NEAR((c.topLeftCorner<3, 3>() - c(0, 0) * Mat3<double>::Identity()).norm(), 0.0,
              kRounding);
  EXPECT_NEAR((c.bottomRightCorner<3, 3>() - c(3, 3) * Mat3<double>::Identity()).norm(), 0.0,
              kRounding);
}

// Given 4000 windows at rest, the count of "moving" decisions is Binomial(4000, 0.01): mean 40,
// σ 6.29. Bounds ±4σ: false-failure probability 6e-5 (normal approximation).
TEST(StandstillDetectorTest, FalseAlarmRateAtRestMatchesConfigured) {
  Rig rig;
  SensorErrors errors(0.0, kNoise, 7);
  const Truth x = testing::rest(quat_from_euler(0.05, -0.02, 1.0));
  constexpr int kWindows = 4000;
  int alarms = 0;
  for (int k = 0; k < kWindows * static_cast<int>(kWindow); ++k) {
    if (rig.feed(x, errors) && !rig.det.at_rest()) ++alarms;
  }
  const double mean = kWindows * kPfa;
  const double sd = std::sqrt(kWindows * kPfa * (1 - kPfa));
  std::printf("false alarms %d of %d windows (expected %.1f ± %.1f)\n", alarms, kWindows, mean, sd);
  EXPECT_EQ(rig.det.windows(), static_cast<std::uint32_t>(kWindows));
  EXPECT_GE(alarms, mean - 4 * sd);
  EXPECT_LE(alarms, mean + 4 * sd);
}

// A vehicle pulling away with a jerk of 0.5 m/s³ (acceleration ramping 0 → 1 m/s² over 2 s):
// within one window (0.25 s) f changes by 0.125 m/s², a scatter 10⁵ times the noise variance.
TEST(StandstillDetectorTest, DetectsAJerk) {
  Rig rig;
  SensorErrors errors(0.0, kNoise, 8);
  constexpr double kJerk = 0.5;
  int windows = 0, moving = 0;
  for (int k = 0; k < static_cast<int>(2.0 * kRateHz); ++k) {
    const double t = k / kRateHz;
    Truth x;
    x.a_n = Vec3<double>(kJerk * t, 0, 0);
    if (rig.feed(x, errors)) {
      ++windows;
      if (!rig.det.at_rest()) ++moving;
    }
  }
  EXPECT_EQ(moving, windows);
  EXPECT_GT(windows, 0);
}

// The start of a slow turn: yaw rate ramping to 0.1 rad/s in 2 s (ω̇ = 0.05 rad/s², ~3°/s after
// one second): ω̇ is seen directly, (0.05/σ_ω̇)² ≈ 10³ per sample against a threshold near 1.3.
TEST(StandstillDetectorTest, DetectsTheStartOfASlowTurn) {
  Rig rig;
  SensorErrors errors(0.0, kNoise, 9);
  constexpr double kWdot = 0.05;
  int windows = 0, moving = 0;
  for (int k = 0; k < static_cast<int>(2.0 * kRateHz); ++k) {
    const double t = k / kRateHz;
    Truth x;
    x.q_nb = Quat<double>(Eigen::AngleAxisd(0.5 * kWdot * t * t, Vec3<double>::UnitZ()));
    x.w_b = Vec3<double>(0, 0, kWdot * t);
    x.wdot_b = Vec3<double>(0, 0, kWdot);
    if (rig.feed(x, errors)) {
      ++windows;
      if (!rig.det.at_rest()) ++moving;
    }
  }
  EXPECT_EQ(moving, windows);
}

// The physical limit, stated as a test: a constant yaw rate about the body z axis leaves every
// Table 1 output unchanged (θ_j·(ω×(ω×ρ_j)) = 0 for ω ∥ z) and f constant, so no accelerometer
// statistic can tell it from rest. The detector must be combined with other evidence (speed,
// odometry) in a vehicle that can turn on the spot at constant rate.
TEST(StandstillDetectorTest, ConstantYawRateIsIndistinguishableFromRest) {
  Rig rig;
  SensorErrors errors(0.0, 0.0, 10);
  Truth x;
  x.w_b = Vec3<double>(0, 0, 0.2);
  const Vec6<double> s = testing::ideal_outputs(rig.solver.geometry(), x);
  const Vec6<double> s_rest = testing::ideal_outputs(rig.solver.geometry(), Truth{});
  constexpr double kRounding = 1e-15;  // a few ulp of the outputs (≈ 7 m/s²)
  EXPECT_LT((s - s_rest).norm(), kRounding * 100);
}

TEST(StandstillDetectorTest, RejectsBadConfiguration) {
  const Rig rig;
  StandstillDetector<float> det;
  StandstillConfig<float> c;
  c.window = 1;
  EXPECT_FALSE(
      det.configure(ArraySolver<float, 6>::create(table1_geometry(0.1F)).value(), c).is_ok());
}

}  // namespace
}  // namespace gfins::nav
