// The stated σ of gfins-calibrate --location-runs (tools::run_location_calibration) against a
// Monte-Carlo over the base calibration and the runs' noise (docs/calibration.md, location σ).
//
// The user's situation: the base (multi-attitude) calibration of SF, bias and angles is itself an
// estimate, off the truth by an error with the covariance its file states; the rate-table runs
// add their own noise. The stated covariance of Δρ must cover both.
//
// Oracle, written here and independent of the solver: the forward physics of a sensor on a rate
// table (paper eqs. (19)-(21); f_j = a + ω̇×ρ*_j + ω×(ω×ρ*_j) − g with a = 0 and ω̇ = 0 at constant
// rate about an axis through o_b, projected on the true axis θ*_j of eqs. (14)/(15), written out
// below; P = SF (f·θ*/g + b)), the base file drawn as truth + an error from the covariance it
// states, and the empirical scatter of the recovered Δρ around the truth over many draws.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "calibrate.hpp"
#include "gfins/calib_file/calibration_data.hpp"
#include "paper_axes_oracle.hpp"

namespace gfins::tools {
namespace {

using test_oracle::axes_of;
using test_oracle::Place;
using test_oracle::place_of;

// The calibration-board scenario's truth (host_sim/scenarios/calibration-board.toml) and its
// 24.8° site (WGS-84 normal gravity at 50 m).
constexpr double kRho = 0.1;     // m, cube half-size
constexpr double kG = 9.789262;  // WGS-84 normal gravity at 24.8°, 50 m (Somigliana + free air)
constexpr std::array<double, 6> kScale{1.31, 1.35, 1.29, 1.37, 1.33, 1.30};  // V/g
constexpr std::array<double, 6> kBiasG{0.002, -0.0015, 0.003, -0.0025, 0.001, -0.0005};
constexpr std::array<double, 6> kBetaDeg{0.8, -1.2, 0.5, 1.5, -0.7, 0.9};
constexpr std::array<double, 6> kAlphaDeg{-1.1, 0.6, 1.3, -0.4, 0.2, -1.6};
constexpr std::array<double, 18> kDrhoMm{1.0,  -0.5, 0.3, -0.8, 0.6,  0.2,  0.4, 0.9,  -0.7,
                                         -0.3, 0.5,  1.2, 0.7,  -0.2, -0.6, 0.1, -0.9, 0.8};
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// The runs of docs/calibration.md §5: five mountings (body axis up), 2, 6 and 10 rad/s, 6000
// samples each, 0.5 mg per-sample noise (the scenario's).
constexpr std::array<std::array<double, 3>, 5> kUp{{{1, 0, 0},
                                                    {0, 1, 0},
                                                    {0, 0, 1},
                                                    {0.7071067811865476, 0.7071067811865476, 0},
                                                    {0.7071067811865476, 0, 0.7071067811865476}}};
constexpr std::array<double, 3> kRates{2.0, 6.0, 10.0};
constexpr std::uint32_t kCount = 6000;
constexpr double kNoiseG = 0.5e-3;

// The base file's stated uncertainty per sensor, (SF [V/g], b [g], angle a1 [rad], angle a2
// [rad]): chosen so that the base's share of the Δρ variance about equals the runs' (measured
// ratio 0.97), as on the simulated board captured through the firmware (docs/calibration.md §5),
// with correlations of both signs.
constexpr std::array<double, 4> kBaseSigma{1.2e-5, 1.6e-6, 6e-6, 6e-6};
constexpr std::array<double, 6> kBaseCorrelation{0.3, -0.4, 0.2, 0.1, -0.3, 0.5};

// Monte-Carlo size: kDraws × 18 components.
constexpr int kDraws = 1000;
// Pooled χ² of the 6·kDraws independent 3-vectors e_j against their stated 3×3 covariance:
// χ² with 18·kDraws = 18000 dof, χ²/dof has sd √(2/18000) = 0.0105; 5 sd either side fails a
// correct σ with probability 5.7e-7 (normal limit, exact to 1e-3 of that at this dof), and fails a
// σ 5 % too small or too large (χ²/dof 1.11 or 0.91).
constexpr double kChi2Sd = 0.0105409;  // √(2/18000)
constexpr double kChi2Band = 5.0 * kChi2Sd;
// Mean of the per-component z² with the file's per-component σ: the three z of one sensor are
// correlated, Var(Σ_k z_k²) = 2 Σ_ab ρ_ab² ≤ 18, so the mean over 18·kDraws has sd ≤ √(18 ·
// 6 kDraws)/(18 kDraws) = √(1/(3 kDraws)) = 0.0183; 5 sd: false failure below 5.7e-7.
constexpr double kZ2Band = 5.0 * 0.0182574;

struct Truth {
  std::array<Eigen::Vector3d, 6> rho_star;    // ρ_j + Δρ_j, m
  std::array<Eigen::Vector3d, 6> theta_star;  // true sensitive axes
};

// Table 1 of the paper (nominal positions and axes), written here.
std::array<Eigen::Vector3d, 6> table1_rho() {
  return {Eigen::Vector3d(0, 0, -kRho), Eigen::Vector3d(0, -kRho, 0), Eigen::Vector3d(-kRho, 0, 0),
          Eigen::Vector3d(kRho, 0, 0),  Eigen::Vector3d(0, kRho, 0),  Eigen::Vector3d(0, 0, kRho)};
}
Truth make_truth() {
  Truth t;
  std::array<double, 6> b{};
  std::array<double, 6> a{};
  for (std::size_t i = 0; i < 6; ++i) {
    b[i] = kBetaDeg[i] * kDegToRad;
    a[i] = kAlphaDeg[i] * kDegToRad;
  }
  t.theta_star = axes_of(b, a);
  const auto rho = table1_rho();
  for (std::size_t j = 0; j < 6; ++j) {
    t.rho_star[j] =
        rho[j] + 1e-3 * Eigen::Vector3d(kDrhoMm[3 * j], kDrhoMm[3 * j + 1], kDrhoMm[3 * j + 2]);
  }
  return t;
}

Eigen::Matrix4d base_covariance_of_sensor() {
  const std::array<std::array<int, 2>, 6> at{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
  Eigen::Matrix4d r = Eigen::Matrix4d::Identity();
  for (std::size_t k = 0; k < 6; ++k) {
    r(at[k][0], at[k][1]) = kBaseCorrelation[k];
    r(at[k][1], at[k][0]) = kBaseCorrelation[k];
  }
  const Eigen::Vector4d s(kBaseSigma[0], kBaseSigma[1], kBaseSigma[2], kBaseSigma[3]);
  return s.asDiagonal() * r * s.asDiagonal();
}

// One base file: the truth plus a draw from the covariance it states.
calib_file::CalibrationData draw_base(std::mt19937_64& rng, const Eigen::Matrix4d& chol_lower) {
  std::normal_distribution<double> n01;
  calib_file::CalibrationData d;
  d.device_id = "mc";
  d.created_utc = "2026-01-01T00:00:00Z";
  d.geometry.rho_m = kRho;
  d.gravity_mps2 = kG;
  d.gravity_source = "given";
  for (std::size_t i = 0; i < 6; ++i) {
    d.beta.angle_deg[i] = kBetaDeg[i];
    d.alpha.angle_deg[i] = kAlphaDeg[i];
    // Each sensor owns angles 2r (σ kBaseSigma[2]) and 2r+1 (kBaseSigma[3]) of its set.
    d.beta.angle_sigma_deg[i] = kBaseSigma[2 + i % 2] / kDegToRad;
    d.alpha.angle_sigma_deg[i] = kBaseSigma[2 + i % 2] / kDegToRad;
  }
  for (int j = 0; j < 6; ++j) {
    const auto js = static_cast<std::size_t>(j);
    const Eigen::Vector4d e = chol_lower * Eigen::Vector4d(n01(rng), n01(rng), n01(rng), n01(rng));
    auto& s = d.sensors[js];
    s.adc_lsb_v_per_count = 1e-6;
    s.scale_v_per_g = kScale[js] + e(0);
    s.scale_sigma_v_per_g = kBaseSigma[0];
    s.bias_g = kBiasG[js] + e(1);
    s.bias_sigma_g = kBaseSigma[1];
    s.correlation = kBaseCorrelation;
    const Place p = place_of(js);
    auto& angles = p.alpha ? d.alpha.angle_deg : d.beta.angle_deg;
    angles[2 * p.row] += e(2) / kDegToRad;
    angles[2 * p.row + 1] += e(3) / kDegToRad;
  }
  return d;
}

// The runs a table would give: mean volts of each sensor (noise of the mean drawn here).
std::vector<LocationRunRow> draw_runs(std::mt19937_64& rng, const Truth& t) {
  std::normal_distribution<double> n01;
  std::vector<LocationRunRow> rows;
  int line = 2;
  for (std::size_t m = 0; m < kUp.size(); ++m) {
    const Eigen::Vector3d up(kUp[m][0], kUp[m][1], kUp[m][2]);
    for (const double rate : kRates) {
      LocationRunRow row;
      row.mounting = static_cast<int>(m);
      row.axis_up_b = kUp[m];
      row.rate_rad_s = rate;
      row.count = kCount;
      row.line = line++;
      const Eigen::Vector3d w = rate * up.normalized();
      const Eigen::Vector3d gravity_b = -kG * up.normalized();  // down
      for (std::size_t j = 0; j < 6; ++j) {
        // f = a + ω̇×ρ* + ω×(ω×ρ*) − g, a = 0, ω̇ = 0; P = SF (f·θ*/g + b).
        const Eigen::Vector3d f = w.cross(w.cross(t.rho_star[j])) - gravity_b;
        const double std_v = kNoiseG * kScale[j];
        row.std_v[j] = std_v;
        row.mean_v[j] = kScale[j] * (f.dot(t.theta_star[j]) / kG + kBiasG[j]) +
                        std_v / std::sqrt(static_cast<double>(kCount)) * n01(rng);
      }
      rows.push_back(row);
    }
  }
  return rows;
}

struct Tally {
  double chi2_total = 0.0;         // against the stated covariance (runs + base)
  double chi2_runs = 0.0;          // against the runs' part alone (the σ stated before)
  double chi2_uncorrelated = 0.0;  // base σ without the correlations (a format version 2 file)
  double z2_sum = 0.0;             // per component against the file's σ
  int beyond3 = 0;                 // per components beyond 3σ
  int components = 0;
  int vectors = 0;
  double base_over_runs = 0.0;  // mean trace ratio, for the printout
};

TEST(LocationSigma, StatedCovarianceMatchesAMonteCarloOverBaseCalibrationsAndRunNoise) {
  const Truth t = make_truth();
  const Eigen::Matrix4d base = base_covariance_of_sensor();
  const Eigen::LLT<Eigen::Matrix4d> llt(base);
  ASSERT_EQ(llt.info(), Eigen::Success) << "the test's base covariance is not positive definite";
  const Eigen::Matrix4d chol = llt.matrixL();
  std::mt19937_64 rng(20261123);
  Tally tally;
  for (int draw = 0; draw < kDraws; ++draw) {
    const calib_file::CalibrationData cal = draw_base(rng, chol);
    const std::vector<LocationRunRow> rows = draw_runs(rng, t);
    const auto rep = run_location_calibration(rows, cal, 1e-3, "mc.csv");
    ASSERT_TRUE(rep.is_ok()) << rep.error().message;
    const auto& r = rep.value();
    ASSERT_TRUE(r.solution.fully_observable());
    calib_file::CalibrationData v2 = cal;
    v2.correlations_known = false;
    for (auto& sc : v2.sensors) sc.correlation = {};
    const auto rep_v2 = run_location_calibration(rows, v2, 1e-3, "mc.csv");
    ASSERT_TRUE(rep_v2.is_ok()) << rep_v2.error().message;
    for (std::size_t j = 0; j < 6; ++j) {
      const Eigen::Vector3d truth =
          1e-3 * Eigen::Vector3d(kDrhoMm[3 * j], kDrhoMm[3 * j + 1], kDrhoMm[3 * j + 2]);
      const Eigen::Vector3d est(r.drho_m[j][0], r.drho_m[j][1], r.drho_m[j][2]);
      const Eigen::Vector3d e = est - truth;
      const Eigen::Matrix3d runs = r.solution.drho_cov_m2[j];
      const Eigen::Matrix3d total = runs + r.base_cov_m2[j];
      tally.chi2_total += e.dot(total.ldlt().solve(e));
      tally.chi2_runs += e.dot(runs.ldlt().solve(e));
      const Eigen::Matrix3d v2_total = runs + rep_v2.value().base_cov_m2[j];
      tally.chi2_uncorrelated += e.dot(v2_total.ldlt().solve(e));
      tally.base_over_runs += r.base_cov_m2[j].trace() / runs.trace();
      ++tally.vectors;
      for (std::size_t k = 0; k < 3; ++k) {
        const double z = e(static_cast<Eigen::Index>(k)) / r.sigma_m[j][k];
        tally.z2_sum += z * z;
        tally.beyond3 += std::abs(z) > 3.0;
        ++tally.components;
      }
    }
  }
  const double dof = 3.0 * tally.vectors;
  const double chi2 = tally.chi2_total / dof;
  const double chi2_runs = tally.chi2_runs / dof;
  const double z2 = tally.z2_sum / tally.components;
  std::printf("chi2/dof with the base sigma but no correlations: %.4f\n",
              tally.chi2_uncorrelated / dof);
  std::printf(
      "%d draws: chi2/dof %.4f with the stated covariance (runs + base), %.3f with the runs' "
      "noise alone; mean z^2 per component %.4f, %d of %d beyond 3 sigma; base/runs variance "
      "ratio %.2f\n",
      kDraws, chi2, chi2_runs, z2, tally.beyond3, tally.components,
      tally.base_over_runs / tally.vectors);
  EXPECT_NEAR(chi2, 1.0, kChi2Band);
  EXPECT_NEAR(z2, 1.0, kZ2Band);
  // The criterion can fail: the runs' noise alone (the σ stated before) is far outside it.
  EXPECT_GT(chi2_runs, 1.0 + kChi2Band);
}

TEST(LocationSigma, ABaseFileWithoutCorrelationsIsUsedWithZeroCorrelationAndTheReportSaysSo) {
  const Truth t = make_truth();
  std::mt19937_64 rng(7);
  const Eigen::Matrix4d zero = Eigen::Matrix4d::Zero();
  calib_file::CalibrationData cal = draw_base(rng, zero);
  cal.correlations_known = false;  // as loaded from a format version 1 or 2 file
  for (auto& s : cal.sensors) s.correlation = {};
  const auto rep = run_location_calibration(draw_runs(rng, t), cal, 1e-3, "runs.csv");
  ASSERT_TRUE(rep.is_ok()) << rep.error().message;
  std::string text;
  for (const auto& l : rep.value().lines) text += l + "\n";
  EXPECT_NE(text.find("predates format version 3"), std::string::npos) << text;
  EXPECT_NE(text.find("taken as 0"), std::string::npos) << text;
  // And the base part is there: the σ of SF, b and the angles alone give a nonzero covariance.
  for (const auto& c : rep.value().base_cov_m2) EXPECT_GT(c.trace(), 0.0);
  EXPECT_EQ(text.find("states sigma = 0"), std::string::npos) << text;
}

TEST(LocationSigma, ABaseWithoutAnyStatedSigmaIsNamedInTheReport) {
  // Given a base whose sensor 4 states σ = 0 for SF, b and both its angles (yx, yz of set α)
  const Truth t = make_truth();
  std::mt19937_64 rng(11);
  calib_file::CalibrationData cal = draw_base(rng, Eigen::Matrix4d::Zero());
  cal.sensors[3].scale_sigma_v_per_g = 0.0;
  cal.sensors[3].bias_sigma_g = 0.0;
  cal.alpha.angle_sigma_deg[2] = 0.0;
  cal.alpha.angle_sigma_deg[3] = 0.0;
  const auto rep = run_location_calibration(draw_runs(rng, t), cal, 1e-3, "runs.csv");
  ASSERT_TRUE(rep.is_ok()) << rep.error().message;
  std::string text;
  for (const auto& l : rep.value().lines) text += l + "\n";
  // Then the report names it (and only it), and its base part is zero
  EXPECT_NE(text.find("states sigma = 0 for SF, bias and angles of a4 ("), std::string::npos)
      << text;
  EXPECT_EQ(rep.value().base_cov_m2[3].trace(), 0.0);
  EXPECT_GT(rep.value().base_cov_m2[0].trace(), 0.0);
}

}  // namespace
}  // namespace gfins::tools
