#include "gfins/host_sim/adc_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/front_end.hpp"
#include "gfins/nav_core/geometry.hpp"

namespace gfins::sim {
namespace {

using Volts = Eigen::Matrix<double, 6, 1>;

// LSB of the default chain: 1.2 V · 8.33 / 2^23, V at the sensor.
constexpr double kDefaultLsbV = 1.2 * 8.33 / 8388608.0;
// The LSB is a quotient of a few doubles: 4 ulps relative.
constexpr double kLsbRel = 4.0 * std::numeric_limits<double>::epsilon();
// Rounding to nearest leaves at most ½ LSB; the product v·counts_per_volt adds ≤ 1 ulp of a
// number below 2^23, i.e. < 1e-9 LSB.
constexpr double kHalfLsbSlack = 1e-9;
// The front end's gain and offset products round at 1e-16 relative; 1e-6 of the half LSB is a
// margin far above that and far below anything a wrong LSB or scale factor would give.
constexpr double kFrontEndRounding = 1e-6;

Volts all(double v) { return Volts::Constant(v); }

TEST(AdcModelTest, LsbFollowsReferenceGainAndDivider) {
  // Given the default chain and one with gain 4 and no divider,
  const AdcModel def(AdcConfig{});
  AdcConfig c;
  c.gain = 4.0;
  c.input_divider = 1.0;
  const AdcModel g4(c);
  // then one count is vref/(gain·divider·2^23) volts at the sensor.
  EXPECT_NEAR(def.volts_per_count(), kDefaultLsbV, kLsbRel * kDefaultLsbV);
  EXPECT_NEAR(g4.volts_per_count(), 1.2 / (4.0 * 8388608.0), kLsbRel * kDefaultLsbV);
}

TEST(AdcModelTest, CodesAreWithinHalfAnLsbOfTheInput) {
  // Given the default chain and 10000 random volts across ±9.9 V,
  AdcModel adc(AdcConfig{});
  const double lsb = adc.volts_per_count();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-9.9, 9.9);
  double worst_lsb = 0.0;
  for (int i = 0; i < 10000; ++i) {
    const double v = u(rng);
    bool sat = true;
    // when converted,
    const std::int32_t code = adc.code_for(v, sat);
    // then the code times the LSB is within ½ LSB of the input and nothing saturates.
    worst_lsb = std::max(worst_lsb, std::abs(code * lsb - v) / lsb);
    EXPECT_FALSE(sat);
  }
  EXPECT_LE(worst_lsb, 0.5 + kHalfLsbSlack);
  // And the rounding is to nearest (0.49 LSB → 0, 0.51 LSB → 1), ties away from zero (checked
  // with vref 1 V and no divider, where the LSB is 2^-23 V and 2.5 LSB is exact in double).
  bool sat = false;
  EXPECT_EQ(adc.code_for(0.49 * lsb, sat), 0);
  EXPECT_EQ(adc.code_for(0.51 * lsb, sat), 1);
  EXPECT_EQ(adc.code_for(-0.51 * lsb, sat), -1);
  AdcConfig exact;
  exact.vref_v = 1.0;
  exact.input_divider = 1.0;
  const AdcModel binary(exact);
  EXPECT_EQ(binary.code_for(2.5 / 8388608.0, sat), 3);
  EXPECT_EQ(binary.code_for(-2.5 / 8388608.0, sat), -3);
}

TEST(AdcModelTest, NegativeInputsAreTwosComplementCodes) {
  // Given the default chain,
  AdcModel adc(AdcConfig{});
  const double lsb = adc.volts_per_count();
  // when −1 LSB and −1000 LSB are sampled on channels 0 and 1,
  Volts v = all(0.0);
  v(0) = -lsb;
  v(1) = -1000.0 * lsb;
  const RawSample s = adc.sample(v, 0);
  // then the counts are −1 (0xFFFFFF as 24 bits, sign-extended) and −1000.
  EXPECT_EQ(s.counts[0], -1);
  EXPECT_EQ(static_cast<std::uint32_t>(s.counts[0]) & 0xFFFFFFu, 0xFFFFFFu);
  EXPECT_EQ(s.counts[1], -1000);
  EXPECT_EQ(s.counts[2], 0);
}

TEST(AdcModelTest, InputsBeyondFullScaleClipAndFlagSaturation) {
  // Given the default ±9.996 V full scale,
  AdcModel adc(AdcConfig{});
  const double fs = adc.volts_per_count() * 8388608.0;
  // when +20 V, −20 V and NaN are sampled,
  Volts v = all(0.0);
  v(0) = 20.0;
  v(1) = -20.0;
  const RawSample s = adc.sample(v, 0);
  // then the codes are the rails and the sample is flagged saturated,
  EXPECT_EQ(s.counts[0], kAdcCodeMax);
  EXPECT_EQ(s.counts[1], kAdcCodeMin);
  EXPECT_NE(s.flags & sample_flags::kSaturated, 0u);
  bool sat = false;
  EXPECT_EQ(adc.code_for(std::numeric_limits<double>::quiet_NaN(), sat), 0);
  EXPECT_TRUE(sat);
  // while 0.999 of full scale is a plain code without the flag,
  const RawSample ok = adc.sample(all(0.999 * fs), 1);
  EXPECT_EQ(ok.flags & sample_flags::kSaturated, 0u);
  EXPECT_LT(ok.counts[0], kAdcCodeMax);
  // and the front end agrees that the clipped channels are saturated.
  nav::FrontEndParams<double> p;
  p.volts_per_count.fill(adc.volts_per_count());
  p.scale_v_per_g.fill(1.0);
  const auto fe = nav::FrontEnd<double>::create(p);
  ASSERT_TRUE(fe.is_ok());
  nav::FrontEnd<double>::Outputs out;
  EXPECT_EQ(fe.value().convert(s.counts, out), 0b11u);
  EXPECT_EQ(fe.value().convert(ok.counts, out), 0u);
}

TEST(AdcModelTest, DataReadyTimeIsSeqOverRatePlusGroupDelay) {
  // Given 1 kHz with a 250 µs group delay and no jitter,
  AdcConfig c;
  c.group_delay_ns = 250000;
  AdcModel adc(c);
  // then sample seq is stamped seq·1 ms + 250 µs, exactly, up to the top of the counter,
  EXPECT_EQ(adc.sample(all(0.0), 0).t_ns, 250000);
  EXPECT_EQ(adc.sample(all(0.0), 7).t_ns, 7250000);
  EXPECT_EQ(adc.sample(all(0.0), 0xFFFFFFFFu).t_ns, 4294967295000000ll + 250000);
  // and every sample says it is synthetic.
  EXPECT_NE(adc.sample(all(0.0), 1).flags & sample_flags::kSynthetic, 0u);
}

TEST(AdcModelTest, JitterHasTheConfiguredSigmaAndIsReproducible) {
  // Given 200 ns rms jitter,
  AdcConfig c;
  c.jitter_ns_rms = 200.0;
  AdcModel a(c), b(c);
  // when 20000 samples are stamped,
  constexpr int kN = 20000;
  double s2 = 0.0;
  bool same = true;
  for (std::uint32_t i = 0; i < kN; ++i) {
    const auto sa = a.sample(all(0.0), i);
    same = same && sa.t_ns == b.sample(all(0.0), i).t_ns;
    const double e = static_cast<double>(sa.t_ns - a.nominal_time_ns(i));
    s2 += e * e;
  }
  // then the deviation from the nominal edge has σ within 5 standard errors (σ/√(2N)) of 200 ns
  // (rounding to whole ns adds 1/12 ns², negligible), and the same seed gives the same stamps.
  EXPECT_NEAR(std::sqrt(s2 / kN), 200.0, 5.0 * 200.0 / std::sqrt(2.0 * kN));
  EXPECT_TRUE(same);
}

TEST(AdcModelTest, SensorAdcAndFrontEndCloseTheLoopWithinHalfAnLsb) {
  // Given Table 6 scale factors and biases without noise or misalignment, a tilted array at rest,
  // the default ADC and a front end configured with the same SF, b and volts_per_count(),
  ArrayErrors errors = SensorArrayModel::paper_table6();
  errors.misalignment = {};
  const auto gravity = nav::GravityModel<double>::constant(nav::kStandardGravity);
  SensorArrayModel sensors(nav::table1_geometry(0.1), errors, gravity, 1000.0, 9);
  AdcModel adc(AdcConfig{});
  nav::FrontEndParams<double> p;
  for (std::size_t j = 0; j < 6; ++j) {
    p.volts_per_count[j] = adc.volts_per_count();
    p.scale_v_per_g[j] = errors.sensors[j].scale_v_per_g;
    p.bias_g[j] = errors.sensors[j].bias_g;
  }
  const auto fe = nav::FrontEnd<double>::create(p);
  ASSERT_TRUE(fe.is_ok());
  const TruthState x =
      make_rest(Quatd(Eigen::AngleAxisd(0.7, Vec3d(1, -2, 0.5).normalized())))->at(0.0);
  // when the truth goes through sensors → ADC → front end,
  const RawSample s = adc.sample(sensors.volts(x), 0);
  nav::FrontEnd<double>::Outputs out;
  EXPECT_EQ(fe.value().convert(s.counts, out), 0u);
  // then each output is the sensed specific force within ½ LSB, i.e. ½·LSB·g/SF_j m/s² (the
  // only error left is quantisation).
  const Volts truth = sensors.ideal_specific_force(x);
  for (std::size_t j = 0; j < 6; ++j) {
    const double half_lsb_mps2 =
        0.5 * adc.volts_per_count() * nav::kStandardGravity / errors.sensors[j].scale_v_per_g;
    EXPECT_NEAR(out(static_cast<Eigen::Index>(j)), truth(static_cast<Eigen::Index>(j)),
                half_lsb_mps2 * (1.0 + kFrontEndRounding))
        << "sensor " << j + 1;
  }
}

TEST(AdcModelTest, NonPhysicalConfigurationsAreRefused) {
  // Given configurations with a zero reference, a negative gain, a zero rate, negative jitter,
  AdcConfig zero_vref;
  zero_vref.vref_v = 0.0;
  AdcConfig neg_gain;
  neg_gain.gain = -1.0;
  AdcConfig zero_rate;
  zero_rate.sample_rate_hz = 0.0;
  AdcConfig neg_jitter;
  neg_jitter.jitter_ns_rms = -1.0;
  // then no model is built from them.
  EXPECT_THROW(AdcModel{zero_vref}, std::invalid_argument);
  EXPECT_THROW(AdcModel{neg_gain}, std::invalid_argument);
  EXPECT_THROW(AdcModel{zero_rate}, std::invalid_argument);
  EXPECT_THROW(AdcModel{neg_jitter}, std::invalid_argument);
}

}  // namespace
}  // namespace gfins::sim
