// The paper's §6.3 as an oracle: the eight bounds it quotes for Figs. 7-10 are reproduced by the
// configuration of the notes (§4): ρ = 0.35 m, gravity along −z, 2 s at 100 Hz, σ = 5e-4 m/s².
//
// How "within 20 %" is measured. The paper quotes each figure's error range as a pair [lo, hi]
// read off a plot. A bound near zero (before: hi = 2 m/s² on a range of 10 m/s²) has no useful
// relative error of its own, so the distance |ours − paper| is compared with the span hi − lo of
// the paper's pair for that figure; this is how the notes' "about 15 %" was measured. The bounds
// after compensation are extremes of noise, so they vary from seed to seed: the test takes the
// median over kSeeds seeds (a single seed can miss by up to 70 % of the span; docs/simulation.md
// gives the per-seed spread).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim {
namespace {

const std::string kBuiltinDir = std::string(GFINS_TEST_DATA_DIR) + "/../../host_sim/scenarios";

// The brief's acceptance: every bound within 20 % (of the span of its pair, see above).
constexpr double kTolerance = 0.20;
// Odd, so the median is one run; 11 runs of 200 samples take well under a second.
constexpr int kSeeds = 11;

struct Eight {
  std::array<double, 8> v{};  // before lin lo/hi, ang lo/hi, after lin lo/hi, ang lo/hi
};

// Paper §6.3, as quoted in docs/simulation.md ("The eight bounds").
constexpr Eight kPaper{{-8.0, 2.0, -0.1, 0.5, -0.002, 0.003, -0.003, 0.003}};
constexpr std::array<const char*, 8> kNames = {
    "before linear lo", "before linear hi", "before angular lo", "before angular hi",
    "after linear lo",  "after linear hi",  "after angular lo",  "after angular hi"};

Scenario builtin(const std::string& name) {
  const HostResult<Scenario> p = load_scenario(name, kBuiltinDir);
  EXPECT_TRUE(p.is_ok()) << p.error().message;
  return p.value();
}

Eight bounds_of(const ScenarioOutcome& o) {
  const Bounds bl = linear_accel_bounds(o.uncompensated);
  const Bounds ba = angular_accel_bounds(o.uncompensated);
  const Bounds al = linear_accel_bounds(o.compensated);
  const Bounds aa = angular_accel_bounds(o.compensated);
  return {{bl.lo, bl.hi, ba.lo, ba.hi, al.lo, al.hi, aa.lo, aa.hi}};
}

double span(std::size_t i) { return kPaper.v[i | 1u] - kPaper.v[i & ~std::size_t{1}]; }

TEST(Paper63, MatchingConfigurationReproducesAllEightQuotedBounds) {
  // Given the matching configuration, when it runs for kSeeds noise seeds,
  Scenario s = builtin("paper-6.3");
  std::array<std::vector<double>, 8> runs;
  for (int k = 0; k < kSeeds; ++k) {
    s.seed = static_cast<std::uint64_t>(k + 1);
    const Eight b = bounds_of(run_scenario(s).value());
    for (std::size_t i = 0; i < 8; ++i) runs[i].push_back(b.v[i]);
  }
  // then the median of each bound is within kTolerance of the span of the paper's pair.
  for (std::size_t i = 0; i < 8; ++i) {
    auto& r = runs[i];
    std::nth_element(r.begin(), r.begin() + kSeeds / 2, r.end());
    const double median = r[kSeeds / 2];
    const double rel = std::abs(median - kPaper.v[i]) / span(i);
    EXPECT_LE(rel, kTolerance) << kNames[i] << ": ours " << median << ", paper " << kPaper.v[i];
    std::printf("  %-18s paper %9.4g  ours (median of %d) %9.4g  off by %4.1f %% of the span\n",
                kNames[i], kPaper.v[i], kSeeds, median, 100.0 * rel);
  }
}

TEST(Paper63, BeforeCompensationTheBoundsDoNotDependOnTheNoiseSeed) {
  // Given the matching configuration, the errors before compensation come from the Table 6
  // misalignment (0.35 m/s² static, grown by the attitude drift), not from the 5e-4 noise: every
  // seed, not only the median, reproduces the four "before" bounds.
  Scenario s = builtin("paper-6.3");
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    s.seed = seed;
    const Eight b = bounds_of(run_scenario(s).value());
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_LE(std::abs(b.v[i] - kPaper.v[i]) / span(i), kTolerance) << kNames[i] << " " << b.v[i];
    }
  }
}

TEST(Paper63, StatedOneMilliGNoiseCannotGiveThePapersBoundsAfterCompensation) {
  // Given the paper's own 1 milli-g noise, the floor after compensation is the noise itself:
  // σ(ω̇) = σ/(√2 ρ) = 9.81e-3/(√2·0.35) = 0.020 rad/s² per axis (Chen's ω̇ = S s/(2ρ),
  // docs/math.md), whose extremes over 600 values are about ±3σ = ±0.06 rad/s², twenty times the
  // paper's ±0.003.
  const Scenario s = builtin("paper-6.3-1mg");
  const Eight b = bounds_of(run_scenario(s).value());
  const double sigma_wdot = s.noise_mps2 / (std::sqrt(2.0) * s.rho_m);
  // At least 2σ (the extremes of 600 Gaussian draws exceed 2σ with probability 1 − 1e-5).
  constexpr double kMinExtremeSigmas = 2.0;
  EXPECT_GT(std::max(-b.v[6], b.v[7]), kMinExtremeSigmas * sigma_wdot);
  EXPECT_GT(std::max(-b.v[6], b.v[7]), 10.0 * kPaper.v[7]);
}

TEST(Paper63, CalibratedCompensatorLeavesTheCalibrationErrorInTheLoop) {
  // Given the matching configuration but with the compensator's angles from a simulated
  // calibration (1 mg per pose mean → about 0.08° per angle), the residual misalignment drives the
  // attitude drift: the linear error after compensation is far above the paper's 0.003 m/s² (notes
  // §4: about 0.39 m/s² after 2 s), yet still well below the uncompensated one.
  Scenario s = builtin("paper-6.3");
  s.misalignment_source = MisalignmentSource::kCalibrated;
  const ScenarioOutcome o = run_scenario(s).value();
  ASSERT_TRUE(o.calibration.ran);
  const double deg = M_PI / 180.0;
  EXPECT_GT(o.calibration.rms_angle_error_rad, 0.01 * deg);  // the calibration is not perfect
  EXPECT_LT(o.calibration.rms_angle_error_rad, 0.3 * deg);   // nor broken
  const Eight b = bounds_of(o);
  const double after = std::max(-b.v[4], b.v[5]);
  const double before = std::max(-b.v[0], b.v[1]);
  EXPECT_GT(after, 30.0 * kPaper.v[5]);
  EXPECT_LT(after, before / 5.0);
}

}  // namespace
}  // namespace gfins::sim
