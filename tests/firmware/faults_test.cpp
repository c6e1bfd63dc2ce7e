// Fault injection on the simulated board (docs/faults.md): each fault is detected, counted,
// published (epoch health counters and status bits), logged, the loop keeps reading every edge
// that arrives, and navigation resumes or degrades as the fault table says. The oracle for
// "resumes" is the same scenario run without the fault: the faulty run's velocity stays within a
// bound derived from what the fault removes (one sample's worth of integration).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim_rig.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

constexpr double kRunSeconds = 6.0;
constexpr double kFaultAtSeconds = 2.0;  // faults are placed near seq 2000..3500
// "Navigation resumes": the faulty run stays within what losing k samples can do to a gyro-free
// INS at rest. A skipped sample integrates the next one over 2·dt, which changes ω by about
// dt·√2·σ_ω̇ per sample (the white noise of two samples instead of one) and that offset
// persists: the attitude error grows as δω·T and the gravity it leaks into the horizontal
// velocity as δv = g·δω·T²/2 over the T seconds left. With the rest scenario's 1 mg white noise
// per sensor, Chen's solver gives σ_ω̇ ≈ σ_s/ρ = 0.0098/0.1 ≈ 0.1 rad/s². The bound is 4σ of
// that for k samples: a fault handled wrongly (a saturated 10 g sample integrated once shifts ω
// by dt·10 g/ρ ≈ 1 rad/s, a velocity error of kilometres per second) is far outside it.
constexpr double kAngularAccelNoise = 0.1;  // rad/s², σ of one sample's ω̇
double resume_tolerance(double skipped_samples) {
  const double dt = 1e-3;
  const double t_left = kRunSeconds - kFaultAtSeconds;
  return 4.0 * nav::kStandardGravity * std::sqrt(2.0 * skipped_samples) * dt * kAngularAccelNoise *
         t_left * t_left / 2.0;
}

std::vector<std::string> lines_with(const std::vector<std::string>& lines, const std::string& key) {
  std::vector<std::string> out;
  for (const auto& l : lines) {
    if (l.find(key) != std::string::npos) out.push_back(l);
  }
  return out;
}

// The epoch of the first sample read at or after conversion `seq`.
const Epoch& epoch_at_seq(const SimRig& rig, std::uint32_t seq) {
  const auto& e = rig.recording->epochs();
  auto it = std::find_if(e.begin(), e.end(), [&](const Epoch& x) { return x.nav.seq >= seq; });
  if (it == e.end()) throw std::runtime_error("no epoch at that seq");
  return *it;
}

double velocity_difference(const SimRig& a, const SimRig& b) {
  const auto& va = a.loop->pipeline().state().v_n;
  const auto& vb = b.loop->pipeline().state().v_n;
  return static_cast<double>((va - vb).norm());
}

class Faults : public ::testing::Test {
 protected:
  void SetUp() override {
    baseline_ = std::make_unique<SimRig>("rest", kRunSeconds);
    baseline_->configure();
    baseline_->run();
    ASSERT_EQ(baseline_->loop->mode(), Mode::kNavigating);
  }
  SimRig& run(const sim_board::FaultPlan& f) {
    rig_ = std::make_unique<SimRig>("rest", kRunSeconds, f);
    rig_->configure();
    rig_->run();
    lines_ = rig_->drain_log();
    return *rig_;
  }
  std::unique_ptr<SimRig> baseline_;
  std::unique_ptr<SimRig> rig_;
  std::vector<std::string> lines_;
};

TEST_F(Faults, CrcErrorIsCountedRejectedPublishedLoggedAndNavigationResumes) {
  sim_board::FaultPlan f;
  f.crc_error_at = {2000, 2001, 3500};
  SimRig& rig = run(f);
  const HealthCounters& h = rig.loop->health();
  EXPECT_EQ(h.crc_errors, 3u);
  EXPECT_EQ(h.rejected_samples, 3u);
  EXPECT_EQ(h.samples, rig.samples);  // every edge read: the loop kept its rate
  EXPECT_NE(epoch_at_seq(rig, 2002).status_bits & status_bits::kCrcError, 0u);
  EXPECT_EQ(epoch_at_seq(rig, 2002).health.crc_errors, 2u);
  EXPECT_EQ(epoch_at_seq(rig, 2002).mode, Mode::kNavigating);  // a CRC error alone: not degraded
  EXPECT_EQ(rig.recording->epochs().back().status_bits & status_bits::kCrcError, 0u);  // expired
  EXPECT_FALSE(lines_with(lines_, "CRC").empty());
  EXPECT_EQ(rig.loop->mode(), Mode::kNavigating);
  EXPECT_LT(velocity_difference(rig, *baseline_), resume_tolerance(3));
}

TEST_F(Faults, MissingEdgesAreCountedAsGapsAndNavigationIntegratesAcross) {
  sim_board::FaultPlan f;
  f.missing_edges = {2500, 2501, 2502, 4000};
  SimRig& rig = run(f);
  const HealthCounters& h = rig.loop->health();
  EXPECT_EQ(h.missed_edges, 4u);
  EXPECT_EQ(h.samples, rig.samples - 4);
  EXPECT_EQ(rig.loop->pipeline().counters().gaps, 2u);
  EXPECT_EQ(rig.loop->pipeline().counters().missed_samples, 4u);
  EXPECT_NE(epoch_at_seq(rig, 2503).status_bits & status_bits::kSampleGap, 0u);
  EXPECT_EQ(lines_with(lines_, "missed").size(), 2u);
  EXPECT_EQ(rig.loop->mode(), Mode::kNavigating);
  EXPECT_LT(velocity_difference(rig, *baseline_), resume_tolerance(4));
}

TEST_F(Faults, ExtraEdgeIsCountedAndChangesNothingElse) {
  sim_board::FaultPlan f;
  f.extra_edge_after = {3000};
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().extra_edges, 1u);
  EXPECT_EQ(rig.loop->health().missed_edges, 0u);
  EXPECT_NE(epoch_at_seq(rig, 3002).status_bits & status_bits::kExtraEdge, 0u);
  EXPECT_FALSE(lines_with(lines_, "without a new conversion").empty());
  EXPECT_EQ(velocity_difference(rig, *baseline_), 0.0);  // the same samples reached the core
}

TEST_F(Faults, SilentDataReadyLineTimesOutDegradesThenResumes) {
  sim_board::FaultPlan f;
  f.silent_from = 2000;
  f.silent_edges = 9;  // three read timeouts of kReadTimeoutPeriods
  SimRig& rig = run(f);
  const HealthCounters& h = rig.loop->health();
  EXPECT_EQ(h.drdy_timeouts, 3u);
  EXPECT_EQ(h.missed_edges, 9u);
  EXPECT_EQ(epoch_at_seq(rig, 2009).mode, Mode::kDegraded);
  EXPECT_NE(epoch_at_seq(rig, 2009).status_bits & status_bits::kDataReadyLost, 0u);
  EXPECT_FALSE(lines_with(lines_, "no data-ready edge").empty());
  EXPECT_EQ(rig.loop->mode(), Mode::kNavigating);  // 1 s after the last timeout
  EXPECT_LT(velocity_difference(rig, *baseline_), resume_tolerance(9));
}

TEST_F(Faults, AdcResetMidRunIsCountedAndNavigationContinues) {
  sim_board::FaultPlan f;
  f.reset_at = 3000;
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().adc_resets, 1u);
  // The conversion the reset hit is lost: the driver reconfigures the chip in that read.
  EXPECT_EQ(rig.loop->health().missed_edges, 1u);
  EXPECT_NE(epoch_at_seq(rig, 3003).status_bits & status_bits::kAdcRecovered, 0u);
  EXPECT_FALSE(lines_with(lines_, "ADC reset").empty());
  EXPECT_EQ(rig.loop->mode(), Mode::kNavigating);
  EXPECT_LT(velocity_difference(rig, *baseline_), resume_tolerance(2));
}

TEST_F(Faults, StuckChannelIsDetectedAfterKSamplesDegradesAndClears) {
  sim_board::FaultPlan f;
  f.stuck_channel = 2;
  f.stuck_from = 2000;
  f.stuck_until = 2500;
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().stuck_events, 1u);
  // Not before K repeats, at K repeats: the code of 2000 repeated by 2001..2000+K.
  EXPECT_EQ(epoch_at_seq(rig, 2000 + kStuckSamples - 1).health.stuck_mask, 0u);
  const Epoch& stuck = epoch_at_seq(rig, 2000 + kStuckSamples);
  EXPECT_EQ(stuck.health.stuck_mask, 1u << 2);
  EXPECT_NE(stuck.status_bits & status_bits::kStuckChannel, 0u);
  EXPECT_EQ(stuck.mode, Mode::kDegraded);
  EXPECT_EQ(epoch_at_seq(rig, 2501).health.stuck_mask, 0u);  // moves again: cleared
  EXPECT_FALSE(lines_with(lines_, "stuck").empty());
  EXPECT_EQ(rig.loop->mode(), Mode::kNavigating);
}

TEST_F(Faults, SaturatedChannelIsRejectedDegradesAndNavigationResumes) {
  sim_board::FaultPlan f;
  f.saturated_channel = 0;
  f.saturated_from = 2000;
  f.saturated_until = 2010;
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().saturated_samples, 10u);
  EXPECT_EQ(rig.loop->health().rejected_samples, 10u);
  EXPECT_EQ(rig.loop->pipeline().counters().rejected, 10u);
  const Epoch& e = epoch_at_seq(rig, 2005);
  EXPECT_EQ(e.health.saturated_mask, 1u);
  EXPECT_EQ(e.mode, Mode::kDegraded);
  EXPECT_FALSE(lines_with(lines_, "full scale").empty());
  EXPECT_EQ(rig.loop->mode(), Mode::kNavigating);
  EXPECT_LT(velocity_difference(rig, *baseline_), resume_tolerance(10));
}

// Frames the publisher sends for the samples read in [first, last): its documented rule, every
// data message whose divider divides the sample counter (docs/can-interface.md).
std::uint32_t frames_for(const SimRig& rig, std::size_t first, std::size_t last) {
  std::uint32_t n = 0;
  for (std::size_t i = first; i < last; ++i) {
    for (std::uint16_t d : rig.config.dividers) {
      if (d != 0 && rig.tap->samples()[i].seq % d == 0) ++n;
    }
  }
  return n;
}

TEST(CanFaults, RefusingSinkAndBusOffAreCountedPublishedLoggedAndTheLoopKeepsReading) {
  SimRig rig("rest", 5.0);
  rig.configure();
  rig.run_cycles(2000);
  const std::size_t refuse_from = rig.tap->samples().size();
  rig.bus->refuse(true);
  rig.run_cycles(100);
  rig.bus->refuse(false);
  const std::size_t refuse_to = rig.tap->samples().size();
  rig.run_cycles(400);
  const std::size_t off_from = rig.tap->samples().size();
  rig.bus->bus_off(true);
  rig.run_cycles(200);
  rig.bus->bus_off(false);
  const std::size_t off_to = rig.tap->samples().size();
  rig.run();
  const auto lines = rig.drain_log();
  const HealthCounters& h = rig.loop->health();
  const std::uint32_t expected =
      frames_for(rig, refuse_from, refuse_to) + frames_for(rig, off_from, off_to);
  EXPECT_GT(expected, 100u);
  EXPECT_EQ(h.can_tx_dropped, expected);
  EXPECT_EQ(h.can_tx_dropped, rig.bus->counters().tx_dropped);
  EXPECT_EQ(h.bus_off_events, 1u);
  EXPECT_EQ(h.samples, rig.samples);
  EXPECT_NE(epoch_at_seq(rig, 2700).status_bits & status_bits::kBusOff, 0u);
  EXPECT_NE(epoch_at_seq(rig, 2200).status_bits & status_bits::kCanTxDrop, 0u);
  EXPECT_EQ(epoch_at_seq(rig, 2700).mode, Mode::kNavigating);  // CAN faults do not touch nav
  EXPECT_FALSE(lines_with(lines, "bus-off").empty());
  EXPECT_FALSE(lines_with(lines, "dropped").empty());
  // After the faults the bus carries frames again.
  EXPECT_GT(rig.bus->counters().tx_frames, 0u);
}

TEST(CanFaults, ReceivedFramesLostInTheKernelAreCountedFlaggedAndLogged) {
  // Given a navigating board
  SimRig rig("rest", 3.0);
  rig.configure();
  rig.run_cycles(2000);
  // When the kernel reports 3 received frames dropped, then 4 more a little later
  rig.bus->lose_received(3);
  rig.run_cycles(10);
  rig.bus->lose_received(4);
  rig.run();
  // Then the health counter has all 7, the status bit is set after the loss, one log line per
  // report, and navigation is untouched
  const auto lines = rig.drain_log();
  EXPECT_EQ(rig.loop->health().can_rx_dropped, 7u);
  EXPECT_EQ(epoch_at_seq(rig, 1990).status_bits & status_bits::kCanRxDrop, 0u);
  EXPECT_NE(epoch_at_seq(rig, 2100).status_bits & status_bits::kCanRxDrop, 0u);
  EXPECT_EQ(epoch_at_seq(rig, 2100).mode, Mode::kNavigating);
  EXPECT_EQ(lines_with(lines, "received CAN frame(s) lost").size(), 2u);
  EXPECT_FALSE(lines_with(lines, "(lost: 7)").empty());
}

}  // namespace
}  // namespace gfins::app
