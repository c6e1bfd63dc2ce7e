// Covariance propagation (covariance.hpp over nav_core/error_model.hpp) against Monte-Carlo runs
// of the nonlinear strapdown with white sensor noise: at rest and along a 6-DoF manoeuvre.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "gfins/host_sim/array_model.hpp"
#include "gfins/host_sim/covariance.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/error_model.hpp"
#include "gfins/nav_core/integrator.hpp"

namespace gfins::sim {
namespace {

using nav::err_idx::kNav;

constexpr double kRhoM = 0.1;

// ---------------------------------------------------------------------------------------------
// Monte-Carlo: white noise on every sensor, same trajectory, N seeds.

constexpr int kSeeds = 800;
constexpr double kMcDtS = 0.01;       // 100 Hz keeps 1000 seeds within the time budget
constexpr double kMcDurationS = 2.0;  // rest; the manoeuvre stops at kWindowEndS
constexpr double kNoiseMps2 = 1e-2;   // ≈ 1 mg per sample, the paper's stated noise level
constexpr double kCheckFromS = 0.5;   // from 50 samples on (see kRelTol)
// Acceptance of the issue: predicted 1σ within 10 % of the sample σ. The sampling error of a
// sample σ of N Gaussian draws is 1/√(2(N−1)) = 2.5 % for N = 800, so 10 % is 4 standard
// errors: a correct model passes every one of the 12 states × 3 check times, a model off by a
// factor (a missing coupling, a wrong PSD) fails. The discrete white noise enters both ends of
// the integrator's trapezoid steps; its variance differs from the PSD σ²h model by a relative
// 1/(2k) after k samples, 1 % at k = 50 (kCheckFromS).
constexpr double kRelTol = 0.10;
constexpr std::array<double, 3> kCheckTimesS = {kCheckFromS, 1.0, 1.5};
// Where the linearisation stops holding (docs/error-model.md): at rest the vertical velocity has
// no first-order tilt coupling ((C f)×φ has no z component for C f vertical), so its first-order
// error is only the noise random walk (∝ √t), while the dropped second-order term g|φ|²/2
// integrates to ∝ t⁴. With this noise the two meet near 2 s: the model then under-predicts δv_z.
constexpr double kWindowEndS = 1.5;
constexpr double kBeyondWindowS = 2.0;

struct McSigma {
  std::vector<double> t_s;
  std::vector<std::array<double, kNav>> sigma;  // sample σ per check time
};

/// Sample σ of the twelve navigation errors over kSeeds noisy runs (errors against the truth:
/// the clean run's deterministic discretisation error only shifts the mean).
McSigma monte_carlo(const Trajectory& traj, double duration_s, const std::vector<double>& times_s) {
  const auto geometry = nav::table1_geometry<double>(kRhoM);
  const auto gravity = nav::GravityModel<double>::constant(nav::kStandardGravity);
  const IdealArrayModel<6> array(geometry, gravity);
  const auto solver = nav::ArraySolver<double>::create(geometry).value();
  const auto steps = static_cast<std::size_t>(std::llround(duration_s / kMcDtS));
  std::vector<Vec6d> ideal(steps + 1);
  std::vector<TruthState> truth(steps + 1);
  for (std::size_t k = 0; k <= steps; ++k) {
    truth[k] = traj.at(static_cast<double>(k) * kMcDtS);
    ideal[k] = array.outputs(truth[k]);
  }
  std::vector<std::size_t> check_k;
  for (const double t : times_s) {
    check_k.push_back(static_cast<std::size_t>(std::llround(t / kMcDtS)));
  }
  // Welford-free: sums and sums of squares in double (errors ≪ 1, 1000 terms: no cancellation).
  std::vector<std::array<double, kNav>> sum(check_k.size()), sum2(check_k.size());
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed) + 1);
    std::normal_distribution<double> normal(0.0, kNoiseMps2);
    const auto noisy = [&](std::size_t k) {
      Vec6d s = ideal[k];
      for (int j = 0; j < 6; ++j) s(j) += normal(rng);
      return s;
    };
    nav::Strapdown<double> sd(solver, gravity);
    const nav::NavState<double> init = to_nav_state<double>(truth[0]);
    sd.initialize(init, noisy(0));
    std::size_t next = 0;
    for (std::size_t k = 1; k <= steps && next < check_k.size(); ++k) {
      sd.step(noisy(k), kMcDtS, static_cast<std::int64_t>(k) * 10'000'000,
              static_cast<std::uint32_t>(k));
      if (k != check_k[next]) continue;
      const auto& s = sd.state();
      Eigen::Matrix<double, kNav, 1> e;
      e << nav::attitude_error_n(s.q_nb, truth[k].q_nb), s.r_n - truth[k].r_n, s.v_n - truth[k].v_n,
          s.w_b - truth[k].w_b;
      for (int i = 0; i < kNav; ++i) {
        sum[next][static_cast<std::size_t>(i)] += e(i);
        sum2[next][static_cast<std::size_t>(i)] += e(i) * e(i);
      }
      ++next;
    }
  }
  McSigma r;
  for (std::size_t c = 0; c < check_k.size(); ++c) {
    r.t_s.push_back(static_cast<double>(check_k[c]) * kMcDtS);
    std::array<double, kNav> sig{};
    for (std::size_t i = 0; i < kNav; ++i) {
      const double n = kSeeds;
      const double mean = sum[c][i] / n;
      sig[i] = std::sqrt(std::max(0.0, (sum2[c][i] - n * mean * mean) / (n - 1)));
    }
    r.sigma.push_back(sig);
  }
  return r;
}

CovarianceSpec white_noise_spec(const Trajectory& traj, double duration_s, double dt_s) {
  CovarianceSpec spec;
  spec.trajectory = &traj;
  spec.geometry = nav::table1_geometry<double>(kRhoM);
  spec.duration_s = duration_s;
  spec.dt_s = dt_s;
  spec.decimation = 1;
  spec.noise.white_sigma_mps2.fill(kNoiseMps2);
  return spec;
}

McSigma expect_covariance_matches_monte_carlo(const Trajectory& traj, double duration_s) {
  // Given white noise of kNoiseMps2 on every sensor,
  std::vector<double> times(kCheckTimesS.begin(), kCheckTimesS.end());
  if (duration_s > kWindowEndS) times.push_back(kBeyondWindowS);
  const McSigma mc = monte_carlo(traj, duration_s, times);
  // when the covariance is propagated along the same truth,
  const CovarianceResult cov = propagate_covariance(white_noise_spec(traj, duration_s, kMcDtS));
  // then every state's predicted 1σ is within kRelTol of the sample σ at every check time.
  for (std::size_t c = 0; c < mc.t_s.size(); ++c) {
    const auto k = static_cast<std::size_t>(std::llround(mc.t_s[c] / kMcDtS));
    if (k >= cov.t_s.size() || std::abs(cov.t_s[k] - mc.t_s[c]) > 1e-9) {
      ADD_FAILURE() << "covariance samples do not line up with the Monte-Carlo check times";
      return {};
    }
    std::printf("%s t=%.2f s  predicted/sample σ:", traj.name().c_str(), mc.t_s[c]);
    for (std::size_t i = 0; i < kNav; ++i) {
      const double ratio = cov.sigma[i][k] / mc.sigma[c][i];
      std::printf(" %.3f", ratio);
      if (mc.t_s[c] > kWindowEndS + 1e-9) continue;  // reported, checked by the caller
      EXPECT_NEAR(ratio, 1.0, kRelTol) << kErrorStateNames[i] << " at t = " << mc.t_s[c];
    }
    std::printf("\n");
  }
  McSigma out = mc;
  for (std::size_t c = 0; c < mc.t_s.size(); ++c) {
    const auto k = static_cast<std::size_t>(std::llround(mc.t_s[c] / kMcDtS));
    for (std::size_t i = 0; i < kNav; ++i) out.sigma[c][i] = cov.sigma[i][k] / mc.sigma[c][i];
  }
  return out;  // the ratios predicted/sample
}

TEST(CovarianceMonteCarloTest, AtRestPredictedSigmaWithinTenPercent) {
  const auto traj = make_rest(nav::quat_from_euler(0.1, -0.05, 0.3));
  const McSigma ratio = expect_covariance_matches_monte_carlo(*traj, kMcDurationS);
  // Beyond the window the second-order vertical term shows: the sample σ of δv_z exceeds the
  // prediction by more than the 10 % the window allows (measured 0.85 with these seeds).
  ASSERT_EQ(ratio.t_s.size(), kCheckTimesS.size() + 1);
  EXPECT_LT(ratio.sigma.back()[nav::err_idx::kVel + 2], 1.0 - kRelTol);
}

TEST(CovarianceMonteCarloTest, ManeuverPredictedSigmaWithinTenPercent) {
  const auto traj = make_maneuver(1.0);
  (void)expect_covariance_matches_monte_carlo(*traj, kWindowEndS);
}

}  // namespace
}  // namespace gfins::sim
