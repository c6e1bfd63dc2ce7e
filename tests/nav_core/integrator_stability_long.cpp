// Long-run behaviour of the integrator with ideal sensors, and the cost of float32.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <string>

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
// measures δω̇ and δf from the first sample and requires the integrator to add nothing to that
// law (no instability, no NaN, unit quaternion). docs/math.md records the figures: the float32
// floor (δω̇ ≈ 3e-6 rad/s² tilted) is 250 times below what a 10 µg sensor bias causes at
// ρ = 0.1 m.
//
// Where each law can be checked. The rate law is exact for all t: the outputs are constant, so
// the solver's ω̇ is constant (Table 1 has no ω-dependent ω̇ terms, K's ω̇ rows are zero) and
// ω = δω̇ t whatever the attitude. The attitude, velocity and position laws are small-angle laws:
// once δω̇ t²/2 is no longer small the tilt error stops growing as t² (an attitude error is at
// most π), so a bound like 2·δω̇ t²/2 = 39 rad after one hour (tilted, float) cannot fail. They
// are checked every second while their attitude bound stays below kSmallAngleRad, where
// sin θ = θ within 0.2 % and the t³, t⁴ laws hold; that window must cover at least
// kMinCheckedS, else the test would check nothing.
constexpr double kSmallAngleRad = 0.1;
constexpr double kMinCheckedS = 60.0;

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

  // Kinematic bound of the input residual at time t, with a factor 2 for the rounding of the
  // integration itself (N = 3.6e6 float additions accumulate at most N·ε/2 ≈ 0.2 relative), plus
  // a floor of a few units in the last place of each quantity.
  const double eps = static_cast<double>(std::numeric_limits<T>::epsilon());
  const double g = kStandardGravity;
  const auto rate_bound = [&](double t) { return 2 * dwdot * t + 8 * eps; };
  const auto attitude_bound = [&](double t) { return 2 * dwdot * t * t / 2 + 8 * eps; };
  const auto velocity_bound = [&](double t) {
    return 2 * (g * dwdot * t * t * t / 6 + df * t) + 8 * eps;
  };
  const auto position_bound = [&](double t) {
    return 2 * (g * dwdot * t * t * t * t / 24 + df * t * t / 2) + 8 * eps;
  };

  const auto steps = static_cast<std::uint32_t>(kHourS / kRate1kHz);
  double max_norm_err = 0;
  double checked_until_s = 0;
  int violations = 0;
  std::string first_violation;
  const auto check = [&](bool ok, const char* what, double t, double value, double bound) {
    if (ok) return;
    if (violations++ == 0) {
      first_violation = std::string(what) + " at t = " + std::to_string(t) +
                        " s: " + std::to_string(value) + " > bound " + std::to_string(bound);
    }
  };
  NavErrors e;
  for (std::uint32_t k = 1; k <= steps; ++k) {
    nav.step(s, static_cast<T>(kRate1kHz), 0, k);
    if (k % 1000 != 0) continue;
    const double t = static_cast<double>(k) * kRate1kHz;
    max_norm_err = std::max(max_norm_err, std::abs(double(nav.state().q_nb.norm()) - 1.0));
    e = testing::errors_against(nav.state().template cast<double>(), traj->at(0));
    check(e.finite, "non-finite state", t, 0, 0);
    check(e.rate_rps <= rate_bound(t), "rate", t, e.rate_rps, rate_bound(t));
    if (attitude_bound(t) > kSmallAngleRad) continue;
    checked_until_s = t;
    check(e.attitude_rad <= attitude_bound(t), "attitude", t, e.attitude_rad, attitude_bound(t));
    check(e.velocity_mps <= velocity_bound(t), "velocity", t, e.velocity_mps, velocity_bound(t));
    check(e.position_m <= position_bound(t), "position", t, e.position_m, position_bound(t));
  }
  const double t = kHourS;
  std::printf(
      "%s %s: input residual dwdot %.3e rad/s^2, df %.3e m/s^2 -> after 1 h: rate %.3e "
      "rad/s (bound %.3e), attitude %.3e rad, velocity %.3e m/s, position %.3e m, |q|-1 %.1e; "
      "small-angle laws checked every second up to %.0f s\n",
      sizeof(T) == 4 ? "float32" : "double ", level ? "level " : "tilted", dwdot, df, e.rate_rps,
      rate_bound(t), e.attitude_rad, e.velocity_mps, e.position_m, max_norm_err, checked_until_s);
  EXPECT_EQ(violations, 0) << first_violation;
  EXPECT_GE(checked_until_s, kMinCheckedS);
  EXPECT_LT(max_norm_err, 4 * std::numeric_limits<T>::epsilon());
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
