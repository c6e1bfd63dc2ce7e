// The QA-1100 analog front end: counts → volts → g per channel, checked against the arithmetic of
// the chain written out here (K1 · R_L scale factor, divider, ADS131M06 LSB §8.5.1.9) and against
// the nav core's FrontEnd and the behavioural AdcModel that already use the same numbers.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "gfins/drivers/qa1100_front_end.hpp"
#include "gfins/host_sim/adc_model.hpp"
#include "gfins/nav_core/front_end.hpp"

namespace {

using gfins::drivers::Ads131m06Config;
using gfins::drivers::Qa1100Channel;
using gfins::drivers::Qa1100FrontEnd;

constexpr double kRel = 1e-12;  // double rounding of a few products and quotients

TEST(Qa1100FrontEnd, DefaultChainNumbers) {
  const auto fe = Qa1100FrontEnd::create(Qa1100FrontEnd::Channels{}, Ads131m06Config{});
  ASSERT_TRUE(fe.is_ok());
  // LSB at the sensor: 1.2 V / 2^23 / (1 / 8.33) = 1.19162 µV.
  const double lsb = 1.2 / 8388608.0 * 8.33;
  EXPECT_NEAR(fe->volts_per_count(0), lsb, kRel * lsb);
  // SF = 1.33 mA/g · 1 kΩ = 1.33 V/g; counts per g = 1.33 / lsb ≈ 1.116e6.
  EXPECT_NEAR(fe->scale_v_per_g(0), 1.33, 1e-12);
  EXPECT_NEAR(fe->counts_per_g(0), 1.33 / lsb, kRel * 1.33 / lsb);
  // Full scale: 9.996 V / 1.33 V/g = 7.516 g — the ADC, not the ±60 g sensor, limits the range.
  EXPECT_NEAR(fe->full_scale_g(0), 8388607.0 * lsb / 1.33, 1e-9);
  EXPECT_EQ(fe->sensor_limit_code(0), gfins::kAdcCodeMax);
  // The behavioural ADC model used by the host so far has the same LSB.
  gfins::sim::AdcModel behavioural(gfins::sim::AdcConfig{});
  EXPECT_NEAR(fe->volts_per_count(0), behavioural.volts_per_count(), kRel * lsb);
}

TEST(Qa1100FrontEnd, SensorRangeLimitsTheCodeWhenTheAdcRangeIsWider) {
  // A 10 Ω load gives 13.3 mV/g: ±60 g = ±0.798 V < 1.2 V at the pins (divider 1), so codes
  // beyond 60 g mean the sensor saturated although the ADC did not.
  Qa1100FrontEnd::Channels ch{};
  for (auto& c : ch) {
    c.load_ohm = 10.0;
    c.divider = 1.0;
  }
  const auto fe = Qa1100FrontEnd::create(ch, Ads131m06Config{});
  ASSERT_TRUE(fe.is_ok());
  const double counts_per_g = 0.0133 / (1.2 / 8388608.0);
  EXPECT_EQ(fe->sensor_limit_code(0), static_cast<std::int32_t>(std::floor(60.0 * counts_per_g)));
  std::array<std::int32_t, 6> counts{};
  counts[3] = fe->sensor_limit_code(3) + 1;
  counts[5] = -fe->sensor_limit_code(5);  // exactly at the limit: still a measurement
  EXPECT_EQ(fe->saturated_mask(counts), 1u << 3);
  counts[0] = gfins::kAdcCodeMin;
  EXPECT_EQ(fe->saturated_mask(counts), (1u << 3) | 1u);
}

TEST(Qa1100FrontEnd, FeedsTheNavCoreFrontEnd) {
  // FrontEndParams from the front end: a code of 1 g must come out as 1 g (in m/s²) from the
  // nav core with zero bias.
  const auto fe = Qa1100FrontEnd::create(Qa1100FrontEnd::Channels{}, Ads131m06Config{});
  ASSERT_TRUE(fe.is_ok());
  gfins::nav::FrontEndParams<double, 6> p;
  for (int j = 0; j < 6; ++j) {
    p.volts_per_count[static_cast<std::size_t>(j)] = fe->volts_per_count(j);
    p.scale_v_per_g[static_cast<std::size_t>(j)] = fe->scale_v_per_g(j);
  }
  const auto nav_fe = gfins::nav::FrontEnd<double, 6>::create(p);
  ASSERT_TRUE(nav_fe.is_ok());
  std::array<std::int32_t, 6> counts{};
  counts.fill(static_cast<std::int32_t>(std::lround(fe->counts_per_g(0))));
  Eigen::Matrix<double, 6, 1> s;
  EXPECT_EQ(nav_fe->convert(counts, s), 0u);
  // Within half a count of quantisation: 0.5 / 1.116e6 g.
  const double half_count_g = 0.5 / fe->counts_per_g(0);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(s(j) / 9.80665, 1.0, half_count_g);
  EXPECT_NEAR(fe->specific_force_g(0, counts[0]), 1.0, half_count_g);
}

TEST(Qa1100FrontEnd, RejectsNonsense) {
  Qa1100FrontEnd::Channels ch{};
  ch[2].load_ohm = 0.0;
  EXPECT_FALSE(Qa1100FrontEnd::create(ch, Ads131m06Config{}).is_ok());
  Ads131m06Config c;
  c.pga_gain[1] = 3;
  EXPECT_FALSE(Qa1100FrontEnd::create(Qa1100FrontEnd::Channels{}, c).is_ok());
}

}  // namespace
