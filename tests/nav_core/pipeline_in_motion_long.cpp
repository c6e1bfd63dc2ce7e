// The in-motion alignment over 100 power-ups on the drive of in_motion_drive.hpp: run k powers
// up k/100 of the way round the figure eight (turns both ways at up to 0.48 rad/s and 2.4 m/s²,
// and the straights between), with its own array and receiver noise (seed k), once with the
// antenna at the array and once 1.8 m from it, (1.6, 0.3, −0.8) m (its fixes the antenna's, the
// filter told the lever arm). From 20 s after power-up, at every 0.1 s, each of the 9 errors
// (roll, pitch, heading, velocity and position per axis) against the σ the filter publishes for
// it:
//  - a run whose worst error is beyond 6σ, or that restarted for divergence, converged to a wrong
//    solution: at most 3 of the 100 may;
//  - over the other runs, at least 98.5 % of the errors within 3σ, and at least 98 % of each of
//    the 9 quantities (one optimistic quantity must not hide among eight honest ones).
// Before 20 s, from power-up, every σ published is either not available (NaN) or honest: none
// before the in-motion start, and over the runs that converged, in each second from power-up, at
// least 98.5 % of the errors whose σ is available within 3σ.
// Where the bounds come from: 400 runs at the array (seeds 1-400, the same 100 places four times)
// and 200 with the lever arm (seeds 1-200) had none that converged to a wrong solution (at the
// array 2 of 400 before a fix's time of validity was modelled, powered up in the tightest turn,
// 0.45 rad/s); with 2 in 400, 4 or more of 100 has probability 1.7e-3. From 20 s they had
// 99.47-99.81 % within 3σ per 100 runs (the Gaussian 99.73 %), at most 4.7σ at the array; per
// quantity 98.69-100 % (the lowest r_N with the lever arm; a quantity whose σ is 30 % optimistic
// has 97.4 % of Gaussian errors within 3σ and fails); before 20 s, 99.03-99.9 % per 1 s bin.
// Mutations this test fails: the level turning the heading as after a divergence restart (49 of
// 100 runs wrong), a GNSS fix's Jacobian not referred from its time of validity to now (Φ ≈ I:
// 1-2 s after power-up 95.9 % within 3σ), a quantity set from a fix without its change since the
// time of validity (0-1 s: 97.3 %); with the lever arm, the track heading's σ without the
// lever-arm term of ω̂'s error (4 of 100 runs wrong, up to 655σ, and 96.7-98.1 % per early bin).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "nav_core/in_motion_drive.hpp"

namespace gfins::nav {
namespace {

using testing::DriveCheck;
using testing::InMotionDrive;

// 100 power-ups with the antenna at lever_b; the checks of the file comment, failures named with
// `what`.
void check_hundred_power_ups(const Vec3<double>& lever_b, const char* what) {
  constexpr unsigned kRuns = 100;
  constexpr unsigned kFailedRunsAllowed = 3;
  constexpr double kPerQuantityBound = 0.98;
  long components = 0;
  long within_3sigma = 0;
  unsigned failed_runs = 0;
  constexpr int kEarlyBins = 20;  // 1 s each, power-up to 20 s
  std::array<long, kEarlyBins> early_n{};
  std::array<long, kEarlyBins> early_in{};
  long sigma_before_start = 0;
  // Per quantity (roll, pitch, heading, v_N, v_E, v_D, r_N, r_E, r_D) from 20 s: one quantity
  // with an optimistic σ must not hide among eight honest ones.
  std::array<long, 9> per_n{};
  std::array<long, 9> per_in{};
  // GFINS_IN_MOTION_FIRST_SEED: another set of runs, for measuring the bounds (not in CI).
  const char* first = std::getenv("GFINS_IN_MOTION_FIRST_SEED");
  const unsigned seed0 = first != nullptr ? static_cast<unsigned>(std::atoi(first)) : 1u;
  for (unsigned seed = seed0; seed < seed0 + kRuns; ++seed) {
    // Each run powers up at another place on the figure eight: turns both ways, straights.
    const double t0 = testing::kDrivePeriodS * ((seed - 1) % kRuns) / kRuns;
    InMotionDrive d(true, seed, t0, 0.5, lever_b);
    ASSERT_TRUE(d.configured());
    double worst = 0.0;
    long n = 0;
    long inside = 0;
    std::array<long, kEarlyBins> run_n{};
    std::array<long, kEarlyBins> run_in{};
    std::array<long, 9> run_per_in{};
    d.run(0, 60'000, 20, [&](const DriveCheck& c) {
      // Before 20 s every sample of 20 ms, from 20 s every 0.1 s.
      const bool early = c.t_s < 20.0;
      if (!early && c.sample % 100 != 0) return;
      const NavAccuracy<double>& a = c.accuracy;
      const Vec3<double> err[3] = {c.euler_err_rad, c.vel_err_mps, c.pos_err_m};
      const Vec3<double> sig[3] = {a.euler_sigma_rad, a.vel_sigma_mps, a.pos_sigma_m};
      const bool started = d.pipeline().phase() == PipelinePhase::kNavigating;
      const auto bin = static_cast<std::size_t>(c.t_s);
      for (int g = 0; g < 3; ++g) {
        for (int i = 0; i < 3; ++i) {
          const double ratio = std::abs(err[g](i)) / sig[g](i);
          if (early) {
            if (std::isnan(sig[g](i))) continue;  // not available: no claim
            if (!started) ++sigma_before_start;
            ++run_n[bin];
            if (ratio <= 3.0) ++run_in[bin];
          } else {
            ++n;
            if (ratio <= 3.0) {  // a NaN σ (not available) counts as outside
              ++inside;
              ++run_per_in[static_cast<std::size_t>(3 * g + i)];
            }
            worst = std::max(worst, std::isnan(ratio) ? 1e9 : ratio);
          }
        }
      }
    });
    EXPECT_EQ(n, 400L * 9) << what << ", seed " << seed;
    EXPECT_EQ(d.pipeline().counters().in_motion_alignments, 1u) << what << ", seed " << seed;
    const bool failed =
        worst > 6.0 || d.pipeline().aiding().filter().counters().divergence_restarts != 0;
    std::printf("%s, seed %u, power-up at %.2f s of the figure eight: worst %.2f sigma%s\n", what,
                seed, t0, worst, failed ? " (converged to a wrong solution)" : "");
    if (failed) {
      ++failed_runs;
    } else {
      components += n;
      within_3sigma += inside;
      for (std::size_t q = 0; q < 9; ++q) {
        per_n[q] += n / 9;
        per_in[q] += run_per_in[q];
      }
      for (std::size_t b = 0; b < kEarlyBins; ++b) {
        early_n[b] += run_n[b];
        early_in[b] += run_in[b];
      }
    }
  }
  const double fraction = static_cast<double>(within_3sigma) / static_cast<double>(components);
  std::printf(
      "%s: %u of %u runs converged to a wrong solution; the others: %.4f of %ld errors "
      "within 3 sigma\n",
      what, failed_runs, kRuns, fraction, components);
  EXPECT_LE(failed_runs, kFailedRunsAllowed) << what;
  EXPECT_GE(fraction, 0.985) << what;
  EXPECT_EQ(sigma_before_start, 0) << what << ": a sigma published before the in-motion start";
  static constexpr std::array<const char*, 9> kQuantity = {"roll", "pitch", "heading", "v_N", "v_E",
                                                           "v_D",  "r_N",   "r_E",     "r_D"};
  for (std::size_t q = 0; q < 9; ++q) {
    const double f = static_cast<double>(per_in[q]) / static_cast<double>(per_n[q]);
    std::printf("%s: %s from 20 s: %.4f of %ld within 3 sigma\n", what, kQuantity[q], f, per_n[q]);
    EXPECT_GE(f, kPerQuantityBound) << what << ", " << kQuantity[q];
  }
  for (std::size_t b = 0; b < kEarlyBins; ++b) {
    const double f = static_cast<double>(early_in[b]) / static_cast<double>(early_n[b]);
    std::printf("%s: %2zu-%2zu s after power-up: %.4f of %ld available errors within 3 sigma\n",
                what, b, b + 1, f, early_n[b]);
    EXPECT_GE(f, 0.985) << what << ", bin " << b << "-" << b + 1 << " s";
  }
}

TEST(PipelineInMotionLong, ErrorsWithinTheFiltersOwnSigmaOverAHundredPowerUps) {
  check_hundred_power_ups(Vec3<double>::Zero(), "antenna at the array");
}

TEST(PipelineInMotionLong, AnAntennaAMetreAndAHalfAwayToo) {
  check_hundred_power_ups(Vec3<double>(1.6, 0.3, -0.8), "antenna at (1.6, 0.3, -0.8) m");
}

}  // namespace
}  // namespace gfins::nav
