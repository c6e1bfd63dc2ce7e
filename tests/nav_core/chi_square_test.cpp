// Normal and χ² quantiles (filter/chi_square.hpp) against tabulated values (Abramowitz & Stegun
// Table 26.8; any χ² table gives the same digits).
#include "gfins/nav_core/filter/chi_square.hpp"

#include <gtest/gtest.h>

namespace gfins::nav {
namespace {

// Tables print three decimals: half a unit of the last digit.
constexpr double kTableRounding = 5e-4;
// Acklam's approximation: relative error below 1.2e-9 (its published bound).
constexpr double kAcklamRel = 1.2e-9;
// Wilson–Hilferty: relative error of about 2 % at k = 3, p = 0.999 (its worst case among the
// filter's gates), below 0.1 % for k ≥ 30 (the known behaviour of the cube-root approximation).
constexpr double kWhRelSmallK = 0.02;
constexpr double kWhRelLargeK = 1e-3;

TEST(ChiSquareTest, NormalQuantileMatchesTable) {
  EXPECT_NEAR(normal_quantile(0.975), 1.959963985, 1.959963985 * kAcklamRel + 1e-9);
  EXPECT_NEAR(normal_quantile(0.999), 3.090232306, 3.090232306 * kAcklamRel + 1e-9);
  EXPECT_NEAR(normal_quantile(0.01), -2.326347874, 2.326347874 * kAcklamRel + 1e-9);
  EXPECT_NEAR(normal_quantile(0.5), 0.0, 1e-12);
  EXPECT_TRUE(std::isnan(normal_quantile(1.0)));
}

TEST(ChiSquareTest, ExactForOneAndTwoDegreesOfFreedom) {
  EXPECT_NEAR(chi_square_quantile(0.999, 1), 10.828, kTableRounding + 1e-8);
  EXPECT_NEAR(chi_square_quantile(0.95, 1), 3.841, kTableRounding + 1e-8);
  EXPECT_NEAR(chi_square_quantile(0.999, 2), 13.816, kTableRounding + 1e-8);
  EXPECT_NEAR(chi_square_quantile(0.99, 2), 9.210, kTableRounding + 1e-8);
}

TEST(ChiSquareTest, WilsonHilfertyWithinItsKnownError) {
  EXPECT_NEAR(chi_square_quantile(0.999, 3), 16.266, 16.266 * kWhRelSmallK);
  EXPECT_NEAR(chi_square_quantile(0.99, 30), 50.892, 50.892 * kWhRelLargeK);
  EXPECT_NEAR(chi_square_quantile(0.95, 10), 18.307, 18.307 * kWhRelSmallK);
  EXPECT_NEAR(chi_square_quantile(0.975, 100), 129.561, 129.561 * kWhRelLargeK);
  EXPECT_NEAR(chi_square_quantile(0.025, 100), 74.222, 74.222 * kWhRelLargeK);
  EXPECT_NEAR(chi_square_quantile(0.99, 100), 135.807, 135.807 * kWhRelLargeK);
}

TEST(ChiSquareTest, FloatAgreesWithDouble) {
  // float: p = 0.999 itself rounds by up to 3e-8, i.e. 3e-5 of the tail 1 − p, which moves the
  // quantile by about 1e-5 relative (measured 1.2e-5 at k = 1); 5e-5 covers it and the rounding
  // of the terms (6e-8 each).
  constexpr double kFloatRel = 5e-5;
  for (const int k : {1, 2, 3, 297}) {
    const double d = chi_square_quantile(0.999, k);
    EXPECT_NEAR(static_cast<double>(chi_square_quantile(0.999F, k)), d, d * kFloatRel) << k;
  }
}

TEST(ChiSquareTest, RejectsBadArguments) {
  EXPECT_TRUE(std::isnan(chi_square_quantile(0.5, 0)));
  EXPECT_TRUE(std::isnan(chi_square_quantile(1.5, 3)));
}

}  // namespace
}  // namespace gfins::nav
