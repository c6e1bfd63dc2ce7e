// Monte-Carlo statistics: the error growth follows the kinematics (ω ∝ t, attitude ∝ t²) when a
// constant residual dominates, and the sample σ of a noise-only run matches the random walk that
// the integrator's trapezoid rule predicts.
#include "gfins/host_sim/montecarlo.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace gfins::sim {
namespace {

const std::string kBuiltinDir = std::string(GFINS_TEST_DATA_DIR) + "/../../host_sim/scenarios";

Scenario builtin(const std::string& name) {
  const HostResult<Scenario> p = load_scenario(name, kBuiltinDir);
  EXPECT_TRUE(p.is_ok()) << p.error().message;
  return p.value();
}

constexpr std::size_t kRate = static_cast<std::size_t>(McQuantity::kRate);
constexpr std::size_t kAttitude = static_cast<std::size_t>(McQuantity::kAttitude);

TEST(LogLogSlope, ExactPowerLawsGiveTheirExponent) {
  std::vector<double> t, y1, y2;
  for (int i = 0; i <= 100; ++i) {
    t.push_back(0.01 * i);
    y1.push_back(3.0 * t.back());
    y2.push_back(0.5 * t.back() * t.back());
  }
  EXPECT_NEAR(loglog_slope(t, y1, 0.1, 1.0), 1.0, 1e-12);
  EXPECT_NEAR(loglog_slope(t, y2, 0.1, 1.0), 2.0, 1e-12);
  EXPECT_TRUE(std::isnan(loglog_slope(t, y1, 2.0, 3.0)));  // no sample in the window
}

TEST(MonteCarlo, CalibrationResidualGrowsRateAsTAndAttitudeAsTSquared) {
  // Given the rest-calibrated scenario (Table 6 misalignment, compensator from a calibration with
  // 1 mg per pose mean, 1 mg sensor noise) and kRuns seeds,
  constexpr std::size_t kRuns = 8;
  const Scenario s = builtin("rest-calibrated");
  const MonteCarloResult r = run_montecarlo(s, kRuns, 1).value();
  // when the RMS error norms are fitted over the last decade of the run,
  const double t_end = r.t_s.back();
  const double w_slope = loglog_slope(r.t_s, r.rms_norm[kRate], 0.1 * t_end, t_end);
  const double a_slope = loglog_slope(r.t_s, r.rms_norm[kAttitude], 0.1 * t_end, t_end);
  // then the slopes are those of a constant ω̇ error c: δω = c t, δθ = c t²/2 (docs/math.md, "Error
  // growth without a gyroscope"). Tolerance: the other terms change the slope by less than this.
  // The noise random walk has σ_ω = h σ/(√2 ρ) √k = 0.0022 rad/s at t = 0.2 s (h = 0.01 s, σ
  // = 9.8e-3 m/s², ρ = 0.1 m), against c t ≈ 0.027 rad/s there: 0.7 % of the variance, a slope
  // change below 0.01; the attitude reaches 0.26 rad at 2 s, where the small-angle growth law is
  // off by a few %. 0.1 covers both with margin and still separates t from √t (0.5) and t² from
  // t^1.5.
  constexpr double kSlopeTolerance = 0.1;
  EXPECT_NEAR(w_slope, 1.0, kSlopeTolerance);
  EXPECT_NEAR(a_slope, 2.0, kSlopeTolerance);
  EXPECT_GT(r.rms_calibration_angle_error_rad, 0.0);
}

TEST(MonteCarlo, NoiseOnlyEnvelopeMatchesTheRandomWalkOfTheTrapezoidRule) {
  // Given an array without misalignment, 1 mg white noise and no compensation needed,
  Scenario s = builtin("rest");
  s.misalignment = nav::Misalignment<double>{};
  s.compensator = nav::CompensatorKind::kNone;
  s.duration_s = 1.0;
  s.rate_hz = 100.0;
  constexpr std::size_t kRuns = 32;
  const MonteCarloResult r = run_montecarlo(s, kRuns, 11).value();
  // the ω error is a random walk: ω_k = h [½ n_0 + n_1 + … + n_{k−1} + ½ n_k] with n the ω̇
  // noise of σ/(√2 ρ) per axis (Chen's ω̇ = S s/(2ρ), docs/math.md), so σ_ω(k) = h σ/(√2 ρ) √(k −
  // ½).
  const std::size_t k = r.t_s.size() - 1;
  const double h = 1.0 / s.rate_hz;
  const double predicted =
      h * s.noise_mps2 / (std::sqrt(2.0) * s.rho_m) * std::sqrt(static_cast<double>(k) - 0.5);
  double pooled_var = 0;
  double worst_mean_in_se = 0;
  for (std::size_t a = 0; a < 3; ++a) {
    pooled_var += r.std[kRate][a][k] * r.std[kRate][a][k] / 3.0;
    worst_mean_in_se =
        std::max(worst_mean_in_se, std::abs(r.mean[kRate][a][k]) /
                                       (predicted / std::sqrt(static_cast<double>(kRuns))));
  }
  // The sample σ pooled over 3 axes × 32 runs (93 degrees of freedom) has a relative standard
  // error of 1/√(2·93) = 7.3 %; three of them:
  constexpr double kSigmaTolerance = 0.22;
  EXPECT_NEAR(std::sqrt(pooled_var) / predicted, 1.0, kSigmaTolerance);
  // and the mean is zero within 3.5 standard errors (for each of the three axes: a false alarm
  // has probability 3 × 5e-4).
  constexpr double kMeanSe = 3.5;
  EXPECT_LT(worst_mean_in_se, kMeanSe);
}

/// Same doubles bit for bit (memcmp: also tells −0 from +0 and compares NaN payloads).
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

TEST(MonteCarlo, ResultIsBitIdenticalForAnyThreadCount) {
  // Given the calibrated scenario, short (0.5 s at 100 Hz) so that 9 runs are cheap; every run
  // draws both the sensor noise and the calibration error from its own seeds,
  Scenario s = builtin("rest-calibrated");
  s.duration_s = 0.5;
  constexpr std::size_t kRuns = 9;
  constexpr std::uint64_t kSeed0 = 3;
  for (const NavScalar scalar : {NavScalar::kFloat, NavScalar::kDouble}) {
    SCOPED_TRACE(scalar == NavScalar::kFloat ? "float core" : "double core");
    // when the runs go to 1, 2 and 7 threads (7 > runs per thread: threads wait for their turn),
    const MonteCarloResult one = run_montecarlo(s, kRuns, kSeed0, {}, scalar, 1).value();
    for (const std::size_t jobs : {2u, 7u}) {
      SCOPED_TRACE("jobs " + std::to_string(jobs));
      const MonteCarloResult r = run_montecarlo(s, kRuns, kSeed0, {}, scalar, jobs).value();
      // then every statistic is the single-threaded one, to the last bit: the runs' random streams
      // depend on (seed0, k) only and the sums add the runs in index order. A generator shared
      // between runs or a sum in completion order changes the last bits (in practice: the
      // mutations tried are in docs/performance.md).
      EXPECT_TRUE(same_bits(r.t_s, one.t_s));
      for (std::size_t q = 0; q < kMcQuantities; ++q) {
        for (std::size_t a = 0; a < 3; ++a) {
          EXPECT_TRUE(same_bits(r.mean[q][a], one.mean[q][a])) << kMcQuantityNames[q] << ' ' << a;
          EXPECT_TRUE(same_bits(r.std[q][a], one.std[q][a])) << kMcQuantityNames[q] << ' ' << a;
        }
        EXPECT_TRUE(same_bits(r.rms_norm[q], one.rms_norm[q])) << kMcQuantityNames[q];
      }
      EXPECT_EQ(std::memcmp(&r.rms_calibration_angle_error_rad,
                            &one.rms_calibration_angle_error_rad, sizeof(double)),
                0);
    }
    // and the runs do differ from each other (otherwise the check above could not fail): σ > 0.
    EXPECT_GT(one.std[kRate][0].back(), 0.0);
    EXPECT_GT(one.rms_calibration_angle_error_rad, 0.0);
  }
}

TEST(MonteCarlo, FewerThanTwoRunsIsAnErrorNamingTheCount) {
  const HostResult<MonteCarloResult> r =
      run_montecarlo(builtin("rest"), 1, 1, {}, NavScalar::kDouble, 2);
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message.find("two runs"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace gfins::sim
