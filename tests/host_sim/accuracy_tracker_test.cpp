// AccuracyTracker against errors written into synthetic records, so every figure is known by
// hand: a position error of 3 m north and 4 m east is 5 m horizontal; RMS of 1 and 7 is 5; a
// component is within 3σ or not by construction.
#include "gfins/host_sim/accuracy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace gfins::sim {
namespace {

SampleRecord record(double t, double pos_n, double pos_e, double heading_rad = 0,
                    double sigma = std::numeric_limits<double>::quiet_NaN()) {
  SampleRecord r;
  r.t_s = t;
  r.truth.t_s = t;
  r.r_n_est = Vec3d(pos_n, pos_e, 0);
  // Heading error: the estimate turned about down by heading_rad.
  r.q_nb_est = Quatd(Eigen::AngleAxisd(heading_rad, Vec3d::UnitZ()));
  r.euler_sigma_rad.setConstant(sigma);
  r.v_sigma_n.setConstant(sigma);
  r.r_sigma_n.setConstant(sigma);
  return r;
}

TEST(AccuracyTracker, CheckpointsRmsWorstAndWindows) {
  AccuracyTracker a({1.0, 3.0}, 1.0, {{2.0, 3.0}}, 1.0);
  a.add(record(0.0, 100, 0));  // before rms_from: only in no statistic
  a.add(record(1.0, 3, 4));    // 5 m, checkpoint 1
  a.add(record(2.0, 0, 7));    // 7 m, inside the window
  a.add(record(3.0, 0, 1));    // 1 m, checkpoint 3; the window's end (not inside)
  a.add(record(4.0, 0, 2));    // 2 m: 1 s after the window
  ASSERT_EQ(a.checkpoints().size(), 2u);
  EXPECT_DOUBLE_EQ(a.checkpoints()[0].pos_h_m, 5.0);
  EXPECT_DOUBLE_EQ(a.checkpoints()[1].pos_h_m, 1.0);
  EXPECT_EQ(a.rms_samples(), 4u);
  EXPECT_DOUBLE_EQ(a.pos_h_rms_m(), std::sqrt((25.0 + 49.0 + 1.0 + 4.0) / 4.0));
  EXPECT_DOUBLE_EQ(a.worst().pos_h_m, 7.0);
  ASSERT_EQ(a.windows().size(), 1u);
  EXPECT_DOUBLE_EQ(a.windows()[0].worst_inside.pos_h_m, 7.0);
  EXPECT_DOUBLE_EQ(a.windows()[0].after.pos_h_m, 2.0);
  // Outside the window and the 1 s after it ([2, 4)): t = 1 and t = 4.
  EXPECT_EQ(a.rms_outside_samples(), 2u);
  EXPECT_DOUBLE_EQ(a.rms_outside().pos_h_m, std::sqrt((25.0 + 4.0) / 2.0));
}

TEST(AccuracyTracker, HeadingErrorInDegreesAndWithin3Sigma) {
  AccuracyTracker a({}, 0.0);
  const double deg = M_PI / 180.0;
  a.add(record(0.0, 0, 0, 2.0 * deg, 1.0 * deg));   // heading 2σ: within
  a.add(record(1.0, 0, 0, -4.0 * deg, 1.0 * deg));  // 4σ: outside
  a.add(record(2.0, 0, 0, 0.0));                    // no σ: not counted
  EXPECT_NEAR(a.worst().heading_deg, 4.0, 1e-9);
  EXPECT_NEAR(a.heading_rms_deg(), std::sqrt((4.0 + 16.0 + 0.0) / 3.0), 1e-9);
  EXPECT_EQ(a.sigma_samples(), 2u);
  EXPECT_DOUBLE_EQ(a.within_3sigma(2), 0.5);  // heading
  EXPECT_DOUBLE_EQ(a.within_3sigma(6), 1.0);  // r_N: zero error
}

// A σ marked not available (NaN, after a divergence restart) leaves its component out of the
// coverage, not the sample: the others still count, and the window's own coverage sees only its
// samples.
TEST(AccuracyTracker, CoverageCountsOnlyPublishedSigma) {
  AccuracyTracker a({}, 0.0, {{1.0, 3.0}}, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  a.add(record(0.0, 1, 0, 0.0, 1.0));  // r_N 1σ: within; before the window
  SampleRecord lost = record(1.0, 50, 0, 0.0, 1.0);
  lost.r_sigma_n.setConstant(nan);  // position σ not available: r_N 50 m not counted
  a.add(lost);
  a.add(record(2.0, 5, 0, 0.0, 1.0));  // r_N 5σ: outside, inside the window
  EXPECT_EQ(a.sigma_samples(), 3u);
  EXPECT_EQ(a.coverage().offered(), 3u);
  EXPECT_EQ(a.coverage().published(6), 2u);  // r_N
  EXPECT_EQ(a.coverage().published(3), 3u);  // v_N
  EXPECT_DOUBLE_EQ(a.within_3sigma(6), 0.5);
  EXPECT_DOUBLE_EQ(a.within_3sigma(3), 1.0);
  ASSERT_EQ(a.windows().size(), 1u);
  const Coverage& in = a.windows()[0].inside;
  EXPECT_EQ(in.samples(), 2u);
  EXPECT_EQ(in.published(6), 1u);
  EXPECT_DOUBLE_EQ(in.fraction(6), 0.0);
  // No σ of a component ever published: its fraction is not a number, not 0 or 1.
  AccuracyTracker none({}, 0.0);
  none.add(lost);
  EXPECT_TRUE(std::isnan(none.within_3sigma(6)));
  SampleRecord nothing = record(0.0, 1, 0);  // no σ at all (no filter): offered, not counted
  none.add(nothing);
  EXPECT_EQ(none.coverage().offered(), 2u);
  EXPECT_EQ(none.sigma_samples(), 1u);
}

TEST(AccuracyTracker, NonFiniteErrorIsTheWorst) {
  AccuracyTracker a({}, 0.0);
  a.add(record(0.0, 1, 0));
  a.add(record(1.0, std::numeric_limits<double>::quiet_NaN(), 0));
  a.add(record(2.0, 2, 0));
  EXPECT_TRUE(std::isnan(a.worst().pos_h_m));
}

/// A sample of the detector tally: the truth at rest, or moving at `v` m/s with body
/// acceleration `a` m/s² along x; `windows` decisions so far, the last `at_rest`.
SampleRecord detector_sample(double v, double a, std::uint32_t windows, bool at_rest) {
  SampleRecord r;
  r.truth.v_n = Vec3d(v, 0, 0);
  r.truth.a_n = Vec3d(a, 0, 0);
  r.detector_windows = windows;
  r.detector_at_rest = at_rest;
  return r;
}

// Windows of 2 samples, each decided at its second sample: the truth and the decisions are
// written here, so every count is known by hand.
TEST(AccuracyTracker, DetectorFalseAlarmsAndMissedDetectionsPerWindow) {
  DetectorTally d;
  const auto window = [&d](double v0, double a0, double v1, double a1, std::uint32_t n, bool rest) {
    d.add(detector_sample(v0, a0, n - 1, !rest));  // the previous decision still shown
    d.add(detector_sample(v1, a1, n, rest));
  };
  window(0, 0, 0, 0, 1, true);    // rest, declared rest (stop 1 reached)
  window(0, 0, 0, 0, 2, false);   // rest, declared moving: a false alarm
  window(0, 0, 1, 1, 3, false);   // rest then moving: straddles the stop's end
  window(1, 1, 2, 2, 4, false);   // accelerating, declared moving
  window(2, 0, 2, 0, 5, true);    // constant velocity, declared rest: missed, like rest
  window(2, 0, 2, 0.5, 6, true);  // the acceleration changes, declared rest: missed
  window(0, 0, 0, 0, 7, false);   // stop 2 (its first sample ends the motion), declared moving
  EXPECT_EQ(d.rest_windows(), 3u);
  EXPECT_EQ(d.false_alarms(), 2u);
  EXPECT_EQ(d.moving_windows(), 3u);
  EXPECT_EQ(d.missed(), 2u);
  EXPECT_EQ(d.moving_like_rest(), 1u);
  EXPECT_EQ(d.missed_like_rest(), 1u);
  EXPECT_EQ(d.mixed_windows(), 1u);
  EXPECT_EQ(d.mixed_declared_rest(), 0u);
  EXPECT_EQ(d.stops(), 2u);
  EXPECT_EQ(d.stops_seen(), 1u);
}

}  // namespace
}  // namespace gfins::sim
