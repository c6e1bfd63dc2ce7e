// Order of the strapdown integrator (docs/math.md): every stage is second order in the step, so
// halving dt must divide the final errors by about 4. The issue asks for at least 3.5.
#include <gtest/gtest.h>

#include <cstdio>

#include "nav_run.hpp"

namespace gfins::nav {
namespace {

using testing::NavErrors;
using testing::RunOptions;

// Second order gives a ratio of 4 per halving; 3.5 leaves room for the higher-order terms at the
// coarsest step only (the threshold).
constexpr double kMinRatio = 3.5;
constexpr double kDurationS = 4.0;
constexpr double kDt0 = 0.008;  // s; then 0.004, 0.002, 0.001

void expect_second_order(const sim::Trajectory& traj, bool misaligned = false) {
  NavErrors prev;
  for (int level = 0; level < 4; ++level) {
    RunOptions o;
    o.duration_s = kDurationS;
    o.dt_s = kDt0 / static_cast<double>(1 << level);
    o.misaligned = misaligned;
    const NavErrors e = testing::run_trajectory<double>(traj, o);
    std::printf("%-10s dt=%.4f s  attitude %.3e rad  velocity %.3e m/s  position %.3e m\n",
                traj.name().c_str(), o.dt_s, e.attitude_rad, e.velocity_mps, e.position_m);
    ASSERT_TRUE(e.finite);
    if (level > 0) {
      EXPECT_GE(prev.attitude_rad / e.attitude_rad, kMinRatio) << "attitude, dt=" << o.dt_s;
      EXPECT_GE(prev.velocity_mps / e.velocity_mps, kMinRatio) << "velocity, dt=" << o.dt_s;
      EXPECT_GE(prev.position_m / e.position_m, kMinRatio) << "position, dt=" << o.dt_s;
    }
    prev = e;
  }
}

TEST(IntegratorConvergenceTest, ConingIsSecondOrder) {
  expect_second_order(*sim::make_coning(0.2, 2.0 * M_PI));
}

TEST(IntegratorConvergenceTest, ManeuverIsSecondOrder) {
  expect_second_order(*sim::make_maneuver(1.0));
}

// The exact compensator's geometry makes ω̇ depend on ω (K's top rows non-zero), so the Heun
// predictor of the integrator's general branch is exercised; it must be second order too.
TEST(IntegratorConvergenceTest, GeneralBranchOnExactCompensatorGeometryIsSecondOrder) {
  RunOptions o;
  o.misaligned = true;
  const auto solver = ArraySolver<double>::create(testing::run_geometry(o));
  ASSERT_TRUE(solver.is_ok());
  ASSERT_TRUE((solver->k().topRows<3>().array() != 0.0).any())
      << "geometry does not exercise the general branch";
  expect_second_order(*sim::make_coning(0.2, 2.0 * M_PI), true);
  expect_second_order(*sim::make_maneuver(1.0), true);
}

// Constant spin about an arbitrary axis with the centre fixed: ω̇ = 0, the two-sample rotation
// vector is exact for constant ω, and C f + g is constant, so the scheme has no truncation error
// at all. Halving dt cannot reduce an error that is already at the rounding floor; what must
// hold instead is that the error stays at that floor for every dt (a stronger statement than
// the second-order ratio).
TEST(IntegratorConvergenceTest, SpinIsExactForEveryStep) {
  const auto traj = sim::make_spin(Vec3<double>(1.0, -2.0, 0.5).normalized(), 3.0,
                                   quat_from_euler(0.2, -0.1, 0.7));
  for (double dt : {0.008, 0.004, 0.002, 0.001}) {
    RunOptions o;
    o.duration_s = kDurationS;
    o.dt_s = dt;
    const NavErrors e = testing::run_trajectory<double>(*traj, o);
    std::printf("spin dt=%.4f s  attitude %.3e rad  velocity %.3e m/s  position %.3e m\n", dt,
                e.attitude_rad, e.velocity_mps, e.position_m);
    // Rounding floor: ~1e-16 relative per step on ω·dt over 4000 steps, times |g| for v, r.
    EXPECT_LT(e.attitude_rad, 1e-11);
    EXPECT_LT(e.velocity_mps, 1e-10);
    EXPECT_LT(e.position_m, 1e-10);
  }
}

}  // namespace
}  // namespace gfins::nav
