#include <gtest/gtest.h>

#include "gfins/nav_core/alignment.hpp"
#include "gfins/nav_core/gravity.hpp"

namespace gfins::nav {
namespace {

// Published WGS-84 normal gravity values (NIMA TR8350.2, table 4.1 via Somigliana).
constexpr double kGammaEquator = 9.7803253359;
constexpr double kGammaPole = 9.8321849378;
// Free-air gradient near the surface at mid latitudes, m/s² per m (textbook -3.086e-6).
constexpr double kFreeAirGradient = -3.086e-6;

TEST(GravityModelTest, NormalGravityMatchesWgs84AtEquatorAndPole) {
  EXPECT_NEAR(GravityModel<double>::normal(0.0, 0.0).magnitude_at_origin(), kGammaEquator, 1e-9);
  EXPECT_NEAR(GravityModel<double>::normal(M_PI / 2, 0.0).magnitude_at_origin(), kGammaPole, 1e-8);
}

TEST(GravityModelTest, GravityDecreasesWithHeightAtFreeAirRate) {
  const auto g = GravityModel<double>::normal(45.0 * M_PI / 180.0, 100.0);
  // 1000 m up is r_n.z = -1000 in NED.
  const double dg = g.g_n(Vec3<double>(0, 0, -1000.0)).z() - g.g_n(Vec3<double>::Zero()).z();
  EXPECT_NEAR(dg / 1000.0, kFreeAirGradient, 0.01e-6);
}

TEST(GravityModelTest, ConstantModelPointsDown) {
  const auto g = GravityModel<float>::constant(9.8f);
  EXPECT_EQ(g.g_n(Vec3<float>(1, 2, 3)), Vec3<float>(0, 0, 9.8f));
}

class AlignmentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto s = ArraySolver<double>::create(table1_geometry(0.1));
    ASSERT_TRUE(s.is_ok());
    solver_ = s.value();
  }
  // Outputs of an ideal array at rest with attitude q_nb under gravity g (NED).
  Vec6<double> at_rest(const Quat<double>& q_nb, double g) const {
    const Vec3<double> f_b = -(q_nb.conjugate() * Vec3<double>(0, 0, g));
    return solver_.predict(Vec3<double>::Zero(), f_b, Vec3<double>::Zero());
  }
  ArraySolver<double> solver_;
};

// Roll and pitch are recovered to rounding from noise-free outputs.
constexpr double kAngleTol = 1e-12;

TEST_F(AlignmentTest, RecoversRollAndPitchAtRest) {
  const double roll = 0.3;
  const double pitch = -0.4;
  const double yaw = 2.0;
  const auto q = quat_from_euler(roll, pitch, yaw);
  StaticAligner<double> aligner;
  for (int i = 0; i < 100; ++i) aligner.add(solver_, at_rest(q, kStandardGravity));
  const auto r = aligner.finish(100);
  ASSERT_TRUE(r.is_ok());
  EXPECT_NEAR(r->roll_rad, roll, kAngleTol);
  EXPECT_NEAR(r->pitch_rad, pitch, kAngleTol);
  EXPECT_NEAR(r->gravity_mps2, kStandardGravity, 1e-12);
  EXPECT_NEAR(r->f_noise_mps2, 0.0, 1e-6);
  // The given heading is kept: the initial attitude equals the truth.
  const auto init = StaticAligner<double>::initial_state(r.value(), yaw, Vec3<double>::Zero(), 0);
  EXPECT_NEAR(init.q_nb.angularDistance(q), 0.0, 1e-12);
}

TEST_F(AlignmentTest, RefusesTooFewSamplesAndNonGravityInput) {
  StaticAligner<double> aligner;
  EXPECT_EQ(aligner.finish(1).status().code(), ErrorCode::kFailedPrecondition);
  for (int i = 0; i < 10; ++i) aligner.add(solver_, Vec6<double>::Zero());  // disconnected sensors
  EXPECT_EQ(aligner.finish(20).status().code(), ErrorCode::kFailedPrecondition);
  EXPECT_EQ(aligner.finish(10).status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace gfins::nav
