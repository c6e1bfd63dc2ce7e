// Normal and χ² quantiles (filter/chi_square.hpp) against tabulated values (Abramowitz & Stegun
// Table 26.8; any χ² table gives the same digits).
#include "gfins/nav_core/filter/chi_square.hpp"

#include <gtest/gtest.h>

#include <cmath>

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

// P(χ²_k > x) by numerical integration of the density x^(k/2−1) e^(−x/2) / (2^(k/2) Γ(k/2)),
// written here (composite Simpson on [x, x + 600] in long double, 60,000 panels: error far below
// the 1e-6 relative checked).
double survival_by_integration(double x_in, int k) {
  const auto x = static_cast<long double>(x_in);
  const long double h = 600.0L / 60000.0L;
  const long double half_k = static_cast<long double>(k) / 2.0L;
  const long double log_norm = half_k * std::log(2.0L) + std::lgamma(half_k);
  const auto pdf = [&](long double u) {
    return std::exp((half_k - 1.0L) * std::log(u) - u / 2.0L - log_norm);
  };
  long double sum = pdf(x) + pdf(x + 600.0L);
  for (int i = 1; i < 60000; ++i) {
    sum += (i % 2 == 1 ? 4.0L : 2.0L) * pdf(x + static_cast<long double>(i) * h);
  }
  return static_cast<double>(sum * h / 3.0L);
}

TEST(ChiSquareTest, UpperQuantileHasTheStatedTailProbability) {
  // The detector's tails (1e-3 down to 1e-9) for the parity space's degrees of freedom and the
  // scatter test's: the survival at the returned x equals α to 1e-6 relative (bisection to double
  // resolution; the survival series is exact).
  for (const int k : {1, 2, 3, 4, 5, 6, 9, 57, 198}) {
    for (const double alpha : {1e-3, 1.4e-7, 1e-9}) {
      const double x = chi_square_upper_quantile(alpha, k);
      EXPECT_NEAR(survival_by_integration(x, k), alpha, 1e-6 * alpha) << k << " " << alpha;
      EXPECT_NEAR(chi_square_survival(x, k), alpha, 1e-9 * alpha) << k << " " << alpha;
    }
  }
  // Against the tables at p = 0.999 (A&S Table 26.8).
  EXPECT_NEAR(chi_square_upper_quantile(1e-3, 3), 16.266, kTableRounding);
  EXPECT_NEAR(chi_square_upper_quantile(1e-3, 5), 20.515, kTableRounding);
  EXPECT_NEAR(chi_square_upper_quantile(1e-3, 10), 29.588, kTableRounding);
  // float, the board's scalar: 1 − 1.4e-7 is not representable, the upper form still is.
  EXPECT_NEAR(static_cast<double>(chi_square_upper_quantile(1.4e-7F, 2)), -2.0 * std::log(1.4e-7),
              1e-5 * 31.6);
  EXPECT_TRUE(std::isnan(chi_square_upper_quantile(0.0, 3)));
  EXPECT_TRUE(std::isnan(chi_square_upper_quantile(1e-3, 0)));
  // Above 200 degrees of freedom, Wilson–Hilferty's upper-tail form: its x is slightly high, so
  // the tail at x is a little below α (measured 5 % below at k = 201, α = 1.4e-7; 2 % at 495):
  // a detector's false alarms stay at or under the stated rate. Bounds −8 %..+2 %; the 1 − α
  // form gave NaN in float, a sign error in z a tail near 1. Float too, where 1 − α is 1.
  for (const int k : {201, 297, 495}) {
    for (const double alpha : {1e-3, 1.4e-7}) {
      const double x = chi_square_upper_quantile(alpha, k);
      const double tail = survival_by_integration(x, k);
      EXPECT_GE(tail, 0.92 * alpha) << k << " " << alpha;
      EXPECT_LE(tail, 1.02 * alpha) << k << " " << alpha;
    }
    const float xf = chi_square_upper_quantile(1e-9F, k);
    EXPECT_TRUE(std::isfinite(xf)) << k;
    EXPECT_NEAR(static_cast<double>(xf), chi_square_upper_quantile(1e-9, k), 1e-4 * k) << k;
  }
}

TEST(ChiSquareTest, RejectsBadArguments) {
  EXPECT_TRUE(std::isnan(chi_square_quantile(0.5, 0)));
  EXPECT_TRUE(std::isnan(chi_square_quantile(1.5, 3)));
}

}  // namespace
}  // namespace gfins::nav
