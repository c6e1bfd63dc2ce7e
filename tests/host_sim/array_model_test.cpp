#include "gfins/host_sim/array_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>

#include "gfins/nav_core/math.hpp"

namespace gfins::sim {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kG = nav::kStandardGravity;
// A sensor output is a dot product of a few rounded terms of size ≤ g (or ρω²); 16 ulps of that
// size bounds the rounding.
constexpr double kRounding = 16.0 * kEps;

const nav::GravityModel<double> kConstantG = nav::GravityModel<double>::constant(kG);
const nav::GravityModel<double> kNoGravity = nav::GravityModel<double>::constant(0.0);

TEST(IdealArrayModelTest, LevelTable1AtRestSeesMinusGTimesTheAxisDownComponent) {
  // Given the level Table 1 array at rest,
  const auto geometry = nav::table1_geometry(0.35);
  const IdealArrayModel<6> model(geometry, kConstantG);
  const auto traj = make_rest(Quatd::Identity());
  // when sampled,
  const auto s = model.outputs(traj->at(1.0));
  // then the specific force is g upwards and s_j = −g θ_j,z (0 for sensors 1 and 6, −g/√2 else).
  EXPECT_EQ(model.specific_force(traj->at(1.0)), Vec3d(0, 0, -kG));
  for (std::size_t j = 0; j < 6; ++j) {
    EXPECT_NEAR(s(static_cast<Eigen::Index>(j)), -kG * geometry.theta_b[j].z(), kRounding * kG)
        << "sensor " << j + 1;
  }
  EXPECT_NEAR(s(1), -kG / std::sqrt(2.0), kRounding * kG);
  EXPECT_EQ(s(0), 0.0);
}

TEST(IdealArrayModelTest, TiltedAtRestGivesTheLevelingFormula) {
  // Given the array at rest with roll φ and pitch θ,
  const double roll = 0.3;
  const double pitch = -0.5;
  const IdealArrayModel<6> model(nav::table1_geometry(0.2), kConstantG);
  const auto traj = make_rest(nav::quat_from_euler(roll, pitch, 1.2));
  // then f_b = g [sin θ, −sin φ cos θ, −cos φ cos θ] (FRD body, NED navigation; yaw-free).
  const Vec3d f_ref = kG * Vec3d(std::sin(pitch), -std::sin(roll) * std::cos(pitch),
                                 -std::cos(roll) * std::cos(pitch));
  EXPECT_LT((model.specific_force(traj->at(0.0)) - f_ref).norm(), kRounding * kG);
}

TEST(IdealArrayModelTest, PureSpinGivesTheHandComputedCentripetalTerm) {
  // Given Table 1 (ρ = 0.35 m) spinning at Ω = 6 rad/s about (1, 0, 1)/√2 with no gravity,
  const double rho = 0.35;
  const double omega = 6.0;
  const IdealArrayModel<6> model(nav::table1_geometry(rho), kNoGravity);
  const auto traj = make_spin(Vec3d(1, 0, 1), omega, nav::quat_from_euler(0.1, 0.2, 0.3));
  for (const double t : {0.0, 0.4, 2.0}) {
    const auto s = model.outputs(traj->at(t));
    // then sensor 1 (ρ_1 = (0, 0, −ρ), θ_1 = (1, 1, 0)/√2) sees
    //   ω×(ω×ρ_1) = ω(ω·ρ_1) − ρ_1 Ω² = (−ρΩ²/2, 0, ρΩ²/2),  s_1 = θ_1·that = −ρΩ²/(2√2),
    EXPECT_NEAR(s(0), -rho * omega * omega / (2.0 * std::sqrt(2.0)),
                kRounding * rho * omega * omega)
        << "t = " << t;
    // and sensor 4 (ρ_4 = (ρ, 0, 0), θ_4 = (0, −1, 1)/√2): ω(ω·ρ_4) − ρ_4Ω² = (−ρΩ²/2, 0, ρΩ²/2),
    // s_4 = ρΩ²/(2√2); the output does not change while the body turns.
    EXPECT_NEAR(s(3), rho * omega * omega / (2.0 * std::sqrt(2.0)), kRounding * rho * omega * omega)
        << "t = " << t;
    // Sensors 2 and 5 lie on the y axis, perpendicular to ω: ω×(ω×ρ) = −Ω²ρ ⟂ θ, so 0.
    EXPECT_NEAR(s(1), 0.0, kRounding * rho * omega * omega);
    EXPECT_NEAR(s(4), 0.0, kRounding * rho * omega * omega);
  }
}

TEST(IdealArrayModelTest, AngularAccelerationEntersThroughRhoCrossTheta) {
  // Given a state with only ω̇ = (0, 0, 10) rad/s² and no gravity,
  const double rho = 0.1;
  const IdealArrayModel<6> model(nav::table1_geometry(rho), kNoGravity);
  TruthState x;
  x.wdot_b = Vec3d(0, 0, 10);
  const auto s = model.outputs(x);
  // then sensor 2 (ρ_2 = (0, −ρ, 0), θ_2 = (1, 0, 1)/√2): ω̇×ρ_2 = (10ρ, 0, 0), s_2 = 10ρ/√2,
  EXPECT_NEAR(s(1), 10.0 * rho / std::sqrt(2.0), kRounding);
  // and sensor 1 on the z axis sees nothing (ω̇ ∥ ρ_1).
  EXPECT_EQ(s(0), 0.0);
}

TEST(IdealArrayModelTest, NonUnitAxisActsAsAGain) {
  // Given a geometry whose third axis is 2 % long (a misaligned array, eq. (23)),
  auto geometry = nav::table1_geometry(0.25);
  const IdealArrayModel<6> nominal(geometry, kConstantG);
  geometry.theta_b[2] *= 1.02;
  const IdealArrayModel<6> long_axis(geometry, kConstantG);
  const TruthState x = make_maneuver()->at(2.5);
  // then that output is 1.02 times the nominal one and the others are unchanged.
  const auto s0 = nominal.outputs(x);
  const auto s1 = long_axis.outputs(x);
  EXPECT_NEAR(s1(2), 1.02 * s0(2), kRounding * kG);
  EXPECT_EQ(s1(0), s0(0));
  EXPECT_EQ(s1(5), s0(5));
}

TEST(IdealArrayModelTest, GravityIsTakenAtTheCentrePosition) {
  // Given normal gravity and the array at rest 1 km above the alignment point (z = −1000 m NED),
  const auto gravity = nav::GravityModel<double>::normal(0.8, 100.0);
  const IdealArrayModel<6> model(nav::table1_geometry(0.3), gravity);
  const Vec3d r_n(0, 0, -1000.0);
  const auto traj = make_rest(Quatd::Identity(), r_n);
  // then the sensed specific force is the weaker gravity of that height (≈ 3.1e-3 m/s² less).
  const double f_z = model.specific_force(traj->at(0.0)).z();
  EXPECT_NEAR(f_z, -gravity.g_n(r_n).z(), kRounding * kG);
  EXPECT_GT(-f_z, gravity.magnitude_at_origin() - 3.2e-3);
  EXPECT_LT(-f_z, gravity.magnitude_at_origin() - 3.0e-3);
}

}  // namespace
}  // namespace gfins::sim
