// Command execution in the sample loop (docs/firmware.md, "Commands"): each command valid and
// out of range; a rejected command changes nothing. The CAN round trip (frames in, response
// frames out) is in can_round_trip_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "sim_rig.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

class Commands : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = std::make_unique<SimRig>("rest", 8.0);
    rig_->configure();
    rig_->run_cycles(1500);  // aligned and navigating
    ASSERT_EQ(rig_->loop->mode(), can::Mode::kNavigating);
  }
  can::Response exec(const can::Command& c) {
    SampleLoop::CommandReply r;
    rig_->loop->execute(c, r);
    return r.response;
  }
  std::unique_ptr<SimRig> rig_;
};

TEST_F(Commands, RealignRestartsAlignmentWithTheGivenHeading) {
  can::Command c;
  c.opcode = can::Opcode::kRealign;
  c.token = 7;
  c.heading_rad = 0.5f;
  const can::Response r = exec(c);
  EXPECT_EQ(r.result, can::ResultCode::kOk);
  EXPECT_EQ(r.token, 7);
  rig_->run_cycles(1);
  EXPECT_EQ(rig_->loop->mode(), can::Mode::kAligning);
  rig_->run_cycles(1100);
  ASSERT_EQ(rig_->loop->mode(), can::Mode::kNavigating);
  EXPECT_FLOAT_EQ(rig_->loop->pipeline().config().heading_rad, 0.5f);
}

TEST_F(Commands, RealignWithAnOutOfRangeHeadingChangesNothing) {
  can::Command c;
  c.opcode = can::Opcode::kRealign;
  c.heading_rad = 4.0f;  // beyond ±π (the command's Heading signal, docs/can-interface.md)
  const std::uint32_t errors = rig_->loop->health().command_errors;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOutOfRange);
  EXPECT_EQ(rig_->loop->health().command_errors, errors + 1);
  rig_->run_cycles(1);
  EXPECT_EQ(rig_->loop->mode(), can::Mode::kNavigating);
  c.heading_rad = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(exec(c).result, can::ResultCode::kOutOfRange);
}

TEST_F(Commands, ResetNavigationRealignsWithTheConfiguredHeading) {
  can::Command c;
  c.opcode = can::Opcode::kResetNavigation;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOk);
  rig_->run_cycles(1);
  EXPECT_EQ(rig_->loop->mode(), can::Mode::kAligning);
  EXPECT_FLOAT_EQ(rig_->loop->pipeline().config().heading_rad, 0.0f);
}

TEST_F(Commands, SetCompensatorSwitchesWithoutInterruptingNavigation) {
  can::Command c;
  c.opcode = can::Opcode::kSetCompensator;
  c.compensator = nav::CompensatorKind::kExact;
  const auto v_before = rig_->loop->pipeline().state().v_n;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOk);
  EXPECT_EQ(rig_->loop->pipeline().config().compensator, nav::CompensatorKind::kExact);
  // Navigation continues from the same state (no re-alignment): velocity unchanged at the switch.
  EXPECT_EQ(rig_->loop->pipeline().phase(), nav::PipelinePhase::kNavigating);
  EXPECT_EQ(rig_->loop->pipeline().state().v_n, v_before);
  rig_->run_cycles(10);
  EXPECT_EQ(rig_->loop->mode(), can::Mode::kNavigating);
}

TEST_F(Commands, SetCompensatorOutOfRangeChangesNothing) {
  can::Command c;
  c.opcode = can::Opcode::kSetCompensator;
  c.compensator = static_cast<nav::CompensatorKind>(9);
  const auto before = rig_->loop->pipeline().config().compensator;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOutOfRange);
  EXPECT_EQ(rig_->loop->pipeline().config().compensator, before);
}

TEST_F(Commands, SetDividerValidAndOutOfRange) {
  can::Command c;
  c.opcode = can::Opcode::kSetDivider;
  c.message = static_cast<can::MessageId>(3);
  c.divider = 50;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOk);
  c.message = static_cast<can::MessageId>(kNumMessages);
  EXPECT_EQ(exec(c).result, can::ResultCode::kOutOfRange);
  c.message = static_cast<can::MessageId>(3);
  c.divider = kMaxDivider + 1;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOutOfRange);
  // Switching the epoch (and with it the status) off is refused: the board never goes silent.
  // Every other data message is switched off first, so that no multiple-of-the-epoch rule is
  // what refuses it.
  c.divider = 0;
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    c.message = static_cast<can::MessageId>(m);
    if (c.message == can::MessageId::kEpoch || c.message == can::MessageId::kStatus) continue;
    ASSERT_EQ(exec(c).result, can::ResultCode::kOk) << kMessageNames[m];
  }
  c.message = can::MessageId::kEpoch;
  const std::uint32_t errors = rig_->loop->health().command_errors;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOutOfRange);
  EXPECT_EQ(rig_->loop->health().command_errors, errors + 1);
  const std::uint64_t frames = rig_->bus->total();
  rig_->run_cycles(100);
  // Epoch + status every 10 samples and nothing else: 20 frames in any 100 samples.
  EXPECT_EQ(rig_->bus->total(), frames + 20);
}

// The rig's budget is the board's default (1 kHz, 500 kbit/s, 50 %: 250,000 bit/s, 1,851.85
// frames/s of 135 worst-case bits). Aiding off, the defaults send 902 frames/s. Epoch (and status)
// at divider 5: 200 + 200 + 6 x 100 + 2 x 50 + 2 x 1 = 1,102 frames/s (29.8 %); five of the six
// 100 Hz messages to 200 Hz: 1,602 (43.3 %); the sixth: 1,702 (46.0 %) still fits, a seventh
// message on at 200 Hz (sensors A, +200: 1,902, 51.4 %) does not: refused with BusLoad, counted,
// its divider unchanged.
TEST_F(Commands, SetDividerBeyondTheBusBudgetIsRefusedWithBusLoad) {
  can::Command c;
  c.opcode = can::Opcode::kSetDivider;
  c.message = can::MessageId::kEpoch;
  c.divider = 5;
  ASSERT_EQ(exec(c).result, can::ResultCode::kOk);
  for (const can::MessageId m :
       {can::MessageId::kQuaternion, can::MessageId::kRate, can::MessageId::kAccel,
        can::MessageId::kVelocity, can::MessageId::kPositionNE, can::MessageId::kPositionD}) {
    c.message = m;
    ASSERT_EQ(exec(c).result, can::ResultCode::kOk) << static_cast<int>(m);
  }
  const std::uint32_t errors = rig_->loop->health().command_errors;
  c.message = can::MessageId::kSensorsA;
  EXPECT_EQ(exec(c).result, can::ResultCode::kBusLoad);
  EXPECT_EQ(rig_->loop->health().command_errors, errors + 1);
  EXPECT_EQ(rig_->publisher->publisher().divider(can::MessageId::kSensorsA), 0);
  // At 10 ms it fits (+100: 1,802 frames/s, 48.7 %).
  c.divider = 10;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOk);
}

TEST_F(Commands, ReportCalibrationGivesTheIdentityInUse) {
  can::Command c;
  c.opcode = can::Opcode::kReportCalibrationId;
  const can::Response r = exec(c);
  EXPECT_EQ(r.result, can::ResultCode::kOk);
  // The identity itself goes out in the frame after the response (can_round_trip_test.cpp).
  EXPECT_EQ(rig_->loop->cal_id(), calib_file::cal_id_of(rig_->factory));
  EXPECT_TRUE(rig_->loop->calibrated());
}

TEST_F(Commands, CaptureAveragesNSamplesPerChannel) {
  can::Command c;
  c.opcode = can::Opcode::kStartCapture;
  c.pose = 4;
  c.samples = 500;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOk);
  EXPECT_TRUE(rig_->loop->capture_active());
  EXPECT_EQ(exec(c).result, can::ResultCode::kBusy);  // one capture at a time
  const std::size_t first = rig_->tap->samples().size();
  rig_->run_cycles(500);
  EXPECT_FALSE(rig_->loop->capture_active());
  const can::CaptureResult& cap = rig_->loop->last_capture();
  EXPECT_EQ(cap.pose, 4);
  EXPECT_EQ(cap.samples, 500);
  EXPECT_FALSE(cap.motion());
  // Oracle: the same statistics computed here from the raw samples the loop read.
  const auto& samples = rig_->tap->samples();
  ASSERT_EQ(samples.size(), first + 500);
  const double lsb = rig_->adc->volts_per_count();
  for (std::size_t j = 0; j < 6; ++j) {
    double sum = 0, sum2 = 0;
    for (std::size_t i = first; i < samples.size(); ++i) sum += samples[i].counts[j];
    const double mean = sum / 500.0;
    for (std::size_t i = first; i < samples.size(); ++i) {
      sum2 += (samples[i].counts[j] - mean) * (samples[i].counts[j] - mean);
    }
    const double sd = std::sqrt(sum2 / 499.0);
    EXPECT_EQ(cap.channels[j].count, 500u);
    EXPECT_FALSE(cap.channels[j].saturated);
    EXPECT_FALSE(cap.channels[j].motion);
    // float storage of the result: 2^-24 relative, plus the running-mean rounding
    EXPECT_NEAR(cap.channels[j].mean_counts, mean, 1e-6 * std::abs(mean) + 1e-3);
    EXPECT_NEAR(cap.channels[j].std_counts, sd, 1e-4 * sd);
    // The scenario's white noise is 1 mg per sensor: 1e-3 g · SF (V/g) / lsb (V/count) codes; the
    // sample standard deviation of N = 500 has a relative spread of 1/sqrt(2N) = 3.2 %: 15 % is
    // 4.7 sigma (false failure 2.6e-6 per channel).
    const double sigma_counts = 1e-3 * rig_->factory.sensors[j].scale_v_per_g / lsb;
    EXPECT_NEAR(cap.channels[j].std_counts, sigma_counts, 0.15 * sigma_counts);
  }
}

TEST_F(Commands, CaptureOutOfRangeIsRejected) {
  can::Command c;
  c.opcode = can::Opcode::kStartCapture;
  c.samples = 0;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOutOfRange);
  c.samples = 10;
  c.pose = can::kMaxCapturePose + 1;
  EXPECT_EQ(exec(c).result, can::ResultCode::kOutOfRange);
  EXPECT_FALSE(rig_->loop->capture_active());
}

TEST_F(Commands, ReloadWithoutAWorkerFailsAndKeepsTheCalibration) {
  can::Command c;
  c.opcode = can::Opcode::kReloadCalibration;
  const std::uint32_t id = rig_->loop->cal_id();
  EXPECT_EQ(exec(c).result, can::ResultCode::kFailed);
  EXPECT_EQ(rig_->loop->cal_id(), id);
}

// A new alignment while the vehicle moves would navigate from a wrong attitude: with aiding on,
// Realign and ResetNavigation are refused (kMoving, counted as a command error, navigation
// untouched) unless forced. The scenario says when the board moves: urban-stop-and-go stands
// 10 s and then 15 s (its first stop), then accelerates to 12 m/s in 5 s along a smooth profile,
// 4.5 m/s² at 27.5 s (|f| 1 m/s² above gravity: the standstill detector's gravity test; at a
// cruise's constant speed a straight stretch can look at rest to accelerometers, docs/math.md,
// "Standstill updates in motion").
TEST(CommandsWhileMoving, RealignAndResetAreRefusedWhileMovingUnlessForced) {
  SimRig rig("urban-stop-and-go", 29.0);
  rig.config.aiding = true;
  rig.cal = load_calibration(rig.config, rig.factory, &rig.factory).set;
  rig.configure();
  const auto exec = [&](can::Opcode op, bool forced) {
    can::Command c;
    c.opcode = op;
    c.forced = forced;
    SampleLoop::CommandReply r;
    rig.loop->execute(c, r);
    return r.response.result;
  };
  // At rest (5 s): a reset is carried out, and the board aligns again before it moves.
  rig.run_cycles(5000);
  ASSERT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  ASSERT_TRUE(rig.loop->pipeline().aiding().at_rest());
  EXPECT_EQ(exec(can::Opcode::kResetNavigation, false), can::ResultCode::kOk);
  rig.run_cycles(4000);
  ASSERT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  // Accelerating (27.5 s).
  rig.run_cycles(18500);
  ASSERT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  ASSERT_FALSE(rig.loop->pipeline().aiding().at_rest());
  const std::uint32_t errors = rig.loop->health().command_errors;
  EXPECT_EQ(exec(can::Opcode::kRealign, false), can::ResultCode::kMoving);
  EXPECT_EQ(exec(can::Opcode::kResetNavigation, false), can::ResultCode::kMoving);
  EXPECT_EQ(rig.loop->health().command_errors, errors + 2);
  rig.run_cycles(1);
  EXPECT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  // Forced, it is carried out; the window it starts (27.5-28.5 s, the acceleration falling from
  // 4.5 to 3.2 m/s²: its specific force scattered) is refused, and the log says why.
  EXPECT_EQ(exec(can::Opcode::kRealign, true), can::ResultCode::kOk);
  rig.run_cycles(1);
  EXPECT_EQ(rig.loop->mode(), can::Mode::kAligning);
  EXPECT_EQ(rig.loop->health().command_errors, errors + 2);
  (void)rig.drain_log();
  rig.run_cycles(1100);
  EXPECT_EQ(rig.loop->mode(), can::Mode::kAligning);
  bool said_why = false;
  for (const std::string& line : rig.drain_log()) {
    said_why = said_why || line.find(
                               "alignment window refused: the specific force scattered "
                               "beyond the limit (the board moved)") != std::string::npos;
  }
  EXPECT_TRUE(said_why);
}

}  // namespace
}  // namespace gfins::app
