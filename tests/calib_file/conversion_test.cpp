// A loaded calibration configures the navigation pipeline: units converted (degrees → radians),
// sensors and sets in the right places.
#include <gtest/gtest.h>

#include <numbers>

#include "calib_file/calib_test_data.hpp"
#include "gfins/calib_file/calibration_data.hpp"

namespace gfins::calib_file {
namespace {

using testing::table6_data;

// deg → rad is one multiplication in double: exact to half an ulp of the result.
constexpr double kRadTolerance = 1e-16;
// Float rounding of a value of magnitude ≤ 3 (SF) or ≤ 0.05 rad: half an ulp of float.
constexpr float kFloatRelTolerance = 6e-8f;

TEST(Conversion, AnglesBecomeRadiansInTheirSets) {
  // Given Table 6 (Δβ_xy = 1.117319°, Δα_zy = −1.451107°)
  const CalibrationData d = table6_data();
  // When converted to the navigation core's misalignment
  const nav::Misalignment<double> m = misalignment<double>(d);
  // Then the angles are radians, in AngleIndex order, per set
  EXPECT_NEAR(m.orientation.beta[0], 1.117319 * std::numbers::pi / 180.0, kRadTolerance);
  EXPECT_NEAR(m.orientation.alpha[5], -1.451107 * std::numbers::pi / 180.0, kRadTolerance);
  EXPECT_NEAR(m.orientation.alpha[static_cast<std::size_t>(nav::AngleIndex::kXz)],
              2.596778 * std::numbers::pi / 180.0, kRadTolerance);
  EXPECT_EQ(m.drho_b[3].x(), d.sensors[3].location_error_m[0]);
  EXPECT_EQ(m.drho_b[3].y(), -2e-4);  // exact: no arithmetic on the way
}

TEST(Conversion, FrontEndAndGeometryAndCompensatorFillThePipelineConfig) {
  // Given Table 6 with the paper compensator and ρ = 0.1 m
  CalibrationData d = table6_data();
  d.compensator = nav::CompensatorKind::kPaper;
  // When applied to a float pipeline configuration
  nav::PipelineConfig<float> config;
  config.sample_rate_hz = 250.0;
  apply_to(d, config);
  // Then the front end carries SF and bias of each sensor in Table 1 order
  EXPECT_NEAR(config.front_end.scale_v_per_g[3], 2.493301f, 2.5f * kFloatRelTolerance);
  EXPECT_NEAR(config.front_end.bias_g[3], -0.007977f, 0.008f * kFloatRelTolerance);
  EXPECT_EQ(config.front_end.volts_per_count[0], static_cast<float>(2.5 / 8388608.0));
  EXPECT_EQ(config.compensator, nav::CompensatorKind::kPaper);
  EXPECT_EQ(config.nominal.rho_b[0].z(), -0.1f);  // sensor 1 at (0, 0, −ρ), Table 1
  EXPECT_EQ(config.sample_rate_hz, 250.0);        // not a calibration value: untouched
  // And the pipeline accepts it
  nav::NavPipeline<float> pipeline;
  EXPECT_TRUE(pipeline.configure(config).is_ok());
}

TEST(Conversion, CustomGeometryIsUsedAsGiven) {
  CalibrationData d = table6_data();
  d.geometry.kind = GeometryKind::kCustom;
  const auto t1 = nav::table1_geometry<double>(0.25);
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    for (int k = 0; k < 3; ++k) {
      d.geometry.positions_m[j][static_cast<std::size_t>(k)] = t1.rho_b[j](k);
      d.geometry.axes[j][static_cast<std::size_t>(k)] = t1.theta_b[j](k);
    }
  }
  const auto g = nominal_geometry<double>(d);
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    EXPECT_EQ(g.rho_b[j], t1.rho_b[j]);
    EXPECT_EQ(g.theta_b[j], t1.theta_b[j]);
  }
}

}  // namespace
}  // namespace gfins::calib_file
