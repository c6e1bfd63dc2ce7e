// Long-run behaviour of the integrator with ideal sensors, and the cost of float32.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>

#include "nav_run.hpp"

namespace gfins::nav {
namespace {

using testing::NavErrors;
using testing::RunOptions;

constexpr double kHourS = 3600.0;
constexpr double kRate1kHz = 1e-3;

// One hour at rest, 1 kHz, ideal sensors. At rest the outputs are constant, so the only input
// error is their rounding to T: a constant residual δω̇ (and δf) that kinematics turns into
// ω = δω̇ t, attitude δω̇ t²/2, velocity g δω̇ t³/6, position g δω̇ t⁴/24 (docs/math.md). The test
// measures δω̇ and δf from the first sample, requires the integrator to add nothing to that law
// (no instability, no NaN, unit quaternion). docs/math.md records the figures: the float32 floor
// (δω̇ ≈ 3e-6 rad/s² tilted) is 250 times below what a 10 µg sensor bias causes at ρ = 0.1 m.
template <typename T>
void run_hour_at_rest(const Quat<double>& q_nb, bool level) {
  const auto geometry = table1_geometry<double>(0.1);
  const sim::IdealArrayModel<6> model(geometry, GravityModel<double>::constant(kStandardGravity));
  const auto traj = sim::make_rest(q_nb);
  const Vec6<T> s = model.outputs(traj->at(0.0)).template cast<T>();
  const auto solver = ArraySolver<T>::create(geometry.template cast<T>()).value();
  const GravityModel<T> gravity = GravityModel<T>::constant(static_cast<T>(kStandardGravity));
  Strapdown<T> nav(solver, gravity);
  NavState<T> init;
  init.q_nb = q_nb.template cast<T>();
  nav.initialize(init, s);
  // The input residual, in double: what the rounded outputs say the body is doing.
  Vec3<T> wdot_in;
  Vec3<T> f_in;
  solver.solve(s, Vec3<T>::Zero(), wdot_in, f_in);
  const double dwdot = wdot_in.template cast<double>().norm();
  const double df =
      (q_nb * f_in.template cast<double>() + Vec3<double>(0, 0, kStandardGravity)).norm();

  const auto steps = static_cast<std::uint32_t>(kHourS / kRate1kHz);
  double max_norm_err = 0;
  for (std::uint32_t k = 1; k <= steps; ++k) {
    nav.step(s, static_cast<T>(kRate1kHz), 0, k);
    if (k % 1000 == 0) {
      max_norm_err = std::max(max_norm_err, std::abs(double(nav.state().q_nb.norm()) - 1.0));
    }
  }
  const NavErrors e = testing::errors_against(nav.state().template cast<double>(), traj->at(0));
  const double t = kHourS;
  const double g = kStandardGravity;
  std::printf(
      "%s %s: input residual dwdot %.3e rad/s^2, df %.3e m/s^2 -> after 1 h: rate %.3e "
      "rad/s, attitude %.3e rad, velocity %.3e m/s, position %.3e m, |q|-1 %.1e\n",
      sizeof(T) == 4 ? "float32" : "double ", level ? "level " : "tilted", dwdot, df, e.rate_rps,
      e.attitude_rad, e.velocity_mps, e.position_m, max_norm_err);
  ASSERT_TRUE(e.finite);
  EXPECT_LT(max_norm_err, 4 * std::numeric_limits<T>::epsilon());
  // Kinematic bound of the input residual, with a factor 2 for the rounding of the integration
  // itself, plus a floor of a few units in the last place of each quantity.
  const double eps = std::numeric_limits<T>::epsilon();
  EXPECT_LE(e.rate_rps, 2 * dwdot * t + 8 * eps);
  EXPECT_LE(e.attitude_rad, 2 * dwdot * t * t / 2 + 8 * eps);
  EXPECT_LE(e.velocity_mps, 2 * (g * dwdot * t * t * t / 6 + df * t) + 8 * eps);
  EXPECT_LE(e.position_m, 2 * (g * dwdot * t * t * t * t / 24 + df * t * t / 2) + 8 * eps);
}

TEST(IntegratorStabilityTest, HourAtRestLevelFloat) {
  run_hour_at_rest<float>(Quat<double>::Identity(), true);
}
TEST(IntegratorStabilityTest, HourAtRestLevelDouble) {
  run_hour_at_rest<double>(Quat<double>::Identity(), true);
}
TEST(IntegratorStabilityTest, HourAtRestTiltedFloat) {
  run_hour_at_rest<float>(quat_from_euler(0.17, -0.09, 1.1), false);
}
TEST(IntegratorStabilityTest, HourAtRestTiltedDouble) {
  run_hour_at_rest<double>(quat_from_euler(0.17, -0.09, 1.1), false);
}

}  // namespace
}  // namespace gfins::nav
