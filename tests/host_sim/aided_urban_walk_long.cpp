// The built-in `urban-stop-and-go` (660 s: 15 s stops every 50 s, 12 m/s on a weaving road; 5 Hz
// receiver, 1.5 m / 0.1 m/s, 100 ms latency, lever arm) and `walk` (300 s at 1.4 m/s with a 1 s
// stop every 4 s; handheld receiver 1 Hz, 3 m / 0.2 m/s, 200 ms) scenarios through the host
// navigation loop with their [aiding] switched on, as `gfins-sim aided` runs them: the figures of
// docs/navigation-accuracy.md, held by bounds. QA-1100 model at 40 °C, float32 core. The oracle is
// each trajectory's analytic truth.
//
// Bounds, and where they come from:
//  - RMS over t ≥ 10 s: horizontal position ≤ 1.5 m and velocity ≤ 0.1 m/s (the aiding targets
//    for a 1.5 m / 0.1 m/s receiver; the walk's receiver is worse, the same bounds hold), heading
//    ≤ 1° (the target after the first turn). Measured urban 0.21 m, 0.066 m/s, 0.29°; walk 0.55 m,
//    0.018 m/s, 0.28°.
//  - roll and pitch RMS, each ≤ 0.3° (the target; measured urban 0.275° / 0.255°, walk 0.083° /
//    0.082°), and the tilt (the larger of the two at each sample) ≤ 0.5° on the drive (measured
//    0.34°) and ≤ 0.3° on the walk (0.10°): a filter that loses its tilt in the stops' braking
//    fails them.
//  - roll and pitch RMS within 1.25 times what the filter's covariance predicts for them (the RMS
//    of its own 1σ; measured ratios 1.10 and 1.05 urban, 0.94 walk): the covariance is a floor the
//    error meets, and with a receiver of 0.02 m/s instead of 0.1 m/s both the floor and the
//    error fall below 0.15° (measured 0.111° / 0.099°) — the tilt on a drive is set by the
//    receiver's velocity accuracy, not by the sensors (docs/navigation-accuracy.md).
//  - bounded over ten minutes (urban): the instantaneous errors at 60 s and 600 s, position ≤ 1.5 m
//    and velocity ≤ 0.3 m/s (one sample of an error whose RMS target is 0.1 m/s: three times it;
//    measured 0.101 m/s at 60 s, in a braking, and 0.042 m/s at 600 s); an error that grows with
//    time, as the unaided one does (kilometres by 60 s), fails them.
//  - every error component within the filter's 3σ in ≥ 98 % of the samples after 10 s (measured
//    99.5 % urban, 100 % walk; the samples are correlated in time, see aided_highway_long.cpp).
//  - negative control: the same drive unaided is kilometres off at 60 s (measured 2.4 km), so the
//    position bound cannot pass without the filter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gfins/host_sim/accuracy.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim {
namespace {

const std::string kScenarioDir = std::string(GFINS_TEST_DATA_DIR) + "/../../host_sim/scenarios";

constexpr double kPosRmsMaxM = 1.5;
constexpr double kVelRmsMaxMps = 0.1;
constexpr double kVelAtCheckpointMaxMps = 0.3;
constexpr double kHeadingRmsMaxDeg = 1.0;
constexpr double kTiltTargetDeg = 0.3;
constexpr double kUrbanTiltRmsMaxDeg = 0.5;
constexpr double kWithin3SigmaMin = 0.98;
constexpr double kUnaidedOffAt60sMinM = 1000.0;

constexpr double kFloorRatioMax = 1.25;
constexpr double kBetterReceiverMps = 0.02;
constexpr double kBetterReceiverTiltMaxDeg = 0.15;

AccuracyTracker run_aided(const std::string& name, bool aided, double sigma_vel_mps = 0) {
  auto s = load_scenario(name, kScenarioDir);
  EXPECT_TRUE(s.is_ok()) << s.error().message;
  Scenario sc = s.value();
  EXPECT_TRUE(sc.gnss.has_value()) << name;
  sc.aiding.enabled = aided;
  if (sigma_vel_mps > 0 && sc.gnss.has_value()) sc.gnss->sigma_vel_mps = sigma_vel_mps;
  AccuracyTracker acc({60.0, 600.0}, 10.0);
  StreamTargets t;
  t.uncompensated_run = false;
  t.accuracy = &acc;
  auto o = run_scenario_streamed(sc, t, {}, NavScalar::kFloat);
  EXPECT_TRUE(o.is_ok()) << o.error().message;
  return acc;
}

void expect_roll_pitch(const AccuracyTracker& acc, double max_deg) {
  const AccuracyTracker::RollPitch rp = acc.roll_pitch();
  EXPECT_LE(rp.roll_rms_deg, max_deg);
  EXPECT_LE(rp.pitch_rms_deg, max_deg);
  EXPECT_LE(rp.roll_rms_deg, kFloorRatioMax * rp.roll_sigma_rms_deg);
  EXPECT_LE(rp.pitch_rms_deg, kFloorRatioMax * rp.pitch_sigma_rms_deg);
  std::printf("roll / pitch RMS %.3f / %.3f deg, covariance %.3f / %.3f deg\n", rp.roll_rms_deg,
              rp.pitch_rms_deg, rp.roll_sigma_rms_deg, rp.pitch_sigma_rms_deg);
}

void expect_consistent(const AccuracyTracker& acc) {
  ASSERT_GT(acc.sigma_samples(), 200000u);
  for (std::size_t k = 0; k < kConsistencyComponents; ++k) {
    EXPECT_GE(acc.within_3sigma(k), kWithin3SigmaMin) << kConsistencyNames[k];
  }
}

TEST(AidedUrban, TenMinutesOfStopAndGoStayWithinTheTargets) {
  const AccuracyTracker acc = run_aided("urban-stop-and-go", true);
  ASSERT_GT(acc.rms_samples(), 600000u);
  EXPECT_LE(acc.pos_h_rms_m(), kPosRmsMaxM);
  EXPECT_LE(acc.vel_rms_mps(), kVelRmsMaxMps);
  EXPECT_LE(acc.heading_rms_deg(), kHeadingRmsMaxDeg);
  EXPECT_LE(acc.tilt_rms_deg(), kUrbanTiltRmsMaxDeg);
  expect_roll_pitch(acc, kTiltTargetDeg);
  ASSERT_EQ(acc.checkpoints().size(), 2u);
  for (const ErrorSnapshot& at : acc.checkpoints()) {
    ASSERT_TRUE(at.seen) << at.t_s;
    EXPECT_LE(at.pos_h_m, kPosRmsMaxM) << "at " << at.t_s << " s";
    EXPECT_LE(at.vel_mps, kVelAtCheckpointMaxMps) << "at " << at.t_s << " s";
  }
  EXPECT_TRUE(std::isfinite(acc.worst().pos_h_m + acc.worst().tilt_deg));
  expect_consistent(acc);
  std::printf("urban aided: %s; at 600 s pos %.3f m, vel %.3f m/s\n", acc.describe_rms().c_str(),
              acc.checkpoints()[1].pos_h_m, acc.checkpoints()[1].vel_mps);
}

TEST(AidedUrban, TheTiltFloorFollowsTheReceiversVelocityAccuracy) {
  // Not checked for consistency here: with a receiver five times better the sensor model's
  // scale-factor drift at 40 °C (not among the filter's states) shows as 95.5 % coverage of the
  // down velocity and 95.9 % of the north position; at the calibration temperature, 25 °C, every
  // component is at 99.4 % or more (docs/navigation-accuracy.md).
  const AccuracyTracker acc = run_aided("urban-stop-and-go", true, kBetterReceiverMps);
  expect_roll_pitch(acc, kBetterReceiverTiltMaxDeg);
}

TEST(AidedUrban, UnaidedTheSameDriveIsKilometresOff) {
  const AccuracyTracker acc = run_aided("urban-stop-and-go", false);
  ASSERT_FALSE(acc.checkpoints().empty());
  const ErrorSnapshot& at60 = acc.checkpoints()[0];
  ASSERT_TRUE(at60.seen);
  // Non-finite counts as off: the unaided solution leaves the finite numbers within 100 s.
  EXPECT_FALSE(at60.pos_h_m <= kUnaidedOffAt60sMinM) << at60.pos_h_m;
  std::printf("urban unaided at 60 s: %.0f m\n", at60.pos_h_m);
}

TEST(AidedWalk, AStopEveryFourSecondsAndAHandheldReceiver) {
  const AccuracyTracker acc = run_aided("walk", true);
  ASSERT_GT(acc.rms_samples(), 280000u);
  EXPECT_LE(acc.pos_h_rms_m(), kPosRmsMaxM);
  EXPECT_LE(acc.vel_rms_mps(), kVelRmsMaxMps);
  EXPECT_LE(acc.heading_rms_deg(), kHeadingRmsMaxDeg);
  EXPECT_LE(acc.tilt_rms_deg(), kTiltTargetDeg);
  expect_roll_pitch(acc, kTiltTargetDeg);
  expect_consistent(acc);
  std::printf("walk aided: %s\n", acc.describe_rms().c_str());
}

// Standstill updates alone (the walk's receiver removed): the walk stands still for 1 s every 4 s
// (stops from 5 + 4 n to 6 + 4 n s). Checked at the end of every stop (5.9 + 4 n s) and in the
// middle of every stretch of walking (7.5 + 4 n s), n = 1..72:
//  - at each stop's end the velocity error is back to ≤ 0.01 m/s (the ZUPT's 1σ; measured at
//    most 0.0018 m/s); walking, ≤ 0.2 m/s (measured at most 0.066 m/s: 3 s of unaided motion);
//  - the tilt stays within the 0.3° target throughout (measured at most 0.036° at the stops and
//    0.11° walking): the stops' ZUPT and ZARU level the board and hold the rate;
//  - the position and heading are not observable without a receiver and drift (8.5 m and 2° after
//    250 s): not bounded here, and not claimed.
// Negative control: the same walk unaided is tens of degrees and metres per second off by the
// first checkpoint (measured 84° and 48 m/s at 10 s, docs/navigation-accuracy.md).
// Over a drive the stops are 35 s apart, and the tilt is lost on the way (AidedUrban below).
// The scenario `name` with its receiver removed, its errors at the instants `at`; standstill: the
// filter's standstill updates (the filter on when aided).
AccuracyTracker without_receiver(const std::string& name, const std::vector<double>& at, bool aided,
                                 bool standstill) {
  auto s = load_scenario(name, kScenarioDir);
  EXPECT_TRUE(s.is_ok()) << s.error().message;
  Scenario sc = s.value();
  sc.gnss.reset();
  sc.aiding.enabled = aided;
  sc.aiding.standstill = standstill;
  AccuracyTracker acc(at, 10.0);
  StreamTargets t;
  t.uncompensated_run = false;
  t.accuracy = &acc;
  auto o = run_scenario_streamed(sc, t, {}, NavScalar::kFloat);
  EXPECT_TRUE(o.is_ok()) << o.error().message;
  return acc;
}

std::vector<ErrorSnapshot> walk_without_receiver(bool aided) {
  std::vector<double> at;
  for (int n = 1; n <= 72; ++n) {
    at.push_back(5.9 + 4.0 * n);
    at.push_back(7.5 + 4.0 * n);
  }
  return without_receiver("walk", at, aided, true).checkpoints();
}

TEST(AidedWalk, StandstillUpdatesAloneResetTheVelocityAtEveryStopAndHoldTheTilt) {
  const std::vector<ErrorSnapshot> at = walk_without_receiver(true);
  ASSERT_EQ(at.size(), 144u);
  double stop_vel = 0, walk_vel = 0, tilt = 0;
  for (std::size_t i = 0; i < at.size(); ++i) {
    const ErrorSnapshot& e = at[i];
    ASSERT_TRUE(e.seen) << e.t_s;
    const bool stop = i % 2 == 0;
    EXPECT_LE(e.vel_mps, stop ? 0.01 : 0.2) << "at " << e.t_s << " s";
    EXPECT_LE(e.tilt_deg, kTiltTargetDeg) << "at " << e.t_s << " s";
    (stop ? stop_vel : walk_vel) = std::max(stop ? stop_vel : walk_vel, e.vel_mps);
    tilt = std::max(tilt, e.tilt_deg);
  }
  std::printf(
      "walk, standstill updates only: velocity at the stops' ends <= %.4f m/s, walking "
      "<= %.3f m/s, tilt <= %.3f deg\n",
      stop_vel, walk_vel, tilt);
}

// Standstill updates alone on the drive (urban-stop-and-go, its receiver removed): 35 s of
// driving on accelerometers alone between stops loses the tilt (tens of degrees, the filter's
// divergence restart), far outside what a ZUPT's linear model can bring back; each stop re-levels
// the board from its window of specific force (ErrorStateFilter::relevel_at_rest) and sets the
// velocity and rate to zero. Stops from 60 + 50 n to 75 + 50 n s (n = 0..11) and the first from 0
// to 25 s; checked 0.1 s before each ends:
//  - velocity error ≤ 0.01 m/s (the ZUPT's 1σ; measured at most 0.0008 m/s);
//  - tilt ≤ 0.3° (the roll/pitch target; measured at most 0.034°, with the filter's roll 1σ at
//    0.029°, of the QA-1100 model's bias and its scale error at 40 °C);
//  - every published σ covers its error at 3σ in ≥ 98 % of the samples that have one.
// Negative control: the standstill updates off, the same stops are tens of degrees off.
AccuracyTracker urban_without_receiver(bool standstill) {
  std::vector<double> at{24.9};
  for (int n = 0; n <= 11; ++n) at.push_back(74.9 + 50.0 * n);
  return without_receiver("urban-stop-and-go", at, true, standstill);
}

TEST(AidedUrban, StandstillUpdatesAloneReLevelTheBoardAtEveryStop) {
  const AccuracyTracker acc = urban_without_receiver(true);
  // Every σ the board publishes over the run covers its error (3σ in ≥ 98 % of the samples that
  // have one, as for the aided runs): roll and pitch between a stop and the tilt's loss, the
  // velocity's N and E while the heading is unknown (with the ZUPT's σ kept as the board drives
  // off, 88-92 %).
  for (std::size_t k = 0; k < kConsistencyComponents; ++k) {
    EXPECT_GE(acc.within_3sigma(k), kWithin3SigmaMin) << kConsistencyNames[k];
  }
  const std::vector<ErrorSnapshot>& at = acc.checkpoints();
  ASSERT_EQ(at.size(), 13u);
  double vel = 0, tilt = 0;
  for (const ErrorSnapshot& e : at) {
    ASSERT_TRUE(e.seen) << e.t_s;
    EXPECT_LE(e.vel_mps, 0.01) << "at " << e.t_s << " s";
    EXPECT_LE(e.tilt_deg, kTiltTargetDeg) << "at " << e.t_s << " s";
    vel = std::max(vel, e.vel_mps);
    tilt = std::max(tilt, e.tilt_deg);
  }
  std::printf(
      "urban, standstill updates only: at the stops' ends velocity <= %.4f m/s, tilt "
      "<= %.3f deg\n",
      vel, tilt);
}

TEST(AidedUrban, WithoutStandstillUpdatesTheStopsAreFarOff) {
  const std::vector<ErrorSnapshot> at = urban_without_receiver(false).checkpoints();
  ASSERT_GE(at.size(), 2u);
  // Non-finite counts as off.
  EXPECT_FALSE(at[1].tilt_deg <= kTiltTargetDeg) << at[1].tilt_deg;
  EXPECT_FALSE(at[1].vel_mps <= 0.01) << at[1].vel_mps;
}

TEST(AidedWalk, WithoutStandstillUpdatesTheSameWalkIsOffAtTheFirstStop) {
  const std::vector<ErrorSnapshot> at = walk_without_receiver(false);
  ASSERT_FALSE(at.empty());
  // Non-finite counts as off.
  EXPECT_FALSE(at[0].vel_mps <= 0.2) << at[0].vel_mps;
  EXPECT_FALSE(at[0].tilt_deg <= kTiltTargetDeg) << at[0].tilt_deg;
}

}  // namespace
}  // namespace gfins::sim
