#include "gfins/nav_core/front_end.hpp"

#include <gtest/gtest.h>

#include <string>

namespace gfins::nav {
namespace {

FrontEndParams<double> paper_like_params() {
  FrontEndParams<double> p;
  // ±10 V input range (divider before an ADS131M06-class converter): 10 / 2^23 V per count.
  p.volts_per_count.fill(10.0 / 8388608.0);
  p.scale_v_per_g = {0.509874, 0.332572, 0.500242, 2.493301, 0.339215, 2.476663};  // Table 6
  p.bias_g = {-0.000731, -0.000242, 0.000867, -0.007977, -0.000891, -0.004691};    // Table 6
  return p;
}

// One count of a 24-bit converter is the conversion's resolution; round trip error is below it.
constexpr double kOneCountTol = 1e-9;

TEST(FrontEndTest, ConvertsCountsThroughScaleFactorAndBias) {
  const auto fe = FrontEnd<double>::create(paper_like_params());
  ASSERT_TRUE(fe.is_ok());
  // Given a specific force of 0.5 g along sensor 3's axis, the QA-1100 gives
  // P = SF (f·θ + b) volts (eq. (21)); the ADC turns that into counts.
  const auto& p = fe->params();
  const double f_g = 0.5;
  const double volts = p.scale_v_per_g[2] * (f_g + p.bias_g[2]);
  std::array<std::int32_t, 6> counts{};
  counts[2] = static_cast<std::int32_t>(std::lround(volts / p.volts_per_count[2]));
  Vec6<double> s;
  EXPECT_EQ(fe->convert(counts, s), 0u);
  EXPECT_NEAR(s(2), f_g * kStandardGravity, 2 * p.volts_per_count[2] / p.scale_v_per_g[2] * 9.81);
  // Zero counts read as minus the bias.
  EXPECT_NEAR(s(0), -p.bias_g[0] * kStandardGravity, kOneCountTol);
  EXPECT_NEAR(fe->counts_for(2, s(2)), counts[2], kOneCountTol * 1e6);
}

TEST(FrontEndTest, FlagsSaturatedChannels) {
  const auto fe = FrontEnd<float>::create(paper_like_params().cast<float>());
  ASSERT_TRUE(fe.is_ok());
  std::array<std::int32_t, 6> counts{};
  counts[1] = kAdcCodeMax;
  counts[4] = kAdcCodeMin;
  Vec6<float> s;
  EXPECT_EQ(fe->convert(counts, s), (1u << 1) | (1u << 4));
}

TEST(FrontEndTest, RejectsNonPositiveScaleFactor) {
  auto p = paper_like_params();
  p.scale_v_per_g[3] = 0.0;
  EXPECT_EQ(FrontEnd<double>::create(p).status().code(), ErrorCode::kInvalidArgument);
  p = paper_like_params();
  p.bias_g[0] = std::nan("");
  EXPECT_EQ(FrontEnd<double>::create(p).status().code(), ErrorCode::kInvalidArgument);
  p = paper_like_params();
  p.volts_per_count[5] = -1e-7;
  EXPECT_EQ(FrontEnd<double>::create(p).status().code(), ErrorCode::kInvalidArgument);
}

// Each value a positive normal float, their gain LSB*g/SF not: 1e-30 V/count over 1e10 V/g is
// 1e-39 m/s² per count, below float's smallest normal 1.18e-38 (and 1e-20 * 9.8 / 1e-20 * 1e30
// overflows). The double core holds both gains, so only the float core refuses.
TEST(FrontEndTest, RejectsAGainTheScalarTypeCannotHold) {
  auto p = paper_like_params();
  p.volts_per_count[2] = 1e-30;
  p.scale_v_per_g[2] = 1e10;
  EXPECT_TRUE(FrontEnd<double>::create(p).is_ok());
  const auto tiny = FrontEnd<float>::create(p.cast<float>());
  EXPECT_EQ(tiny.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(std::string(tiny.status().message()).find("gain"), std::string::npos);
  p = paper_like_params();
  p.volts_per_count[2] = 1e30;
  p.scale_v_per_g[2] = 1e-10;
  EXPECT_TRUE(FrontEnd<double>::create(p).is_ok());
  EXPECT_EQ(FrontEnd<float>::create(p.cast<float>()).status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace gfins::nav
