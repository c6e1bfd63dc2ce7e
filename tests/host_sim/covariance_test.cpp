// Covariance propagation (covariance.hpp over nav_core/error_model.hpp): the growth laws of a
// bias and the additivity of the error budget. The Monte-Carlo comparison is in
// covariance_montecarlo_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "gfins/host_sim/covariance.hpp"
#include "gfins/host_sim/montecarlo.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/error_model.hpp"
#include "support/covariance_spec.hpp"

namespace gfins::sim {
namespace {

using nav::err_idx::kNav;

constexpr double kRhoM = 0.1;

// ---------------------------------------------------------------------------------------------
// Growth laws of a constant bias (docs/math.md, "Error growth without a gyroscope"): δω̇ = M_w b is
// constant, so δω ∝ t, φ ∝ t², the tilt-induced δv ∝ g t³ and δr ∝ g t⁴.

// Fit windows and slope tolerance. The bias also enters f directly (M_f b): δv gains a t term and
// δr a t² term. For sensor 1 of Table 1 at ρ = 0.1 m, |M_f b| = 0.5 b and |M_w b| = 5 b/m, so
// the direct δr is 0.25 b t² against the tilt term g·5 b t⁴/24 = 2.0 b t⁴: at t = 5 s the direct
// term is 0.5 % of the total and bends the local slope by at most 2 × 0.5 % = 0.01; for δv
// (0.5 b t against 8.2 b t³, 0.08 % at 5 s) less. δω and φ are exact powers at rest. 0.03 covers
// the 0.01 and the curvature of the fit over the window; a missing coupling would change the
// slope by 1 or more.
constexpr double kGrowthFitFromS = 5.0;
constexpr double kGrowthFitToS = 20.0;
constexpr double kSlopeTol = 0.03;
constexpr double kBiasSigmaMps2 = 1e-4;  // ≈ 10 µg, the notes' example

double block_norm(const CovarianceResult& r, int offset, std::size_t k) {
  double s2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double s = r.sigma[static_cast<std::size_t>(offset + a)][k];
    s2 += s * s;
  }
  return std::sqrt(s2);
}

TEST(CovarianceGrowthTest, BiasGrowthFollowsKinematics) {
  // Given one sensor with a random-constant bias and no other error, at rest and level,
  const auto traj = make_rest(Quatd::Identity());
  CovarianceSpec spec;
  spec.trajectory = traj.get();
  spec.geometry = nav::table1_geometry<double>(kRhoM);
  spec.duration_s = kGrowthFitToS;
  spec.dt_s = 0.02;
  spec.decimation = 5;
  spec.noise.bias_sigma_mps2[0] = kBiasSigmaMps2;
  // when its covariance is propagated,
  const CovarianceResult r = propagate_covariance(spec);
  std::array<std::vector<double>, 4> y;
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    y[0].push_back(block_norm(r, nav::err_idx::kRate, k));
    y[1].push_back(block_norm(r, nav::err_idx::kPhi, k));
    y[2].push_back(block_norm(r, nav::err_idx::kVel, k));
    y[3].push_back(block_norm(r, nav::err_idx::kPos, k));
  }
  // then the envelopes grow as t, t², t³ and t⁴ on a log-log scale.
  const std::array<double, 4> expected = {1.0, 2.0, 3.0, 4.0};
  const std::array<const char*, 4> names = {"rate", "attitude", "velocity", "position"};
  for (std::size_t q = 0; q < 4; ++q) {
    const double slope = loglog_slope(r.t_s, y[q], kGrowthFitFromS, kGrowthFitToS);
    std::printf("%-8s log-log slope %.4f (expected %.0f)\n", names[q], slope, expected[q]);
    EXPECT_NEAR(slope, expected[q], kSlopeTol) << names[q];
  }
  // and the magnitudes agree with the closed forms of docs/math.md ("Error growth without a
  // gyroscope"): δω = 5 b t, φ = 5 b t²/2.
  constexpr double kClosedFormRelTol = 1e-6;  // Φ to second order is exact for these polynomials
  const std::size_t last = r.t_s.size() - 1;
  const double t = r.t_s[last];
  EXPECT_NEAR(y[0][last] / (5.0 * kBiasSigmaMps2 * t), 1.0, kClosedFormRelTol);
  EXPECT_NEAR(y[1][last] / (5.0 * kBiasSigmaMps2 * t * t / 2), 1.0, kClosedFormRelTol);
}

// ---------------------------------------------------------------------------------------------
// Error budget: the model is linear and the sources independent, so the variances add up.

TEST(CovarianceBudgetTest, SourceVariancesAddUpToTheTotal) {
  // Given every kind of source at once on a moving trajectory,
  const auto traj = make_maneuver(1.0);
  const CovarianceSpec spec = test::every_source_spec(*traj, 2.0, 0.02);
  // when the budget is computed,
  const ErrorBudget b = error_budget(spec, {1.0, 2.0});
  ASSERT_EQ(b.sigma.size(), kBudgetSources.size() + 1);
  // then each source contributes, and the sum of the variances is the total variance.
  constexpr double kAddRelTol = 1e-9;  // rounding of a few thousand steps in double
  for (std::size_t k = 0; k < b.t_s.size(); ++k) {
    for (std::size_t i = 0; i < kNav; ++i) {
      double sum = 0;
      for (std::size_t s = 0; s < kBudgetSources.size(); ++s) {
        EXPECT_GT(b.sigma[s][k][i], 0.0) << kBudgetSources[s] << ' ' << kErrorStateNames[i];
        sum += b.sigma[s][k][i] * b.sigma[s][k][i];
      }
      const double total = b.sigma.back()[k][i];
      EXPECT_NEAR(sum / (total * total), 1.0, kAddRelTol) << kErrorStateNames[i];
    }
  }
}

TEST(CovarianceReport, SameBitsForAnyThreadCountAndTheSerialPropagation) {
  // Given every source at once along a manoeuvre (so P and all 36 constant parameters move),
  const auto traj = make_maneuver(1.0);
  // 20 steps: what matters is that every job has run (cheap under ASan).
  CovarianceSpec spec = test::every_source_spec(*traj, 0.2, 0.01);
  spec.decimation = 5;
  const std::vector<double> times = {0.1, 0.2};
  // when the report is computed on 1, 2 and 7 threads,
  const CovarianceReport one = covariance_report(spec, times, 1);
  const CovarianceResult serial = propagate_covariance(spec);
  const auto bits_equal = [](const std::vector<double>& a, const std::vector<double>& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
  };
  // then its envelopes are the one serial propagation of the whole spec,
  ASSERT_TRUE(bits_equal(one.envelopes.t_s, serial.t_s));
  for (std::size_t i = 0; i < kNav; ++i) {
    EXPECT_TRUE(bits_equal(one.envelopes.sigma[i], serial.sigma[i])) << kErrorStateNames[i];
  }
  // the budget's total row is that propagation at the chosen times,
  ASSERT_EQ(one.budget.sigma.size(), kBudgetSources.size() + 1);
  for (std::size_t k = 0; k < times.size(); ++k) {
    const auto idx = static_cast<std::size_t>(std::llround(one.budget.t_s[k] / 0.05));
    for (std::size_t i = 0; i < kNav; ++i) {
      EXPECT_EQ(one.budget.sigma.back()[k][i], serial.sigma[i][idx]) << kErrorStateNames[i];
    }
  }
  // and every thread count gives the same bits.
  for (const std::size_t jobs : {2u, 7u}) {
    SCOPED_TRACE("jobs " + std::to_string(jobs));
    const CovarianceReport r = covariance_report(spec, times, jobs);
    for (std::size_t i = 0; i < kNav; ++i) {
      EXPECT_TRUE(bits_equal(r.envelopes.sigma[i], one.envelopes.sigma[i]));
    }
    ASSERT_EQ(r.budget.sigma.size(), one.budget.sigma.size());
    for (std::size_t s = 0; s < r.budget.sigma.size(); ++s) {
      for (std::size_t k = 0; k < times.size(); ++k) {
        EXPECT_EQ(std::memcmp(r.budget.sigma[s][k].data(), one.budget.sigma[s][k].data(),
                              sizeof(double) * kNav),
                  0)
            << "source " << s << " time " << k;
      }
    }
  }
}

}  // namespace
}  // namespace gfins::sim
