// The in-motion alignment over 100 power-ups on the drive of in_motion_drive.hpp: run k powers
// up k/100 of the way round the figure eight (turns both ways at up to 0.48 rad/s and 2.4 m/s²,
// and the straights between), with its own array and receiver noise (seed k). From 20 s after
// power-up, at every 0.1 s, each of the 9 errors (roll, pitch, heading, velocity and position per
// axis) against the σ the filter publishes for it:
//  - a run whose worst error is beyond 6σ, or that restarted for divergence, converged to a wrong
//    solution: at most 3 of the 100 may;
//  - over the other runs, at least 98.5 % of the errors within 3σ.
// Where the bounds come from: 400 runs (seeds 1-400, the same 100 places four times) had 2 that
// converged to a wrong solution (powered up in the tightest turn, 0.45 rad/s: a limit stated in
// docs/navigation-accuracy.md); with that rate, 4 or more of 100 has probability 1.7e-3. The
// others had 99.67-99.75 % within 3σ per 100 runs (the Gaussian 99.73 %) and at most 4.9σ.
// Mutations this test fails: the level turning the heading as after a divergence restart (54 of
// 100 runs wrong), the roll and pitch rate prior of the start at the restart's 0.3 rad/s (10 of
// 100).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "nav_core/in_motion_drive.hpp"

namespace gfins::nav {
namespace {

using testing::DriveCheck;
using testing::InMotionDrive;

TEST(PipelineInMotionLong, ErrorsWithinTheFiltersOwnSigmaOverAHundredPowerUps) {
  constexpr unsigned kRuns = 100;
  constexpr unsigned kFailedRunsAllowed = 3;
  long components = 0;
  long within_3sigma = 0;
  unsigned failed_runs = 0;
  // GFINS_IN_MOTION_FIRST_SEED: another set of runs, for measuring the bounds (not in CI).
  const char* first = std::getenv("GFINS_IN_MOTION_FIRST_SEED");
  const unsigned seed0 = first != nullptr ? static_cast<unsigned>(std::atoi(first)) : 1u;
  for (unsigned seed = seed0; seed < seed0 + kRuns; ++seed) {
    // Each run powers up at another place on the figure eight: turns both ways, straights.
    const double t0 = testing::kDrivePeriodS * ((seed - 1) % kRuns) / kRuns;
    InMotionDrive d(true, seed, t0);
    ASSERT_TRUE(d.configured());
    double worst = 0.0;
    long n = 0;
    long inside = 0;
    d.run(0, 60'000, 100, [&](const DriveCheck& c) {
      if (c.t_s < 20.0) return;
      const NavAccuracy<double>& a = c.accuracy;
      const Vec3<double> r[3] = {c.euler_err_rad.cwiseAbs().cwiseQuotient(a.euler_sigma_rad),
                                 c.vel_err_mps.cwiseAbs().cwiseQuotient(a.vel_sigma_mps),
                                 c.pos_err_m.cwiseAbs().cwiseQuotient(a.pos_sigma_m)};
      for (const Vec3<double>& v : r) {
        for (int i = 0; i < 3; ++i) {
          ++n;
          if (v(i) <= 3.0) ++inside;  // a NaN σ (not available) counts as outside
          worst = std::max(worst, std::isnan(v(i)) ? 1e9 : v(i));
        }
      }
    });
    EXPECT_EQ(n, 400L * 9) << "seed " << seed;
    EXPECT_EQ(d.pipeline().counters().in_motion_alignments, 1u) << "seed " << seed;
    const bool failed =
        worst > 6.0 || d.pipeline().aiding().filter().counters().divergence_restarts != 0;
    std::printf("seed %u, power-up at %.2f s of the figure eight: worst %.2f sigma%s\n", seed, t0,
                worst, failed ? " (converged to a wrong solution)" : "");
    if (failed) {
      ++failed_runs;
    } else {
      components += n;
      within_3sigma += inside;
    }
  }
  const double fraction = static_cast<double>(within_3sigma) / static_cast<double>(components);
  std::printf(
      "%u of %u runs converged to a wrong solution; the others: %.4f of %ld errors "
      "within 3 sigma\n",
      failed_runs, kRuns, fraction, components);
  EXPECT_LE(failed_runs, kFailedRunsAllowed);
  EXPECT_GE(fraction, 0.985);
}

}  // namespace
}  // namespace gfins::nav
