// The re-level at rest of Aiding (filter/aiding.hpp, ErrorStateFilter::relevel_at_rest): a board
// whose tilt is lost (here an in-motion start, lose_attitude; a divergence restart takes the same
// path) and whose attitude is 20° of roll and 15° of pitch off stands still. No ZUPT can bring
// that back; the window's mean specific force must.
//
// The truth is written here: the board at rest at roll 5°, pitch −3°, heading 40°, the array's
// forward physics (filter_truth.hpp) with a constant bias per sensor and white noise. Tolerances:
//  - roll and pitch within 4σ of the σ the filter publishes: the error is the window mean's noise
//    plus the bias seen through the solve, both Gaussian, and the published σ is their marginal
//    (the tilt set as A δβ + n, correlated with the bias); false failure below 6.4e-5 per axis and
//    run for an honest σ. A sign or axis slip in the turn leaves tens of degrees.
//  - that σ, just after the re-level, below 0.003°: the noise (1e-3 m/s² per sensor, 100-sample
//    window) and the bias prior (2e-4 m/s² per sensor) give 1.6e-4 m/s² per axis, 1.6e-5 rad
//    (0.0009°) of tilt; a variance not divided by g² gives a σ 9.8 times larger (checked).
//  - the heading kept within 0.01°: nothing at rest observes it, and the turn that levels a 25°
//    tilt moves the yaw angle by about roll × pitch (over 1°) unless it is put back.
//  - the velocity within 0.03 m/s of zero (3σ of the ZUPT's 0.01 m/s): before the re-level the
//    wrong tilt had made it grow by g sin 25° ≈ 4 m/s² over each window.
#include <gtest/gtest.h>

#include <cmath>

#include "nav_core/aiding_stand.hpp"

namespace gfins::nav {
namespace {

using rest_stand::kDeg;
using rest_stand::Stand;

TEST(AidingRestRelevel, AStandstillLevelsALostTiltAndKeepsTheHeading) {
  Stand b(true, 11);
  b.run(50);  // half a detector window: nothing decided yet
  EXPECT_TRUE(b.aiding.filter().tilt_lost());
  EXPECT_TRUE(std::isnan(b.accuracy().euler_sigma_rad(0)));
  EXPECT_EQ(b.accuracy().valid & filter_valid::kRollPitch, 0);

  b.run(50);  // the first window's decision, applied at the propagation with its last sample
  const FilterCounters& c = b.counters();
  EXPECT_EQ(c.rest_relevels, 1u);
  EXPECT_FALSE(b.aiding.filter().tilt_lost());
  const auto check_tilt = [&b](double sigma_max_rad) {
    const NavAccuracy<double> a = b.accuracy();
    const Vec3<double> e = b.euler_error();
    for (int i = 0; i < 2; ++i) {
      SCOPED_TRACE(i == 0 ? "roll" : "pitch");
      ASSERT_TRUE(std::isfinite(a.euler_sigma_rad(i)));
      EXPECT_LT(a.euler_sigma_rad(i), sigma_max_rad);
      EXPECT_LE(std::abs(e(i)), 4.0 * a.euler_sigma_rad(i));
    }
  };
  check_tilt(0.003 * kDeg);

  // 0.9 s more at rest: the ZUPT and ZARU hold it (the tilt σ grows with what the ZARU's 1e-3
  // rad/s leaves of the rate, about 1e-4 rad per window: 0.05° bounds nine windows of it).
  b.run(900);
  EXPECT_EQ(c.rest_relevels, 1u);  // once: the tilt is found, then the ZUPTs hold it
  EXPECT_GE(c.accepted[static_cast<std::size_t>(AidingKind::kZupt)], 5u);
  check_tilt(0.05 * kDeg);
  const NavAccuracy<double> a = b.accuracy();
  const Vec3<double> e = b.euler_error();
  EXPECT_LT(std::abs(e(2)), 0.01 * kDeg);
  // Roll and pitch are published; heading, velocity and position are not (the heading is not
  // known, so neither is the velocity's direction once the board moves off).
  EXPECT_EQ(a.valid, filter_valid::kRollPitch);
  EXPECT_LT(b.nav.state().v_n.norm(), 0.03);
}

TEST(AidingRestRelevel, WithoutStandstillUpdatesTheTiltStaysLost) {
  Stand b(false, 11);  // negative control: the same board, the standstill updates off
  b.run(1000);
  EXPECT_EQ(b.counters().rest_relevels, 0u);
  EXPECT_TRUE(b.aiding.filter().tilt_lost());
  EXPECT_TRUE(std::isnan(b.accuracy().euler_sigma_rad(0)));
  EXPECT_EQ(b.accuracy().valid & filter_valid::kRollPitch, 0);
  EXPECT_GT(std::abs(b.euler_error()(0)), 10.0 * kDeg);
}

TEST(AidingRestRelevel, ATiltWhoseSigmaIsPastTheValidityHorizonIsRelevelledToo) {
  // Not lost, but the filter's tilt 1σ (0.3 rad, 17°) is past the 1° horizon: roll and pitch are
  // not published, and a 20-25° error is outside what the ZUPT's linear model can bring back. The
  // velocity is known, and the window's drift (g sin 25° over 0.1 s) passes the gate with that
  // tilt σ. The heading is known and kept.
  Stand b(true, 12, 0.3, false);
  EXPECT_FALSE(b.aiding.filter().tilt_lost());
  EXPECT_TRUE(b.aiding.filter().relevel_wanted());
  b.run(100);
  EXPECT_EQ(b.counters().rest_relevels, 1u);
  EXPECT_FALSE(b.aiding.filter().relevel_wanted());
  const NavAccuracy<double> a = b.accuracy();
  const Vec3<double> e = b.euler_error();
  for (int i = 0; i < 2; ++i) {
    EXPECT_LT(a.euler_sigma_rad(i), 0.003 * kDeg);
    EXPECT_LE(std::abs(e(i)), 4.0 * a.euler_sigma_rad(i));
  }
  EXPECT_LT(std::abs(e(2)), 0.01 * kDeg);
  EXPECT_NE(a.valid & filter_valid::kRollPitch, 0);
}

TEST(AidingRestRelevel, ATiltMoreThanAQuarterTurnOffIsLevelledToo) {
  // A lost tilt can be past 90° (the unaided drive: 89° after 10 s); at rest f̄ is exact, so the
  // level takes any angle short of upside-down exactly. Strapdown roll 130° against the truth's 5°.
  Stand b(true, 13, 0.01, true, 130.0);
  b.run(100);
  EXPECT_EQ(b.counters().rest_relevels, 1u);
  const NavAccuracy<double> a = b.accuracy();
  const Vec3<double> e = b.euler_error();
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(std::isfinite(a.euler_sigma_rad(i)));
    EXPECT_LT(a.euler_sigma_rad(i), 0.003 * kDeg) << i;
    EXPECT_LE(std::abs(e(i)), 4.0 * a.euler_sigma_rad(i)) << i;
  }
}

TEST(AidingRestRelevel, TheLevelIsTakenAtZeroRate) {
  // The tilt past the horizon (not lost: a lost one has its rate zeroed at the loss) and the
  // strapdown's rate 0.4 rad/s off about x and about z (the board is at rest): its f̄ carries
  // the centripetal term K_f m(ω̂), for Table 1 ρ ω̂_x ω̂_z = 0.016 m/s² along y (0.09° of roll),
  // which the re-level must take out as it zeroes the rate. Roll and pitch within 4σ (σ below
  // 0.003°) after it; levelled on f̄ as it was, the roll was 0.094° (100σ) off.
  Stand b(true, 15, 0.3, false, 25.0, false, Vec3<double>(0.4, 0.0, 0.4));
  b.run(100);
  ASSERT_EQ(b.counters().rest_relevels, 1u);
  const NavAccuracy<double> a = b.accuracy();
  const Vec3<double> e = b.euler_error();
  for (int i = 0; i < 2; ++i) {
    EXPECT_LT(a.euler_sigma_rad(i), 0.003 * kDeg) << i;
    EXPECT_LE(std::abs(e(i)), 4.0 * a.euler_sigma_rad(i)) << i;
  }
}

TEST(AidingRestRelevel, ACruiseThatReadsLikeRestIsNotLevelledToAStop) {
  // A straight drive at 30 m/s (the specific force is gravity's alone, as at rest) with the tilt
  // σ past the horizon and the velocity known to 0.05 m/s: the re-level's velocity gate refuses
  // a zero velocity (NIS ≈ 30² / 0.05² against 16.3), counted as a rejected ZUPT and a motion
  // veto, and the velocity stays. Without the gate it was set to zero with the ZUPT's σ.
  Stand b(true, 14, 0.1, false, 25.0, true);
  ASSERT_TRUE(b.aiding.filter().relevel_wanted());
  b.run(1000);
  EXPECT_EQ(b.counters().rest_relevels, 0u);
  EXPECT_EQ(b.counters().accepted[static_cast<std::size_t>(AidingKind::kZupt)], 0u);
  EXPECT_EQ(b.counters().rejected[static_cast<std::size_t>(AidingKind::kZupt)], 10u);
  EXPECT_EQ(b.aiding.motion_vetoes(), 10u);
  EXPECT_GT(b.nav.state().v_n.x(), 25.0);
}

TEST(AidingRestRelevel, ATiltWithinTheValidityHorizonIsLeftToTheZupt) {
  // The filter's tilt 1σ at 0.57° (the default P0), not lost: the tilt is the filter's to
  // estimate (with its correlations), and a re-level is refused and counted as invalid.
  Stand b(true, 11, 0.01, false);
  EXPECT_FALSE(b.aiding.filter().relevel_wanted());
  const std::uint32_t invalid_before =
      b.counters().invalid[static_cast<std::size_t>(AidingKind::kZupt)];
  Strapdown<double> copy = b.nav;
  ErrorStateFilter<double> filter = b.aiding.filter();
  const UpdateOutcome o = filter.relevel_at_rest(copy, Vec3<double>(0, 0, -testing::kG), 1e-8);
  EXPECT_EQ(o.status, UpdateStatus::kInvalid);
  EXPECT_EQ(filter.counters().invalid[static_cast<std::size_t>(AidingKind::kZupt)],
            invalid_before + 1);
  EXPECT_EQ(filter.counters().rest_relevels, 0u);
  b.run(1000);  // and the pipeline leaves it to the ZUPT
  EXPECT_EQ(b.counters().rest_relevels, 0u);
}

}  // namespace
}  // namespace gfins::nav
