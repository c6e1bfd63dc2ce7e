// The in-motion alignment over 100 power-ups on the drive of in_motion_drive.hpp (seeds 1-100:
// the array's bias and noise and the receiver's noise differ per run). From 20 s after power-up,
// at every 0.1 s, each of the 9 errors (roll, pitch, heading, velocity and position per axis)
// against the σ the filter publishes for it:
//  - no run restarts for divergence, and no error is beyond 6σ in any run;
//  - pooled over the runs, the errors within 3σ are at least 98.5 %.
// Where the bounds come from: 300 runs (seeds 1-300) gave 99.69 % within 3σ on average (the
// Gaussian 99.73 %), 95.4 % in the worst single run, and at most 4.4σ; resampling those 300
// runs 100,000 times in groups of 100 never gave a pooled figure below 98.5 %, so the false
// failure probability is below 1e-5. With the roll and pitch rate prior of the start at 0.3 rad/s
// (FilterConfig::in_motion_sigma_tilt_rate_rps; the divergence restart's), 23 of the 300 runs
// converged to a wrong attitude: on seeds 1-100 two runs pass 6σ and the pooled figure is 97.8 %,
// so this test fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "nav_core/in_motion_drive.hpp"

namespace gfins::nav {
namespace {

using testing::DriveCheck;
using testing::InMotionDrive;

TEST(PipelineInMotionLong, ErrorsWithinTheFiltersOwnSigmaOverAHundredPowerUps) {
  constexpr unsigned kRuns = 100;
  long components = 0;
  long within_3sigma = 0;
  for (unsigned seed = 1; seed <= kRuns; ++seed) {
    InMotionDrive d(true, seed);
    ASSERT_TRUE(d.configured());
    double worst = 0.0;
    d.run(0, 60'000, 100, [&](const DriveCheck& c) {
      if (c.t_s < 20.0) return;
      const NavAccuracy<double>& a = c.accuracy;
      const Vec3<double> r[3] = {c.euler_err_rad.cwiseAbs().cwiseQuotient(a.euler_sigma_rad),
                                 c.vel_err_mps.cwiseAbs().cwiseQuotient(a.vel_sigma_mps),
                                 c.pos_err_m.cwiseAbs().cwiseQuotient(a.pos_sigma_m)};
      for (const Vec3<double>& v : r) {
        for (int i = 0; i < 3; ++i) {
          ++components;
          if (v(i) <= 3.0) ++within_3sigma;  // a NaN σ (not available) counts as outside
          worst = std::max(worst, std::isnan(v(i)) ? 1e9 : v(i));
        }
      }
    });
    EXPECT_EQ(d.pipeline().counters().in_motion_alignments, 1u) << "seed " << seed;
    EXPECT_EQ(d.pipeline().aiding().filter().counters().divergence_restarts, 0u) << "seed " << seed;
    EXPECT_LE(worst, 6.0) << "seed " << seed;
    if (seed % 20 == 0) std::printf("%u of %u power-ups\n", seed, kRuns);
  }
  const double fraction = static_cast<double>(within_3sigma) / static_cast<double>(components);
  std::printf("within 3 sigma: %.4f of %ld errors\n", fraction, components);
  EXPECT_EQ(components, 100L * 400 * 9);
  EXPECT_GE(fraction, 0.985);
}

}  // namespace
}  // namespace gfins::nav
