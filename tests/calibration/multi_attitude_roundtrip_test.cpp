// Round trip on simulation: random scale factors, biases and orientation errors → static outputs
// (mean of N noisy samples, through nav::misaligned_geometry and model (16)) → calibration. Every
// parameter must fall within its reported uncertainty as often as a Gaussian says it should.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "gfins/nav_core/calibration/multi_attitude.hpp"
#include "gfins/nav_core/misalignment.hpp"

namespace gfins::calib {
namespace {

constexpr int kSeeds = 200;
constexpr int kSamplesPerPose = 100;    // N samples averaged per pose
constexpr double kSampleNoiseV = 2e-3;  // σ of one sample, V (σ of a mean: 0.2 mV)
// Parameter ranges of the brief: SF 0.3-2.5 V/g, |b| ≤ 10 mg, |angle| ≤ 3°.
constexpr double kMinScale = 0.3;
constexpr double kMaxScale = 2.5;
constexpr double kMaxBiasG = 0.010;
constexpr double kMaxAngleRad = 3.0 * 3.14159265358979323846 / 180.0;

// Coverage: for a Gaussian estimate P(|e| ≤ 3σ) = 0.9973. Over n = 24 · kSeeds marginals the
// count outside has mean n·0.0027 and sd √(n·0.0027); we accept up to mean + 5 sd (and never
// below the brief's 97 %). An estimator whose σ were underestimated by 1.5× would put ~2.6 % out.
constexpr double kGaussianInside3Sigma = 0.9973;
constexpr double kOutsideSdAllowed = 5.0;
constexpr double kBriefMinFraction = 0.97;
// χ²: Σ eᵀ Σ⁻¹ e over 6 sensors × kSeeds, 4 dof each, divided by its dof has mean 1 and sd
// √(2/dof) (0.02 for 4800 dof); accepted within 5 sd. σ estimated from N = 100 samples adds a
// relative 1/(2N) = 0.5 % bias upwards, well inside.
constexpr double kChi2SdAllowed = 5.0;

struct Truth {
  std::array<double, 6> scale{};
  std::array<double, 6> bias{};
  nav::OrientationErrors<double> angles{};
};

Truth random_truth(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> sf(kMinScale, kMaxScale);
  std::uniform_real_distribution<double> b(-kMaxBiasG, kMaxBiasG);
  std::uniform_real_distribution<double> ang(-kMaxAngleRad, kMaxAngleRad);
  Truth t;
  for (std::size_t i = 0; i < 6; ++i) {
    t.scale[i] = sf(rng);
    t.bias[i] = b(rng);
    t.angles.beta[i] = ang(rng);
    t.angles.alpha[i] = ang(rng);
  }
  return t;
}

// Simulated pose: N samples P = SF (b + θ*·a) + noise; mean and sample std as a recorder gives.
void simulate(const Truth& t, std::span<AttitudeObservation<double>> obs, std::mt19937_64& rng) {
  nav::Misalignment<double> m;
  m.orientation = t.angles;
  const auto geo = nav::misaligned_geometry(nav::table1_geometry(1.0), m);
  std::normal_distribution<double> noise(0.0, kSampleNoiseV);
  for (auto& o : obs) {
    const nav::Vec3<double> a(o.f_b_g[0], o.f_b_g[1], o.f_b_g[2]);
    o.sample_count = kSamplesPerPose;
    for (std::size_t i = 0; i < 6; ++i) {
      const double p = t.scale[i] * (t.bias[i] + geo.theta_b[i].dot(a));
      double sum = 0.0;
      double sum2 = 0.0;
      for (int k = 0; k < kSamplesPerPose; ++k) {
        const double x = p + noise(rng);
        sum += x;
        sum2 += x * x;
      }
      const double mean = sum / kSamplesPerPose;
      o.mean_v[i] = mean;
      o.sample_std_v[i] = std::sqrt((sum2 - kSamplesPerPose * mean * mean) / (kSamplesPerPose - 1));
    }
  }
}

// Errors of (SF, b, angle A, angle B) of sensor i.
Eigen::Vector4d errors(const MultiAttitudeResult<double>& r, const Truth& t, std::size_t i) {
  const auto angle = [&](const nav::OrientationErrors<double>& o, std::size_t k) {
    const bool alpha = i == 0 || i == 3 || i == 5;
    return alpha ? o.alpha[k] : o.beta[k];
  };
  const std::size_t ka = r.covariance_angle[i][0];
  const std::size_t kb = r.covariance_angle[i][1];
  return {r.scale_v_per_g[i] - t.scale[i], r.bias_g[i] - t.bias[i],
          angle(r.orientation, ka) - angle(t.angles, ka),
          angle(r.orientation, kb) - angle(t.angles, kb)};
}

struct Coverage {
  int inside = 0;
  int total = 0;
  double chi2 = 0.0;
  int chi2_dof = 0;
};

void accumulate(const MultiAttitudeResult<double>& r, const Truth& t, Coverage& c) {
  for (std::size_t i = 0; i < 6; ++i) {
    const Eigen::Vector4d e = errors(r, t, i);
    const Eigen::Matrix4d cov =
        Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(r.covariance[i].data());
    for (int k = 0; k < 4; ++k) {
      c.inside += std::abs(e(k)) <= 3.0 * std::sqrt(cov(k, k)) ? 1 : 0;
      ++c.total;
    }
    c.chi2 += e.dot(cov.ldlt().solve(e));
    c.chi2_dof += 4;
  }
}

void expect_consistent(const Coverage& c) {
  const double n = c.total;
  const double expected_out = n * (1.0 - kGaussianInside3Sigma);
  const double max_out = expected_out + kOutsideSdAllowed * std::sqrt(expected_out);
  const double fraction = c.inside / n;
  EXPECT_GE(fraction, kBriefMinFraction);
  EXPECT_LE(n - c.inside, max_out) << "fraction within 3 sigma " << fraction;
  const double chi2_per_dof = c.chi2 / c.chi2_dof;
  EXPECT_NEAR(chi2_per_dof, 1.0, kChi2SdAllowed * std::sqrt(2.0 / c.chi2_dof));
  ::testing::Test::RecordProperty("fraction_within_3sigma", std::to_string(fraction));
  ::testing::Test::RecordProperty("chi2_per_dof", std::to_string(chi2_per_dof));
}

std::vector<AttitudeObservation<double>> board_poses() {
  // Six faces down plus two body diagonals, every sensor recorded in every pose.
  const double k = 1.0 / std::sqrt(3.0);
  const std::array<std::array<double, 3>, 8> f = {{{1, 0, 0},
                                                   {-1, 0, 0},
                                                   {0, 1, 0},
                                                   {0, -1, 0},
                                                   {0, 0, 1},
                                                   {0, 0, -1},
                                                   {k, k, k},
                                                   {-k, k, -k}}};
  std::vector<AttitudeObservation<double>> obs(f.size());
  for (std::size_t j = 0; j < f.size(); ++j) obs[j].f_b_g = f[j];
  return obs;
}

TEST(MultiAttitudeRoundTrip, PaperPosesWithStatedSigmaAreConsistent) {
  // Given the paper's twelve poses (Table 2 for set β, Table 3 for set α) and random truths
  Coverage c;
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    const Truth t = random_truth(rng);
    auto obs = paper_observations(PaperTableOutputs<double>{});
    simulate(t, obs, rng);
    // When calibrated with the σ of each mean
    const auto r =
        calibrate_multi_attitude<double>(std::span<const AttitudeObservation<double>>(obs));
    ASSERT_TRUE(r.is_ok()) << r.status().message();
    ASSERT_EQ(r->covariance_source[0], CovarianceSource::kStatedSigma);
    accumulate(r.value(), t, c);
  }
  // Then the errors are distributed as the reported covariance says
  expect_consistent(c);
}

TEST(MultiAttitudeRoundTrip, GeneralPosesWithStatedSigmaAreConsistent) {
  Coverage c;
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::mt19937_64 rng(1000u + static_cast<std::uint64_t>(seed));
    const Truth t = random_truth(rng);
    auto obs = board_poses();
    simulate(t, obs, rng);
    const auto r =
        calibrate_multi_attitude<double>(std::span<const AttitudeObservation<double>>(obs));
    ASSERT_TRUE(r.is_ok()) << r.status().message();
    EXPECT_EQ(r->verdict, Verdict::kGood) << to_string(r->verdict);
    accumulate(r.value(), t, c);
  }
  expect_consistent(c);
}

TEST(MultiAttitudeRoundTrip, ResidualCovarianceCoversTheTruth) {
  // Given many poses and no σ: the covariance comes from the residuals (Student t with
  // n − 4 = 20 dof: P(|t| ≤ 3) = 0.9930, so the expected count outside is 0.7 % of the total)
  constexpr double kStudentT20Inside3 = 0.9930;
  Coverage c;
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::mt19937_64 rng(5000u + static_cast<std::uint64_t>(seed));
    const Truth t = random_truth(rng);
    std::vector<AttitudeObservation<double>> obs(24);
    std::normal_distribution<double> z(0.0, 1.0);
    for (auto& o : obs) {
      const nav::Vec3<double> v = nav::Vec3<double>(z(rng), z(rng), z(rng)).normalized();
      o.f_b_g = {v.x(), v.y(), v.z()};
    }
    simulate(t, obs, rng);
    for (auto& o : obs) o.sample_count = 0;  // σ not given
    const auto r =
        calibrate_multi_attitude<double>(std::span<const AttitudeObservation<double>>(obs));
    ASSERT_TRUE(r.is_ok()) << r.status().message();
    ASSERT_EQ(r->covariance_source[2], CovarianceSource::kResiduals);
    accumulate(r.value(), t, c);
  }
  const double n = c.total;
  const double expected_out = n * (1.0 - kStudentT20Inside3);
  EXPECT_LE(n - c.inside, expected_out + kOutsideSdAllowed * std::sqrt(expected_out));
  EXPECT_GE(c.inside / n, kBriefMinFraction);
}

TEST(MultiAttitudeRoundTrip, NoiseFreeDataIsRecoveredExactly) {
  // Given noise-free outputs of a random truth in the paper's poses
  constexpr double kExactTol = 1e-12;  // double rounding; the model is exactly invertible
  std::mt19937_64 rng(7);
  const Truth t = random_truth(rng);
  auto obs = paper_observations(PaperTableOutputs<double>{});
  nav::Misalignment<double> m;
  m.orientation = t.angles;
  const auto geo = nav::misaligned_geometry(nav::table1_geometry(1.0), m);
  for (auto& o : obs) {
    const nav::Vec3<double> a(o.f_b_g[0], o.f_b_g[1], o.f_b_g[2]);
    for (std::size_t i = 0; i < 6; ++i) {
      o.mean_v[i] = t.scale[i] * (t.bias[i] + geo.theta_b[i].dot(a));
    }
  }
  PaperTableOutputs<double> p;
  for (std::size_t j = 0; j < 12; ++j) {
    for (std::size_t i = 0; i < 6; ++i) {
      if (obs[j].used_mask & (1u << i)) p.mean_v[i][j % 6] = obs[j].mean_v[i];
    }
  }
  // When both routes calibrate
  const auto general =
      calibrate_multi_attitude<double>(std::span<const AttitudeObservation<double>>(obs));
  const auto paper = calibrate_paper_procedure<double>(p);
  ASSERT_TRUE(general.is_ok() && paper.is_ok());
  // Then both recover the truth to rounding
  for (const auto* r : {&general.value(), &paper.value()}) {
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_NEAR(r->scale_v_per_g[i], t.scale[i], kExactTol);
      EXPECT_NEAR(r->bias_g[i], t.bias[i], kExactTol);
      EXPECT_NEAR(r->orientation.beta[i], t.angles.beta[i], kExactTol);
      EXPECT_NEAR(r->orientation.alpha[i], t.angles.alpha[i], kExactTol);
    }
  }
}

}  // namespace
}  // namespace gfins::calib
