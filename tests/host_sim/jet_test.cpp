#include "gfins/host_sim/jet.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

namespace gfins::sim {
namespace {

using J = Jet<double>;

// Each jet result goes through a handful of rounded operations on values of order one; 16 ulps
// of the size of the quantity covers that with room and is still 1e10 times smaller than any
// wrong derivative rule would give.
constexpr double kUlps = 16.0 * std::numeric_limits<double>::epsilon();

void expect_jet(const J& got, double f0, double f1, double f2) {
  EXPECT_NEAR(got.val, f0, kUlps * (1.0 + std::abs(f0)));
  EXPECT_NEAR(got.d1, f1, kUlps * (1.0 + std::abs(f1)));
  EXPECT_NEAR(got.d2, f2, kUlps * (1.0 + std::abs(f2)));
}

constexpr std::array<double, 5> kTimes = {-1.3, -0.2, 0.0, 0.7, 2.9};

TEST(JetTest, VariableAndConstantHaveTheRightDerivatives) {
  const J t = J::variable(0.4);
  expect_jet(t, 0.4, 1.0, 0.0);
  const J c = 3.5;
  expect_jet(c, 3.5, 0.0, 0.0);
}

TEST(JetTest, ProductAndQuotientMatchHandDerivatives) {
  // Given f(t) = t³ / (1 + t²) = t − t/(1 + t²):
  //   f' = 1 − (1 − t²)/(1 + t²)²,  f'' = (6t − 2t³)/(1 + t²)³.
  for (const double t0 : kTimes) {
    const J t = J::variable(t0);
    const J f = t * t * t / (1.0 + t * t);
    const double d = 1.0 + t0 * t0;
    expect_jet(f, t0 * t0 * t0 / d, 1.0 - (1.0 - t0 * t0) / (d * d),
               (6.0 * t0 - 2.0 * t0 * t0 * t0) / (d * d * d));
  }
}

TEST(JetTest, SumDifferenceAndScalarFormsAreLinear) {
  for (const double t0 : kTimes) {
    const J t = J::variable(t0);
    // f = 2t² − (t − 4)/2 + 3: f' = 4t − 1/2, f'' = 4.
    const J f = 2.0 * (t * t) - (t - 4.0) / 2.0 + 3.0;
    expect_jet(f, 2.0 * t0 * t0 - (t0 - 4.0) / 2.0 + 3.0, 4.0 * t0 - 0.5, 4.0);
    J g = t;
    g += t;
    g -= 0.5 * t;
    g *= t;
    g /= 3.0;  // g = t²/2
    expect_jet(g, 0.5 * t0 * t0, t0, 1.0);
    expect_jet(-g, -0.5 * t0 * t0, -t0, -1.0);
  }
}

TEST(JetTest, SinAndCosOfAComposedArgumentFollowTheChainRule) {
  // Given f(t) = sin(w t²): f' = 2wt cos(w t²), f'' = 2w cos(w t²) − 4w²t² sin(w t²).
  const double w = 1.7;
  for (const double t0 : kTimes) {
    const J t = J::variable(t0);
    const double u = w * (t0 * t0);  // the same rounding of the argument as the jet
    expect_jet(sin(w * (t * t)), std::sin(u), 2.0 * w * t0 * std::cos(u),
               2.0 * w * std::cos(u) - 4.0 * w * w * t0 * t0 * std::sin(u));
    // cos(w t²): f' = −2wt sin(u), f'' = −2w sin(u) − 4w²t² cos(u).
    expect_jet(cos(w * (t * t)), std::cos(u), -2.0 * w * t0 * std::sin(u),
               -2.0 * w * std::sin(u) - 4.0 * w * w * t0 * t0 * std::cos(u));
    J s;
    J c;
    sin_cos(w * (t * t), s, c);
    const J s_ref = sin(w * (t * t));
    const J c_ref = cos(w * (t * t));
    EXPECT_EQ(s.val, s_ref.val);
    EXPECT_EQ(s.d2, s_ref.d2);
    EXPECT_EQ(c.d1, c_ref.d1);
    EXPECT_EQ(c.d2, c_ref.d2);
  }
}

TEST(JetTest, SqrtAndExpMatchHandDerivatives) {
  const double tau = 0.8;
  for (const double t0 : kTimes) {
    const J t = J::variable(t0);
    // sqrt(1 + t²): f' = t/√(1+t²), f'' = (1+t²)^(−3/2).
    const double d = 1.0 + t0 * t0;
    expect_jet(sqrt(1.0 + t * t), std::sqrt(d), t0 / std::sqrt(d), 1.0 / (d * std::sqrt(d)));
    // exp(−t/τ): f' = −f/τ, f'' = f/τ².
    const double e = std::exp(-t0 / tau);
    expect_jet(exp(-t / tau), e, -e / tau, e / (tau * tau));
  }
}

}  // namespace
}  // namespace gfins::sim
