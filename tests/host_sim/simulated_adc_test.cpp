// The real ADS131M06 driver on the register-level chip model (SimulatedAdc): the generic channel
// sweep (Zephyr's emulator pattern) and one test per injectable fault.
//
// The oracle of every code is computed here from the datasheet's transfer function (§8.5.1.9:
// 1 LSB = vref / (gain · 2^23), codes clip at 7FFFFFh / 800000h) and the front end's divider,
// never from the model's or the driver's helpers.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>

#include "gfins/host_sim/adc_model.hpp"
#include "gfins/host_sim/chip/simulated_adc.hpp"

namespace {

using gfins::ErrorCode;
using gfins::RawSample;
using gfins::Result;
using gfins::sim::SimulatedAdc;
using gfins::sim::SimulatedAdcConfig;
namespace flags = gfins::sample_flags;

constexpr double kVref = 1.2;
constexpr double kTwo23 = 8388608.0;
constexpr std::int64_t kPeriodNs = 1'000'000;  // 1 kHz
// A code and its oracle may differ by one count: the test computes v · divider · gain / vref ·
// 2^23 in a different order than the model, so a value within rounding error of a half-count
// tie can round either way. Anything more is a wrong scale, gain or sign extension.
constexpr std::int32_t kOneLsb = 1;

std::int32_t oracle_code(double sensor_v, double divider, int gain) {
  const double x = std::round(sensor_v * divider * gain / kVref * kTwo23);
  return static_cast<std::int32_t>(std::clamp(x, -kTwo23, kTwo23 - 1.0));
}

SimulatedAdcConfig config_with_gains(std::array<std::uint8_t, 6> gains) {
  SimulatedAdcConfig c;
  c.adc.pga_gain = gains;
  c.adc.verify_every_frames = 100;
  c.adc.stuck_after_frames = 20;
  return c;
}

class SimulatedAdcTest : public ::testing::Test {
 protected:
  void start(const SimulatedAdcConfig& c = config_with_gains({1, 1, 1, 1, 1, 1})) {
    config_ = c;
    adc_ = std::make_unique<SimulatedAdc>(c);
    ASSERT_TRUE(adc_->start().is_ok());
  }
  Result<RawSample> step(const std::array<double, 6>& v) {
    const std::uint32_t seq = seq_++;
    return adc_->convert(v, seq, static_cast<std::int64_t>(seq) * kPeriodNs);
  }
  // A slowly varying input so no channel repeats a code by accident (stuck detection).
  std::array<double, 6> wobble() const {
    std::array<double, 6> v{};
    for (int j = 0; j < 6; ++j) v[static_cast<std::size_t>(j)] = 0.5 + 0.01 * j + 1e-4 * seq_;
    return v;
  }
  SimulatedAdcConfig config_;
  std::unique_ptr<SimulatedAdc> adc_;
  std::uint32_t seq_ = 0;
};

TEST_F(SimulatedAdcTest, EveryChannelSweepsItsWholeRangeWithinOneLsb) {
  // Different gains per channel exercise both GAIN registers; the sweep spans 110 % of each
  // channel's full scale so both clip points are crossed.
  const std::array<std::uint8_t, 6> gains = {1, 2, 4, 8, 16, 128};
  start(config_with_gains(gains));
  constexpr int kSteps = 2001;
  for (int ch = 0; ch < 6; ++ch) {
    const double divider = config_.sensors[static_cast<std::size_t>(ch)].divider;
    const double fs_sensor_v = kVref / (gains[static_cast<std::size_t>(ch)] * divider);
    for (int k = 0; k < kSteps; ++k) {
      std::array<double, 6> v{};
      v.fill(0.01);
      v[static_cast<std::size_t>(ch)] = fs_sensor_v * (-1.1 + 2.2 * k / (kSteps - 1));
      const Result<RawSample> s = step(v);
      ASSERT_TRUE(s.is_ok()) << s.status().message();
      for (int j = 0; j < 6; ++j) {
        const auto ju = static_cast<std::size_t>(j);
        const std::int32_t want = oracle_code(v[ju], config_.sensors[ju].divider, gains[ju]);
        ASSERT_LE(std::abs(s->counts[ju] - want), kOneLsb) << "channel " << j << " step " << k;
      }
      const bool at_rail = std::fabs(v[static_cast<std::size_t>(ch)]) >= fs_sensor_v;
      EXPECT_EQ((s->flags & flags::kSaturated) != 0, at_rail) << "channel " << ch << " step " << k;
      EXPECT_NE(s->flags & flags::kSynthetic, 0u);
      EXPECT_EQ(s->seq, seq_ - 1);
    }
  }
  const auto& n = adc_->driver().counters();
  EXPECT_EQ(n.crc_errors + n.input_crc_errors + n.missed_edges + n.chip_resets, 0u);
  EXPECT_EQ(n.register_mismatches, 0u);  // 120 periodic re-verifications passed
}

TEST_F(SimulatedAdcTest, AgreesWithTheBehaviouralAdcModel) {
  // The host sample source used the behavioural AdcModel before; with the same reference, gain
  // and divider the register-level path must give the same codes (within the 1-LSB rounding).
  start();
  gfins::sim::AdcModel behavioural(gfins::sim::AdcConfig{});
  EXPECT_DOUBLE_EQ(adc_->volts_per_count(0), behavioural.volts_per_count());
  for (int k = 0; k < 500; ++k) {
    std::array<double, 6> v{};
    Eigen::Matrix<double, 6, 1> ve;
    for (int j = 0; j < 6; ++j) {
      v[static_cast<std::size_t>(j)] = 9.5 * std::sin(0.37 * k + j);
      ve(j) = v[static_cast<std::size_t>(j)];
    }
    const Result<RawSample> s = step(v);
    ASSERT_TRUE(s.is_ok());
    const RawSample b = behavioural.sample(ve, seq_ - 1);
    for (std::size_t j = 0; j < 6; ++j) ASSERT_LE(std::abs(s->counts[j] - b.counts[j]), kOneLsb);
  }
}

TEST_F(SimulatedAdcTest, OutputCrcCorruptionIsFlaggedAndCounted) {
  start();
  ASSERT_TRUE(step(wobble()).is_ok());
  adc_->chip().corrupt_output_crc(1);
  const Result<RawSample> bad = step(wobble());
  ASSERT_TRUE(bad.is_ok());
  EXPECT_NE(bad->flags & flags::kCrcError, 0u);
  const Result<RawSample> good = step(wobble());
  ASSERT_TRUE(good.is_ok());
  EXPECT_EQ(good->flags & flags::kCrcError, 0u);
  EXPECT_EQ(adc_->driver().counters().crc_errors, 1u);
}

TEST_F(SimulatedAdcTest, InputCrcErrorIsReportedByTheChipAndCounted) {
  start();
  ASSERT_TRUE(step(wobble()).is_ok());
  adc_->chip().corrupt_input_crc(1);  // the next NULL arrives with a bad CRC
  ASSERT_TRUE(step(wobble()).is_ok());
  ASSERT_TRUE(step(wobble()).is_ok());  // its STATUS carries CRC_ERR
  EXPECT_EQ(adc_->chip().input_crc_failures(), 1u);
  EXPECT_EQ(adc_->driver().counters().input_crc_errors, 1u);
  EXPECT_EQ(adc_->driver().state(), gfins::drivers::Ads131m06State::kRun);
}

TEST_F(SimulatedAdcTest, StuckChannelIsDetected) {
  start();
  adc_->chip().stick_channel(2, 1234);
  for (int k = 0; k < 25; ++k) {
    const Result<RawSample> s = step(wobble());
    ASSERT_TRUE(s.is_ok());
    EXPECT_EQ(s->counts[2], 1234);
  }
  EXPECT_EQ(adc_->driver().stuck_mask(), 1u << 2);  // after stuck_after_frames = 20
  EXPECT_EQ(adc_->driver().counters().stuck_events, 1u);
  adc_->chip().clear_channel_faults();
  ASSERT_TRUE(step(wobble()).is_ok());
  EXPECT_EQ(adc_->driver().stuck_mask(), 0u);
}

TEST_F(SimulatedAdcTest, SaturatedChannelIsFlagged) {
  start();
  adc_->chip().saturate_channel(4, /*positive=*/false);
  const Result<RawSample> s = step(wobble());
  ASSERT_TRUE(s.is_ok());
  EXPECT_EQ(s->counts[4], gfins::kAdcCodeMin);
  EXPECT_NE(s->flags & flags::kSaturated, 0u);
  EXPECT_EQ(adc_->driver().counters().saturated_samples, 1u);
}

TEST_F(SimulatedAdcTest, LostEdgesAreCountedAndTheSequenceStaysTheConversionIndex) {
  start();
  ASSERT_TRUE(step(wobble()).is_ok());
  adc_->drop_edges(2);
  EXPECT_EQ(step(wobble()).status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(step(wobble()).status().code(), ErrorCode::kUnavailable);
  const Result<RawSample> s = step(wobble());
  ASSERT_TRUE(s.is_ok());
  EXPECT_EQ(s->seq, 3u);
  EXPECT_EQ(adc_->driver().counters().missed_edges, 2u);
}

TEST_F(SimulatedAdcTest, ExtraEdgesAreSkipped) {
  start();
  ASSERT_TRUE(step(wobble()).is_ok());
  adc_->inject_extra_edges(2);
  for (int k = 0; k < 3; ++k) {
    const Result<RawSample> s = step(wobble());
    ASSERT_TRUE(s.is_ok()) << s.status().message();
    EXPECT_EQ(s->seq, seq_ - 1);  // numbering unaffected by the glitches
  }
  EXPECT_EQ(adc_->driver().counters().extra_edges, 2u);
  EXPECT_EQ(adc_->driver().counters().missed_edges, 0u);
}

TEST_F(SimulatedAdcTest, ChipResetMidRunIsDetectedAndTheConfigurationRestored) {
  // Gain 4 on channel 1: after a reset the chip is back at gain 1, so a sample with the right
  // code proves the driver wrote its table again.
  start(config_with_gains({1, 4, 1, 1, 1, 1}));
  ASSERT_TRUE(step(wobble()).is_ok());
  adc_->chip().power_on_reset();
  EXPECT_EQ(adc_->chip().gain(1), 1);
  EXPECT_EQ(step(wobble()).status().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(adc_->driver().counters().chip_resets, 1u);
  EXPECT_EQ(adc_->driver().counters().recoveries, 1u);
  const std::array<double, 6> v = wobble();
  const Result<RawSample> s = step(v);
  ASSERT_TRUE(s.is_ok());
  EXPECT_LE(std::abs(s->counts[1] - oracle_code(v[1], config_.sensors[1].divider, 4)), kOneLsb);
}

TEST_F(SimulatedAdcTest, HaltedConversionsTimeOutThenRecover) {
  start();
  ASSERT_TRUE(step(wobble()).is_ok());
  adc_->chip().halt_conversions(3);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(step(wobble()).status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(adc_->driver().counters().timeouts, 3u);
  EXPECT_EQ(adc_->driver().counters().recoveries, 1u);  // after timeouts_before_recover = 3
  const Result<RawSample> s = step(wobble());
  ASSERT_TRUE(s.is_ok());
  EXPECT_EQ(adc_->driver().counters().missed_edges, 3u);  // the sample clock ran on
}

TEST_F(SimulatedAdcTest, RegisterUpsetIsFoundByReVerification) {
  SimulatedAdcConfig c = config_with_gains({2, 2, 2, 2, 2, 2});
  c.adc.verify_every_frames = 1;  // every frame re-reads the next table register
  start(c);
  adc_->chip().upset_register(gfins::drivers::ads131m06::Reg::kGain1, 0x0000);
  bool recovered = false;
  for (int k = 0; k < 8 && !recovered; ++k) {
    const Result<RawSample> s = step(wobble());
    recovered = !s.is_ok() && s.status().code() == ErrorCode::kDataLoss;
  }
  EXPECT_TRUE(recovered);
  EXPECT_EQ(adc_->driver().counters().register_mismatches, 1u);
  EXPECT_EQ(adc_->chip().gain(0), 2);
}

}  // namespace

namespace {

TEST(SimulatedAdcConfig, MatchesTheBehaviouralParametersAndFindsAClock) {
  // 1 kHz: the nominal 8.192 MHz CLKIN and OSR 4096 (8.192 MHz / 2 / 4096 = 1000 Hz).
  auto c = SimulatedAdc::config_for(1.2, 1.0, 1.0 / 8.33, 1000.0);
  ASSERT_TRUE(c.is_ok());
  EXPECT_DOUBLE_EQ(c->adc.clkin_hz, 8.192e6);
  // 100 Hz is not reachable from 8.192 MHz (250 Hz is the slowest); the largest CLKIN below it
  // that makes 100 Hz exact is 2 · 100 · 16384 = 3.2768 MHz.
  c = SimulatedAdc::config_for(1.2, 2.0, 0.5, 100.0);
  ASSERT_TRUE(c.is_ok());
  EXPECT_DOUBLE_EQ(c->adc.clkin_hz, 3.2768e6);
  EXPECT_EQ(c->adc.pga_gain[5], 2);
  SimulatedAdc adc(c.value());
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_EQ(adc.driver().osr(), 16384u);
  EXPECT_DOUBLE_EQ(adc.volts_per_count(0), 1.2 / (2.0 * 8388608.0 * 0.5));
  EXPECT_FALSE(SimulatedAdc::config_for(1.2, 3.0, 1.0, 1000.0).is_ok());    // gain 3
  EXPECT_FALSE(SimulatedAdc::config_for(1.2, 1.0, 1.0, 100000.0).is_ok());  // > 32 kHz
}

}  // namespace
