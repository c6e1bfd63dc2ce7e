#include "gfins/host_sim/sensor_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/misalignment.hpp"

namespace gfins::sim {
namespace {

constexpr double kG = nav::kStandardGravity;
constexpr double kRateHz = 1000.0;
constexpr double kRhoM = 0.1;
// Volts are a handful of rounded products of numbers ≤ 100; 64 ulps of 1 bounds that rounding.
constexpr double kRounding = 64.0 * std::numeric_limits<double>::epsilon();
// Statistical tests: a 5σ bound fails by chance with probability ≈ 6e-7 (and the seeds are
// fixed, so a pass is reproducible).
constexpr double kSigmas = 5.0;

const nav::GravityModel<double> kGravity = nav::GravityModel<double>::constant(kG);
const nav::ArrayGeometry<double, 6> kNominal = nav::table1_geometry(kRhoM);

Eigen::Index ix(std::size_t j) { return static_cast<Eigen::Index>(j); }

// The rest state with the body upright (level) or upside down (rolled by π).
TruthState rest(bool upside_down) {
  TruthState x;
  if (upside_down) x.q_nb = Quatd(Eigen::AngleAxisd(std::numbers::pi, Vec3d::UnitX()));
  return x;
}

// At rest with a constant kinematic acceleration a_n (m/s², NED), level.
TruthState accelerating(const Vec3d& a_n) {
  TruthState x;
  x.a_n = a_n;
  return x;
}

ArrayErrors errors_with(const AccelErrors& e) {
  ArrayErrors a;
  a.sensors.fill(e);
  return a;
}

TEST(SensorModelTest, ScaleFactorAndBiasAreRecoveredFromTwoOppositeAttitudes) {
  // Given Table 6 scale factors and biases, no noise and no misalignment,
  ArrayErrors errors = SensorArrayModel::paper_table6();
  errors.misalignment = {};
  SensorArrayModel model(kNominal, errors, kGravity, kRateHz, 1);
  // when the array is read upright and upside down (sensed inputs ±a_j),
  const auto up = rest(false);
  const auto down = rest(true);
  const auto p_up = model.volts(up);
  const auto p_down = model.volts(down);
  const Vec6d a_up = model.ideal_specific_force(up) / kG;
  const Vec6d a_down = model.ideal_specific_force(down) / kG;
  // then the two-point calibration gives back SF and b for every sensor with a non-zero input
  // (sensors 1 and 6 have a horizontal axis and see 0 g both ways: only their bias shows).
  for (std::size_t j = 0; j < 6; ++j) {
    const AccelErrors& e = errors.sensors[j];
    const double da = a_up(ix(j)) - a_down(ix(j));
    if (std::abs(da) > 0.5) {
      const double sf = (p_up(ix(j)) - p_down(ix(j))) / da;
      EXPECT_NEAR(sf, e.scale_v_per_g, kRounding * 10.0) << "sensor " << j + 1;
    }
    const double b = p_up(ix(j)) / e.scale_v_per_g - a_up(ix(j));
    EXPECT_NEAR(b, e.bias_g, kRounding * 10.0) << "sensor " << j + 1;
  }
}

TEST(SensorModelTest, SecondOrderNonlinearityIsEvenInTheInput) {
  // Given K2 = 20 µg/g² (QA-1100 class) and bias 0.5 mg,
  AccelErrors e;
  e.scale_v_per_g = 1.33;
  e.bias_g = 5e-4;
  e.k2_g_per_g2 = 20e-6;
  SensorArrayModel model(kNominal, errors_with(e), nav::GravityModel<double>::constant(0.0),
                         kRateHz, 2);
  // when the array accelerates at ±10 g along x (no gravity),
  const auto plus = accelerating(Vec3d(10.0 * kG, 0, 0));
  const auto minus = accelerating(Vec3d(-10.0 * kG, 0, 0));
  const auto p_plus = model.volts(plus);
  const auto p_minus = model.volts(minus);
  // then the even part of the output is SF·(K2 a² + b) and the odd part is SF·a.
  for (std::size_t j = 0; j < 6; ++j) {
    const double a = model.ideal_specific_force(plus)(ix(j)) / kG;
    const double even = 0.5 * (p_plus(ix(j)) + p_minus(ix(j))) / e.scale_v_per_g;
    const double odd = 0.5 * (p_plus(ix(j)) - p_minus(ix(j))) / e.scale_v_per_g;
    EXPECT_NEAR(even, e.k2_g_per_g2 * a * a + e.bias_g, kRounding * 100.0) << "sensor " << j + 1;
    EXPECT_NEAR(odd, a, kRounding * 100.0) << "sensor " << j + 1;
  }
}

TEST(SensorModelTest, WhiteNoiseHasTheConfiguredSigmaAndZeroMean) {
  // Given 1 mg of white noise (the paper's §6.3 figure) and nothing else,
  AccelErrors e;
  e.noise_g = 1e-3;
  SensorArrayModel model(kNominal, errors_with(e), kGravity, kRateHz, 3);
  const auto x = rest(false);
  const Vec6d a = model.ideal_specific_force(x) / kG;
  // when N samples are taken at rest,
  constexpr int kN = 20000;
  std::array<double, 6> sum{}, sum2{};
  for (int i = 0; i < kN; ++i) {
    const auto p = model.volts(x);
    for (std::size_t j = 0; j < 6; ++j) {
      const double n = p(ix(j)) - a(ix(j));
      sum[j] += n;
      sum2[j] += n * n;
    }
  }
  // then each sensor's sample σ is within 5 standard errors (σ/√(2N)) of the configured one and
  // its mean within 5 σ/√N of 0.
  for (std::size_t j = 0; j < 6; ++j) {
    const double mean = sum[j] / kN;
    const double sigma = std::sqrt(sum2[j] / kN - mean * mean);
    EXPECT_NEAR(sigma, e.noise_g, kSigmas * e.noise_g / std::sqrt(2.0 * kN)) << "sensor " << j + 1;
    EXPECT_NEAR(mean, 0.0, kSigmas * e.noise_g / std::sqrt(double{kN})) << "sensor " << j + 1;
  }
}

// Sample standard deviation of the increments of `w` over windows of `len` samples.
double increment_sigma(const std::vector<double>& w, std::size_t len, std::size_t& count) {
  double s2 = 0.0;
  count = 0;
  for (std::size_t k = len; k < w.size(); k += len, ++count) {
    const double d = w[k] - w[k - len];
    s2 += d * d;
  }
  return std::sqrt(s2 / static_cast<double>(count));
}

TEST(SensorModelTest, BiasRandomWalkGrowsAsTheSquareRootOfTime) {
  // Given a bias random walk of 50 µg/√s and no other error,
  AccelErrors e;
  e.bias_rw_g_per_sqrt_s = 50e-6;
  SensorArrayModel model(kNominal, errors_with(e), kGravity, kRateHz, 4);
  const auto x = rest(false);
  const Vec6d a = model.ideal_specific_force(x) / kG;
  // when 40 s are sampled at 1 kHz and the walk is read off the outputs,
  constexpr std::size_t kSteps = 40000;
  std::array<std::vector<double>, 6> w;
  for (std::size_t i = 0; i < kSteps; ++i) {
    const auto p = model.volts(x);
    for (std::size_t j = 0; j < 6; ++j) w[j].push_back(p(ix(j)) - a(ix(j)));
  }
  // then over windows of 10 ms and 160 ms the increments have σ = q·√t_window (variance ∝ t),
  // within 5 standard errors of a σ estimated from `count` independent increments.
  for (const std::size_t len : {std::size_t{10}, std::size_t{160}}) {
    const double expected = e.bias_rw_g_per_sqrt_s * std::sqrt(static_cast<double>(len) / kRateHz);
    double s2 = 0.0;
    std::size_t total = 0;
    for (std::size_t j = 0; j < 6; ++j) {
      std::size_t count = 0;
      const double s = increment_sigma(w[j], len, count);
      s2 += s * s * static_cast<double>(count);
      total += count;
    }
    const double sigma = std::sqrt(s2 / static_cast<double>(total));
    EXPECT_NEAR(sigma, expected, kSigmas * expected / std::sqrt(2.0 * static_cast<double>(total)))
        << "window " << len << " samples";
  }
}

TEST(SensorModelTest, TemperatureShiftsBiasAndScaleFactorByTheirCoefficients) {
  // Given the QA-1100 class temperature coefficients (30 µg/°C, 180 ppm/°C) and no noise,
  AccelErrors e = AccelErrors::qa1100_typical();
  e.noise_g = 0.0;
  e.bias_rw_g_per_sqrt_s = 0.0;
  e.k2_g_per_g2 = 0.0;
  ArrayErrors errors = errors_with(e);
  errors.temperature_c = 45.0;  // 20 °C above the 25 °C reference
  SensorArrayModel model(kNominal, errors, kGravity, kRateHz, 5);
  // when the two-point calibration of the first test is done at 45 °C,
  const auto up = rest(false);
  const auto down = rest(true);
  const auto p_up = model.volts(up);
  const auto p_down = model.volts(down);
  const Vec6d a_up = model.ideal_specific_force(up) / kG;
  const Vec6d a_down = model.ideal_specific_force(down) / kG;
  // then SF is 1 + 20·180 ppm = 1.0036 times the nominal one and the bias is 20·30 µg = 0.6 mg.
  const double sf_expected = e.scale_v_per_g * (1.0 + 20.0 * 180e-6);
  const double b_expected = 20.0 * 30e-6;
  for (const std::size_t j : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{4}}) {
    const double sf = (p_up(ix(j)) - p_down(ix(j))) / (a_up(ix(j)) - a_down(ix(j)));
    EXPECT_NEAR(sf, sf_expected, kRounding * 10.0) << "sensor " << j + 1;
    EXPECT_NEAR(p_up(ix(j)) / sf_expected - a_up(ix(j)), b_expected, kRounding * 10.0)
        << "sensor " << j + 1;
  }
  // and back at the reference temperature both return to nominal.
  model.set_temperature_c(25.0);
  const auto p_ref = model.volts(up);
  EXPECT_NEAR(p_ref(1), e.scale_v_per_g * a_up(1), kRounding * 10.0);
}

TEST(SensorModelTest, InputBeyondTheRangeIsClippedAtSaturation) {
  // Given the ±60 g range and no gravity,
  AccelErrors e;
  e.saturation_g = 60.0;
  SensorArrayModel model(kNominal, errors_with(e), nav::GravityModel<double>::constant(0.0),
                         kRateHz, 6);
  // when the array accelerates at 100 g along x (f_b = +a: sensors 1 and 2 sense +70.7 g,
  // sensors 5 and 6 −70.7 g, sensors 3 and 4 nothing),
  const auto x = accelerating(Vec3d(100.0 * kG, 0, 0));
  const auto p = model.volts(x);
  // then sensors past the range read exactly ±60 g and the others are unaffected,
  EXPECT_EQ(p(0), 60.0);
  EXPECT_EQ(p(1), 60.0);
  EXPECT_EQ(p(2), 0.0);
  EXPECT_EQ(p(3), 0.0);
  EXPECT_EQ(p(4), -60.0);
  EXPECT_EQ(p(5), -60.0);
  // and within the range (80 g → 56.6 g sensed) the output is linear again.
  const auto y = accelerating(Vec3d(80.0 * kG, 0, 0));
  EXPECT_NEAR(model.volts(y)(0), 80.0 / std::sqrt(2.0), kRounding * 100.0);
}

TEST(SensorModelTest, MisalignmentAndLocationErrorsEnterThroughTheRealGeometry) {
  // Given Table 6 orientation errors and a 2 mm location error of sensor 4, spinning at
  // 3 rad/s about z,
  ArrayErrors errors;
  errors.misalignment = SensorArrayModel::paper_table6().misalignment;
  errors.misalignment.drho_b[3] = Vec3d(0.002, -0.001, 0.0015);
  SensorArrayModel model(kNominal, errors, kGravity, kRateHz, 7);
  TruthState x;
  x.w_b = Vec3d(0, 0, 3.0);
  x.wdot_b = Vec3d(0.5, 0, 0);
  // when sampled,
  const auto p = model.volts(x);
  // then each output is θ*_j·(f + ω̇×ρ*_j + ω×(ω×ρ*_j)) with θ*, ρ* from misaligned_geometry,
  const auto real = nav::misaligned_geometry(kNominal, errors.misalignment);
  const Vec3d f_b(0, 0, -kG);
  for (std::size_t j = 0; j < 6; ++j) {
    const Vec3d& r = real.rho_b[j];
    const double s = real.theta_b[j].dot(f_b + x.wdot_b.cross(r) + x.w_b.cross(x.w_b.cross(r)));
    EXPECT_NEAR(p(ix(j)), s / kG, kRounding * 10.0) << "sensor " << j + 1;
  }
  // and the misaligned outputs differ from the ideal ones by more than rounding (Table 6 angles
  // are degrees: ≥ 1e-3 g here).
  const Vec6d ideal = model.ideal_specific_force(x) / kG;
  EXPECT_GT((p - ideal).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(SensorModelTest, SameSeedSameVoltsOtherSeedOtherVolts) {
  // Given two models with the same seed and one with another seed, all with noise,
  const ArrayErrors errors = errors_with(AccelErrors::qa1100_typical());
  SensorArrayModel a(kNominal, errors, kGravity, kRateHz, 42);
  SensorArrayModel b(kNominal, errors, kGravity, kRateHz, 42);
  SensorArrayModel c(kNominal, errors, kGravity, kRateHz, 43);
  const auto x = rest(false);
  // when sampled 100 times,
  bool all_equal_ab = true, any_diff_ac = false;
  for (int i = 0; i < 100; ++i) {
    const auto pa = a.volts(x);
    all_equal_ab = all_equal_ab && pa == b.volts(x);
    any_diff_ac = any_diff_ac || pa != c.volts(x);
  }
  // then same seed is bit-identical and another seed is not.
  EXPECT_TRUE(all_equal_ab);
  EXPECT_TRUE(any_diff_ac);
}

TEST(SensorModelTest, NonPositiveSampleRateIsRefused) {
  // Given a zero and a NaN sample rate, then no model is built (the walk step would be infinite).
  EXPECT_THROW(SensorArrayModel(kNominal, ArrayErrors{}, kGravity, 0.0, 1), std::invalid_argument);
  EXPECT_THROW(SensorArrayModel(kNominal, ArrayErrors{}, kGravity,
                                std::numeric_limits<double>::quiet_NaN(), 1),
               std::invalid_argument);
}

TEST(SensorModelTest, MakeRefusesTheSameRatesWithAValue) {
  // The simulated board's way (it runs inside gfins-fw, where nothing may throw).
  for (const double bad : {0.0, -1000.0, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    HostResult<SensorArrayModel> r = HostError{};
    EXPECT_NO_THROW(r = SensorArrayModel::make(kNominal, ArrayErrors{}, kGravity, bad, 1));
    ASSERT_FALSE(r.is_ok()) << bad;
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("sample rate"), std::string::npos) << r.error().message;
  }
  const auto good = SensorArrayModel::make(kNominal, ArrayErrors{}, kGravity, kRateHz, 1);
  ASSERT_TRUE(good.is_ok());
  EXPECT_EQ(good.value().sample_rate_hz(), kRateHz);
}

// --- channel failures
// ------------------------------------------------------------------------------ Each failure
// against the same model without it, same seed: identical volts before the onset (and on the other
// channels throughout), then the failure's own formula (sensor_model.hpp).

namespace failures {

constexpr double kSf = 1.33;      // V/g
constexpr double kNoiseG = 1e-4;  // white noise, g
constexpr double kOnsetS = 0.05;  // sample 50 at 1 kHz
constexpr int kSamples = 100;

struct Pair {
  std::vector<SensorArrayModel::Volts> clean;
  std::vector<SensorArrayModel::Volts> failed;
};

Pair run(const ChannelFailure& f) {
  AccelErrors e;
  e.scale_v_per_g = kSf;
  e.noise_g = kNoiseG;
  ArrayErrors clean = errors_with(e);
  ArrayErrors failed = clean;
  failed.failures.push_back(f);
  SensorArrayModel a(kNominal, clean, kGravity, kRateHz, 9);
  SensorArrayModel b(kNominal, failed, kGravity, kRateHz, 9);
  Pair p;
  for (int k = 0; k < kSamples; ++k) {
    // A slow tilt so that a stuck channel differs from a good one.
    TruthState x = rest(false);
    x.t_s = k / kRateHz;
    x.q_nb = Quatd(Eigen::AngleAxisd(0.5 * x.t_s, Vec3d::UnitX()));
    p.clean.push_back(a.volts(x));
    p.failed.push_back(b.volts(x));
  }
  return p;
}

// Sensor 3 (index 2) fails; the onset sample is 50.
constexpr std::size_t kCh = 2;
constexpr int kOnset = 50;

void expect_untouched_before_and_elsewhere(const Pair& p) {
  for (int k = 0; k < kSamples; ++k) {
    for (std::size_t j = 0; j < 6; ++j) {
      if (j == kCh && k >= kOnset) continue;
      EXPECT_EQ(p.failed[static_cast<std::size_t>(k)](ix(j)),
                p.clean[static_cast<std::size_t>(k)](ix(j)))
          << k << " " << j;
    }
  }
}

}  // namespace failures

TEST(SensorModelTest, BiasAndRampFailuresAddTheirBiasFromTheOnset) {
  using namespace failures;
  const Pair bias = run({ChannelFailureKind::kBias, kCh, kOnsetS, 2e-3});
  const Pair ramp = run({ChannelFailureKind::kRamp, kCh, kOnsetS, 0.1});
  expect_untouched_before_and_elsewhere(bias);
  expect_untouched_before_and_elsewhere(ramp);
  for (int k = kOnset; k < kSamples; ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_NEAR(bias.failed[i](ix(kCh)) - bias.clean[i](ix(kCh)), kSf * 2e-3, kRounding) << k;
    EXPECT_NEAR(ramp.failed[i](ix(kCh)) - ramp.clean[i](ix(kCh)),
                kSf * 0.1 * (k / kRateHz - kOnsetS), kRounding)
        << k;
  }
}

TEST(SensorModelTest, NoiseFailureScalesTheSameDraws) {
  using namespace failures;
  const Pair noisy = run({ChannelFailureKind::kNoise, kCh, kOnsetS, 8.0});
  expect_untouched_before_and_elsewhere(noisy);
  // No other error: volts = SF (a + n), so (failed − SF a) = 8 (clean − SF a), with SF a the
  // noise-free reading computed here from the truth.
  SensorArrayModel ideal(kNominal, errors_with([] {
                           AccelErrors e;
                           e.scale_v_per_g = kSf;
                           return e;
                         }()),
                         kGravity, kRateHz, 9);
  for (int k = 0; k < kSamples; ++k) {
    TruthState x = rest(false);
    x.t_s = k / kRateHz;
    x.q_nb = Quatd(Eigen::AngleAxisd(0.5 * x.t_s, Vec3d::UnitX()));
    const double sa = ideal.volts(x)(ix(kCh));
    if (k < kOnset) continue;
    const auto i = static_cast<std::size_t>(k);
    EXPECT_NEAR(noisy.failed[i](ix(kCh)) - sa, 8.0 * (noisy.clean[i](ix(kCh)) - sa), 1e-12) << k;
  }
}

TEST(SensorModelTest, StuckHoldsTheLastReadingDeadReadsZeroSaturationClips) {
  using namespace failures;
  const Pair stuck = run({ChannelFailureKind::kStuck, kCh, kOnsetS, 0.0});
  const Pair dead = run({ChannelFailureKind::kDead, kCh, kOnsetS, 0.0});
  // Sensor 3 senses (0, k, k)·f with f = (0, 0, −g) level (NED, at rest): −0.707 g; clipped at
  // −0.5 g from the onset.
  const Pair clipped = run({ChannelFailureKind::kSaturation, kCh, kOnsetS, 0.5});
  for (const Pair* p : {&stuck, &dead, &clipped}) expect_untouched_before_and_elsewhere(*p);
  const double held = stuck.clean[kOnset - 1](ix(kCh));
  for (int k = kOnset; k < kSamples; ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_EQ(stuck.failed[i](ix(kCh)), held) << k;
    EXPECT_EQ(dead.failed[i](ix(kCh)), 0.0) << k;
    // SF (−0.5 g + n): within 6 noise σ of −SF·0.5 g, at least 0.19 g above the clean reading.
    EXPECT_NEAR(clipped.failed[i](ix(kCh)), -kSf * 0.5, kSf * 6.0 * kNoiseG) << k;
    EXPECT_GT(clipped.failed[i](ix(kCh)), clipped.clean[i](ix(kCh)) + kSf * 0.19) << k;
  }
  // The stuck channel really is stuck while the truth moves (the tilt changes it by ~1e-3 g).
  EXPECT_GT(std::abs(stuck.clean[kSamples - 1](ix(kCh)) - held), kSf * 5e-4);
}

}  // namespace
}  // namespace gfins::sim
