// The built-in `highway` scenario (600 s: a 10 s stop, 20 s of acceleration to 30 m/s, gentle
// curves, a 30 s GNSS outage at full speed; QA-1100 sensor model at 40 °C, 5 Hz receiver with
// 1.5 m / 0.1 m/s) through the host navigation loop with its [aiding] switched on, as
// `gfins-sim aided highway` runs it. The oracle is the trajectory's analytic truth.
//
// Bounds, and what breaks them:
//  - outside the outage and the 10 s after it: horizontal position RMS ≤ 1.5 m and velocity RMS
//    ≤ 0.1 m/s (the aiding targets for a 1.5 m / 0.1 m/s receiver), tilt and heading RMS ≤ 1°.
//    Measured 0.21 m, 0.082 m/s, 0.43°, 0.18°. Without the heading of the GNSS track (the
//    negative control below) the heading is lost at constant speed and every one of these fails
//    (measured 9.9 m, 9.7 m/s, 57°, 93°).
//  - 10 s after the outage the position error is back under 1.5 m (measured 0.19 m): a filter
//    whose gate keeps out the first fixes after an outage (the solution is then hundreds of
//    metres off) never comes back.
//  - every error component within the filter's 3σ in ≥ 98 % of the samples after 10 s (measured
//    99.1-100 %). A consistent filter has 99.7 % per component; the samples are correlated in
//    time (hundreds of independent stretches), so 98 % leaves room for that and still fails an
//    optimistic filter (the control: 47-81 %).
//  - inside the outage the solution diverges (the filter restarts, measured 13 times): from the
//    first restart (17 s into the outage) to the first fixes after it every σ is not available,
//    and where a σ is published each error lies within its 3σ in ≥ 98 % of the samples
//    (measured 100 %). Published through the restart, the σ the filter kept covered the position
//    error in only 83 % (down) and 86 % (east) of the outage's samples.
//  - roll and pitch RMS outside the outage (measured 0.338° / 0.328°) miss the 0.3° target, and
//    the filter's covariance predicts it: the RMS of its own 1σ is 0.317° / 0.314°, above the
//    target, and the errors are within 1.25 times it (docs/navigation-accuracy.md: the floor is
//    the receiver's 0.1 m/s).
//  - no sample is non-finite (the unaided solution of the same sensors leaves the finite numbers
//    within 100 s; the divergence restart keeps the aided one finite through the outage).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "gfins/host_sim/accuracy.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim {
namespace {

const std::string kScenarioDir = std::string(GFINS_TEST_DATA_DIR) + "/../../host_sim/scenarios";

constexpr double kPosRmsMaxM = 1.5;
constexpr double kVelRmsMaxMps = 0.1;
constexpr double kAngleRmsMaxDeg = 1.0;
constexpr double kAfterOutagePosMaxM = 1.5;
constexpr double kWithin3SigmaMin = 0.98;
constexpr double kTiltTargetDeg = 0.3;
constexpr double kFloorRatioMax = 1.25;

struct HighwayRun {
  AccuracyTracker acc;
  StreamedOutcome out;
};

HighwayRun run_highway(double track_heading_deg, double receiver_sigma_vel_mps = 0.0) {
  auto s = load_scenario("highway", kScenarioDir);
  EXPECT_TRUE(s.is_ok()) << s.error().message;
  Scenario sc = s.value();
  EXPECT_TRUE(sc.gnss.has_value());
  EXPECT_EQ(sc.gnss->outages.size(), 1u);
  sc.aiding.enabled = true;
  sc.aiding.track_heading_sigma_deg = track_heading_deg;
  if (receiver_sigma_vel_mps > 0.0) sc.gnss->sigma_vel_mps = receiver_sigma_vel_mps;
  HighwayRun r{AccuracyTracker({60.0, 600.0}, 10.0, sc.gnss->outages, 10.0), {}};
  StreamTargets t;
  t.uncompensated_run = false;
  t.accuracy = &r.acc;
  auto o = run_scenario_streamed(sc, t, {}, NavScalar::kFloat);
  EXPECT_TRUE(o.is_ok()) << o.error().message;
  r.out = o.value();
  return r;
}

TEST(AidedHighway, BoundedThroughTheOutageAndConsistent) {
  const HighwayRun r = run_highway(0.5);
  ASSERT_EQ(r.acc.windows().size(), 1u);
  const ErrorSnapshot in = r.acc.rms_outside();
  ASSERT_GT(r.acc.rms_outside_samples(), 500000u);
  EXPECT_LE(in.pos_h_m, kPosRmsMaxM);
  EXPECT_LE(in.vel_mps, kVelRmsMaxMps);
  EXPECT_LE(in.tilt_deg, kAngleRmsMaxDeg);
  EXPECT_LE(in.heading_deg, kAngleRmsMaxDeg);
  const auto& w = r.acc.windows()[0];
  ASSERT_TRUE(w.after.seen);
  EXPECT_LE(w.after.pos_h_m, kAfterOutagePosMaxM);
  EXPECT_TRUE(std::isfinite(r.acc.worst().pos_h_m + r.acc.worst().tilt_deg));
  ASSERT_GT(r.acc.sigma_samples(), 500000u);
  for (std::size_t k = 0; k < kConsistencyComponents; ++k) {
    EXPECT_GE(r.acc.within_3sigma(k), kWithin3SigmaMin) << kConsistencyNames[k];
  }
  EXPECT_GT(
      r.out.compensated.report.filter.accepted[static_cast<std::size_t>(nav::AidingKind::kHeading)],
      1000u);
  // Roll and pitch miss the 0.3° target at 30 m/s, and the covariance says so: the filter's own
  // 1σ RMS is above it, the floor for this receiver's 0.1 m/s, and the errors meet that floor.
  const AccuracyTracker::RollPitch rp = r.acc.roll_pitch();
  EXPECT_GT(rp.roll_sigma_rms_deg, kTiltTargetDeg);
  EXPECT_GT(rp.pitch_sigma_rms_deg, kTiltTargetDeg);
  EXPECT_LE(rp.roll_rms_deg, kFloorRatioMax * rp.roll_sigma_rms_deg);
  EXPECT_LE(rp.pitch_rms_deg, kFloorRatioMax * rp.pitch_sigma_rms_deg);
  // Inside the outage the solution diverges and the filter restarts; from the restart until the
  // fixes set each quantity again its σ is not available, and where a σ is published the error
  // lies within its 3σ.
  EXPECT_GE(r.out.compensated.report.filter.divergence_restarts, 1u);
  const Coverage& inside = w.inside;
  for (std::size_t k = 0; k < kConsistencyComponents; ++k) {
    EXPECT_LT(inside.published(k), inside.offered()) << kConsistencyNames[k];
    EXPECT_GT(inside.published(k), inside.offered() / 4) << kConsistencyNames[k];
    EXPECT_GE(inside.fraction(k), kWithin3SigmaMin) << kConsistencyNames[k];
  }
  std::printf(
      "highway aided: %s; outside the outage: pos %.3f m, vel %.3f m/s, tilt %.3f deg, "
      "heading %.3f deg; 10 s after it %.3f m; outage worst %.1f m\n",
      r.acc.describe_rms().c_str(), in.pos_h_m, in.vel_mps, in.tilt_deg, in.heading_deg,
      w.after.pos_h_m, w.worst_inside.pos_h_m);
}

// A receiver five times better in velocity (0.02 m/s): the first fixes after the outage are then
// much sharper than the solution they meet (the outage leaves tens of degrees of tilt), which is
// where a filter that trusts its linear model after a re-level starts to spin. Bounds: the same
// accuracy and consistency bounds as above (the 1.5 m / 0.1 m/s targets hold a fortiori), and no
// more than 5 fixes of each GNSS kind rejected in the run (a spinning solution has its gate
// reject hundreds) and no lock-out reset. Measured: 98.7-100 % within 3σ, 0.020 m/s and 0.096 m
// RMS outside the outage, 0.23 m 10 s after it, 5 position and 1 velocity fix rejected.
TEST(AidedHighway, AFiveTimesBetterReceiverSettlesAfterTheOutageToo) {
  const HighwayRun r = run_highway(0.5, 0.02);
  const ErrorSnapshot in = r.acc.rms_outside();
  EXPECT_LE(in.pos_h_m, kPosRmsMaxM);
  EXPECT_LE(in.vel_mps, kVelRmsMaxMps);
  EXPECT_LE(in.tilt_deg, kAngleRmsMaxDeg);
  EXPECT_LE(in.heading_deg, kAngleRmsMaxDeg);
  ASSERT_EQ(r.acc.windows().size(), 1u);
  EXPECT_LE(r.acc.windows()[0].after.pos_h_m, kAfterOutagePosMaxM);
  for (std::size_t k = 0; k < kConsistencyComponents; ++k) {
    EXPECT_GE(r.acc.within_3sigma(k), kWithin3SigmaMin) << kConsistencyNames[k];
  }
  const nav::FilterCounters& c = r.out.compensated.report.filter;
  EXPECT_LE(c.rejected[static_cast<std::size_t>(nav::AidingKind::kGnssPosition)], 5u);
  EXPECT_LE(c.rejected[static_cast<std::size_t>(nav::AidingKind::kGnssVelocity)], 5u);
  EXPECT_EQ(c.gnss_lockout_resets, 0u);
  std::printf(
      "highway aided, 0.02 m/s receiver: %s; outside the outage: pos %.3f m, vel %.3f m/s\n",
      r.acc.describe_rms().c_str(), in.pos_h_m, in.vel_mps);
}

// Negative control: the same without the track's heading (the filter has no heading
// information at constant speed) fails the bounds above.
TEST(AidedHighway, WithoutTheTrackHeadingTheBoundsFail) {
  const HighwayRun r = run_highway(0.0);
  const ErrorSnapshot in = r.acc.rms_outside();
  EXPECT_GT(in.heading_deg, kAngleRmsMaxDeg);
  EXPECT_GT(in.vel_mps, kVelRmsMaxMps);
  std::size_t failing = 0;
  for (std::size_t k = 0; k < kConsistencyComponents; ++k) {
    failing += r.acc.within_3sigma(k) < kWithin3SigmaMin ? 1 : 0;
  }
  EXPECT_GT(failing, 0u);
}

}  // namespace
}  // namespace gfins::sim
