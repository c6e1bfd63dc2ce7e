// nav::sin_cos (math.hpp) for float, the core's own sine and cosine, against double's std::sin and
// std::cos evaluated at the same float argument (an independent implementation: glibc's).
// Bound 3e-7 absolute: the polynomials' truncation is below 7e-10, and each result carries the
// rounding of its reduction (|k| 2π split in two constants, exact products) and of about ten
// float operations on values up to 1, a few ulp of 6e-8 (measured: see the printed figure). A
// missing fold (π − y) or a dropped polynomial term leaves errors of 1e-3 or more.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "gfins/nav_core/math.hpp"

namespace gfins::nav {
namespace {

constexpr double kMaxAbsError = 3e-7;

TEST(SinCos, FloatIsWithinAFewUlpOfTheExactValuesOverTheCoresAngles) {
  double worst = 0;
  float worst_x = 0;
  // 2,000,001 points over [−100, 100] rad, plus the fold and reduction boundaries.
  auto check = [&](float x) {
    float s = 0;
    float c = 0;
    sin_cos(x, s, c);
    const double xs = static_cast<double>(x);
    const double e = std::max(std::abs(static_cast<double>(s) - std::sin(xs)),
                              std::abs(static_cast<double>(c) - std::cos(xs)));
    if (!(e <= worst)) {
      worst = e;
      worst_x = x;
    }
  };
  for (int i = -1'000'000; i <= 1'000'000; ++i) check(static_cast<float>(i) * 1e-4F);
  const double kPi = 3.14159265358979323846;
  for (int m = -64; m <= 64; ++m) {
    const auto b = static_cast<float>(m * kPi / 2);
    check(std::nextafter(b, -1e9F));
    check(b);
    check(std::nextafter(b, 1e9F));
  }
  std::printf("sin_cos<float>: worst |error| %.3g at x = %.9g\n", worst,
              static_cast<double>(worst_x));
  EXPECT_LE(worst, kMaxAbsError) << "at x = " << worst_x;
}

TEST(SinCos, SmallAnglesKeepTheirRelativeAccuracy) {
  // sin x ≈ x: the relative error of the sine near 0 stays at float's rounding (a polynomial
  // without the leading y factor would not).
  for (float x = 1e-30F; x < 1e-2F; x *= 3.7F) {
    float s = 0;
    float c = 0;
    sin_cos(x, s, c);
    EXPECT_NEAR(static_cast<double>(s) / std::sin(static_cast<double>(x)), 1.0, 2.5e-7) << x;
    EXPECT_NEAR(static_cast<double>(c), std::cos(static_cast<double>(x)), 1.2e-7) << x;
  }
}

TEST(SinCos, NotFiniteOrBeyondTwoToTheTwelveTurnsIsNotAvailable) {
  for (float x : {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                  std::numeric_limits<float>::quiet_NaN(), 25736.0F, -5e5F, 1048576.0F, -3e30F}) {
    float s = 0;
    float c = 0;
    sin_cos(x, s, c);
    EXPECT_TRUE(std::isnan(s) && std::isnan(c)) << x;
  }
}

TEST(SinCos, QuatFromEulerMatchesTheAxisProduct) {
  // The written-out Z-Y-X product against Eigen's AngleAxis product in double.
  for (double r = -3.0; r <= 3.0; r += 0.7) {
    for (double p = -1.5; p <= 1.5; p += 0.4) {
      for (double y = -3.1; y <= 3.1; y += 0.9) {
        const Quat<double> want(Eigen::AngleAxisd(y, Vec3<double>::UnitZ()) *
                                Eigen::AngleAxisd(p, Vec3<double>::UnitY()) *
                                Eigen::AngleAxisd(r, Vec3<double>::UnitX()));
        const Quat<double> got = quat_from_euler(r, p, y);
        // Coefficients up to the quaternion's sign: 1e-14 in double, 3e-7 (sin_cos's bound, a few
        // products) in float; |q·q'| − 1 would let 2.8e-3 rad through at 1e-6.
        const double sd = got.dot(want) < 0 ? -1.0 : 1.0;
        EXPECT_LT((sd * got.coeffs() - want.coeffs()).cwiseAbs().maxCoeff(), 1e-14)
            << r << " " << p << " " << y;
        const Quat<double> gf =
            quat_from_euler(static_cast<float>(r), static_cast<float>(p), static_cast<float>(y))
                .cast<double>();
        // The same angles as the float call, rounded to float, in double.
        const auto round_f = [](double a) { return static_cast<double>(static_cast<float>(a)); };
        const Quat<double> wf(Eigen::AngleAxisd(round_f(y), Vec3<double>::UnitZ()) *
                              Eigen::AngleAxisd(round_f(p), Vec3<double>::UnitY()) *
                              Eigen::AngleAxisd(round_f(r), Vec3<double>::UnitX()));
        const double sf = gf.dot(wf) < 0 ? -1.0 : 1.0;
        EXPECT_LT((sf * gf.coeffs() - wf.coeffs()).cwiseAbs().maxCoeff(), 1e-6)
            << r << " " << p << " " << y;
      }
    }
  }
}

}  // namespace
}  // namespace gfins::nav
