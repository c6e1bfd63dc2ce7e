// The predicted σ of gfins-calibrate --verify (tools::verify_calibration) against a Monte-Carlo
// over calibration errors drawn from the covariance the file states (docs/calibration.md §7).
//
// The user's situation: the installed calibration (SF, bias, angles) is an estimate, off the
// truth by an error with the covariance its file states — σ and, since format version 3, the
// correlations of each sensor's (SF, b, a1, a2). A verification pose then shows residuals whose
// scatter is that error seen through the measurement model, plus the capture's noise. The
// predicted σ must match that scatter; with the paper's Tables 4/5 the SF–angle correlations are
// strong (sensor 1: −0.69 and +0.86), so ignoring them misstates it.
//
// Oracle, written here and independent of the tool: the forward physics of a sensor in a static
// pose (f_j = a + ω̇×ρ*_j + ω×(ω×ρ*_j) − g with a = ω̇ = ω = 0, i.e. −g, projected on the true
// axis θ*_j = Σ_k C_rk θ_k of eqs. (14)/(15) written out below; P = SF (f·θ*/g + b), eq. (21)),
// calibration errors drawn here from the file's σ and correlations (own Cholesky), the residual
// P − SF(b + θ*·f) of each drawn file computed here, and its empirical scatter over many draws.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "calibrate.hpp"
#include "gfins/calib_file/calibration_data.hpp"
#include "paper_axes_oracle.hpp"

namespace gfins::tools {
namespace {

using test_oracle::Place;
using test_oracle::place_of;

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr double kG = 9.7894;  // m/s², WGS-84 normal gravity at 24.8° (the paper's site)

// Verification poses, none of them a pose of Tables 2/3: specific force sensed, in g (body FRD).
// 13 is the 30° tilt of docs/calibration.md; 14 level; 15 upside down; 16 nose down (x up);
// 17 right wing down (f points up, along −y); 18 a 45°/45° tilt.
constexpr std::array<std::array<double, 3>, 6> kPoses{{{0.0, 0.5, -0.8660254037844386},
                                                       {0.0, 0.0, -1.0},
                                                       {0.0, 0.0, 1.0},
                                                       {1.0, 0.0, 0.0},
                                                       {0.0, -1.0, 0.0},
                                                       {0.5, 0.5, -0.7071067811865476}}};
constexpr int kFirstPose = 13;
// The capture: 0.5 mg per sample (the calibration-board scenario's noise), 2000 samples.
constexpr double kNoiseG = 0.5e-3;
constexpr std::uint32_t kCount = 2000;

// Monte-Carlo size and criterion. For one (pose, sensor) cell, z = residual / predicted σ is
// Gaussian with unit variance when the prediction is right (the residual is linear in the
// calibration error to first order; the second-order terms are ~1e-3 of the first here, far below
// the band), so Σ z² over kDraws independent draws is χ² with kDraws dof. The band on the mean z²
// is its 2.87e-7 and 1 − 2.87e-7 quantiles (normal ±5 sd on the Wilson–Hilferty cube-root
// transform, accurate to far better than 1 % of the tail at 20000 dof): a correct σ fails one cell
// with probability 5.7e-7, the 36 cells with at most 36 · 5.7e-7 = 2.1e-5. The band is about
// ±0.05, so a variance misstated by 6 % fails.
constexpr int kDraws = 20000;
constexpr double kBandSd = 5.0;
double chi2_mean_bound(double sd_multiple) {
  const double v = 2.0 / (9.0 * kDraws);  // Wilson–Hilferty: (χ²/n)^(1/3) ~ N(1 − v, v)
  return std::pow(1.0 - v + sd_multiple * std::sqrt(v), 3.0);
}
// The tool's residual must be the test's to rounding: a few ULP of ~2.5 V outputs.
constexpr double kResidualTolV = 1e-12;

// θ*_j of every sensor from a file's angles (deg).
std::array<Eigen::Vector3d, 6> axes_of(const calib_file::CalibrationData& d) {
  std::array<double, 6> beta_rad{};
  std::array<double, 6> alpha_rad{};
  for (std::size_t i = 0; i < 6; ++i) {
    beta_rad[i] = d.beta.angle_deg[i] * kDegToRad;
    alpha_rad[i] = d.alpha.angle_deg[i] * kDegToRad;
  }
  return test_oracle::axes_of(beta_rad, alpha_rad);
}

// Specific force at a sensor, m/s²: f = a + ω̇×ρ* + ω×(ω×ρ*) − g (g the gravity vector, body).
Eigen::Vector3d specific_force(const Eigen::Vector3d& a, const Eigen::Vector3d& wdot,
                               const Eigen::Vector3d& w, const Eigen::Vector3d& rho_star,
                               const Eigen::Vector3d& gravity_b) {
  return a + wdot.cross(rho_star) + w.cross(w.cross(rho_star)) - gravity_b;
}

// The paper's Tables 4/5 solved by the paper route (no σ with the means: σ from the fit
// residuals), as `gfins-calibrate --means paper_tables_4_5.csv` writes it.
calib_file::CalibrationData paper_file() {
  const auto means = read_means(std::string(GFINS_TEST_DATA_DIR) + "/paper_tables_4_5.csv");
  EXPECT_TRUE(means.is_ok()) << means.error().message;
  CalibrationInputs in;
  in.means = means.value();
  const auto run = run_calibration(in, "paper_tables_4_5.csv");
  EXPECT_TRUE(run.is_ok()) << run.error().message;
  FileSettings settings;
  settings.device_id = "paper";
  settings.adc_lsb_v_per_count.fill(1e-7);
  settings.gravity_mps2 = kG;
  settings.gravity_source = "given";
  return make_calibration_data(run.value(), settings);
}

// Sensor j's stated covariance of (SF [V/g], b [g], a1 [rad], a2 [rad]), built here from the
// file's σ and correlations ((SF,b) (SF,a1) (SF,a2) (b,a1) (b,a2) (a1,a2)).
Eigen::Matrix4d stated_covariance(const calib_file::CalibrationData& d, std::size_t j) {
  const auto& s = d.sensors[j];
  const Place p = place_of(j);
  const auto& sig = p.alpha ? d.alpha.angle_sigma_deg : d.beta.angle_sigma_deg;
  const Eigen::Vector4d sd(s.scale_sigma_v_per_g, s.bias_sigma_g, sig[2 * p.row] * kDegToRad,
                           sig[2 * p.row + 1] * kDegToRad);
  const std::array<std::array<int, 2>, 6> at{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
  Eigen::Matrix4d r = Eigen::Matrix4d::Identity();
  for (std::size_t k = 0; k < 6; ++k) {
    r(at[k][0], at[k][1]) = s.correlation[k];
    r(at[k][1], at[k][0]) = s.correlation[k];
  }
  return sd.asDiagonal() * r * sd.asDiagonal();
}

// A file as installed: the truth plus an error drawn from the covariance it states.
calib_file::CalibrationData draw_file(std::mt19937_64& rng,
                                      const calib_file::CalibrationData& truth,
                                      const std::array<Eigen::Matrix4d, 6>& chol) {
  std::normal_distribution<double> n01;
  calib_file::CalibrationData d = truth;
  for (std::size_t j = 0; j < 6; ++j) {
    const Eigen::Vector4d e = chol[j] * Eigen::Vector4d(n01(rng), n01(rng), n01(rng), n01(rng));
    d.sensors[j].scale_v_per_g += e(0);
    d.sensors[j].bias_g += e(1);
    const Place p = place_of(j);
    auto& angles = p.alpha ? d.alpha.angle_deg : d.beta.angle_deg;
    angles[2 * p.row] += e(2) / kDegToRad;
    angles[2 * p.row + 1] += e(3) / kDegToRad;
  }
  return d;
}

std::vector<Pose> verify_poses() {
  std::vector<Pose> poses;
  for (std::size_t k = 0; k < kPoses.size(); ++k) {
    poses.push_back(Pose{kFirstPose + static_cast<int>(k), kPoses[k], 0});
  }
  return poses;
}

// The capture of every verification pose by the true board: forward physics plus the noise of
// the mean (std/√count), one row per (pose, sensor).
std::vector<MeanRow> capture(std::mt19937_64& rng, const calib_file::CalibrationData& truth,
                             const std::array<Eigen::Vector3d, 6>& theta_true) {
  std::normal_distribution<double> n01;
  std::vector<MeanRow> rows;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < kPoses.size(); ++k) {
    // At rest the sensed specific force is −g: gravity_b = −kG · (the pose's f in g).
    const Eigen::Vector3d gravity_b =
        -kG * Eigen::Vector3d(kPoses[k][0], kPoses[k][1], kPoses[k][2]);
    for (std::size_t j = 0; j < 6; ++j) {
      const auto& s = truth.sensors[j];
      // Static: a = ω̇ = ω = 0, so ρ*_j does not enter; any value shows it.
      const Eigen::Vector3d f = specific_force(zero, zero, zero, zero, gravity_b);
      const double std_v = kNoiseG * s.scale_v_per_g;
      MeanRow m;
      m.sensor = static_cast<int>(j) + 1;
      m.attitude = kFirstPose + static_cast<int>(k);
      m.std_v = std_v;
      m.count = kCount;
      m.mean_v = s.scale_v_per_g * (f.dot(theta_true[j]) / kG + s.bias_g) +
                 std_v / std::sqrt(static_cast<double>(kCount)) * n01(rng);
      rows.push_back(m);
    }
  }
  return rows;
}

struct Cell {
  double z2_stated = 0.0;        // Σ z² against the tool's σ (the file's whole covariance)
  double z2_uncorrelated = 0.0;  // Σ z² against the tool's σ with the correlations dropped
  double sigma_stated = 0.0;     // Σ of the predicted σ, for the printout (V)
  double sigma_uncorrelated = 0.0;
};

TEST(VerifySigma, PredictedResidualSigmaMatchesAMonteCarloOverTheStatedCovariance) {
  // Given the paper's Tables 4/5 file as the truth, and the covariance it states,
  const calib_file::CalibrationData truth = paper_file();
  ASSERT_TRUE(truth.correlations_known);
  // the case where correlations matter: sensor 1's SF is correlated with both its angles.
  EXPECT_LT(truth.sensors[0].correlation[1], -0.6);  // (SF, Δα_xy), −0.69
  EXPECT_GT(truth.sensors[0].correlation[2], 0.8);   // (SF, Δα_xz), +0.86
  std::array<Eigen::Matrix4d, 6> chol{};
  for (std::size_t j = 0; j < 6; ++j) {
    const Eigen::LLT<Eigen::Matrix4d> llt(stated_covariance(truth, j));
    ASSERT_EQ(llt.info(), Eigen::Success) << "sensor " << j + 1 << ": covariance not definite";
    chol[j] = llt.matrixL();
  }
  const auto theta_true = axes_of(truth);
  const std::vector<Pose> poses = verify_poses();
  std::mt19937_64 rng(20261123);
  std::array<std::array<Cell, 6>, kPoses.size()> cells{};
  double worst_residual_diff = 0.0;
  for (int draw = 0; draw < kDraws; ++draw) {
    // when a file drawn around the truth verifies a capture of the true board,
    const calib_file::CalibrationData file = draw_file(rng, truth, chol);
    const std::vector<MeanRow> rows = capture(rng, truth, theta_true);
    const auto rep = verify_calibration(rows, poses, file, "mc.csv");
    ASSERT_TRUE(rep.is_ok()) << rep.error().message;
    calib_file::CalibrationData v2 = file;  // the same file as a version 2 file would read
    v2.correlations_known = false;
    for (auto& s : v2.sensors) s.correlation = {};
    const auto rep_v2 = verify_calibration(rows, poses, v2, "mc.csv");
    ASSERT_TRUE(rep_v2.is_ok()) << rep_v2.error().message;
    ASSERT_EQ(rep.value().rows.size(), rows.size());
    const auto theta_file = axes_of(file);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto k = static_cast<std::size_t>(rows[i].attitude - kFirstPose);
      const auto j = static_cast<std::size_t>(rows[i].sensor - 1);
      const Eigen::Vector3d f(kPoses[k][0], kPoses[k][1], kPoses[k][2]);
      const auto& s = file.sensors[j];
      // The residual, computed here: P − SF (b + θ*·f) with the drawn file's parameters.
      const double res = rows[i].mean_v - s.scale_v_per_g * (s.bias_g + theta_file[j].dot(f));
      worst_residual_diff =
          std::max(worst_residual_diff, std::abs(res - rep.value().rows[i].residual_v));
      const double sd = rep.value().rows[i].sigma_v;
      const double sd_v2 = rep_v2.value().rows[i].sigma_v;
      Cell& c = cells[k][j];
      c.z2_stated += res * res / (sd * sd);
      c.z2_uncorrelated += res * res / (sd_v2 * sd_v2);
      c.sigma_stated += sd;
      c.sigma_uncorrelated += sd_v2;
    }
  }
  EXPECT_LT(worst_residual_diff, kResidualTolV);
  // then the mean z² of every cell is within the χ² band with the stated covariance,
  const double lo = chi2_mean_bound(-kBandSd);
  const double hi = chi2_mean_bound(kBandSd);
  std::printf("%d draws per cell; band on mean z^2 [%.4f, %.4f]\n", kDraws, lo, hi);
  std::printf("pose sensor  sigma stated (mV)  mean z^2   sigma no corr (mV)  mean z^2\n");
  int uncorrelated_outside = 0;
  for (std::size_t k = 0; k < kPoses.size(); ++k) {
    for (std::size_t j = 0; j < 6; ++j) {
      const Cell& c = cells[k][j];
      const double z2 = c.z2_stated / kDraws;
      const double z2_v2 = c.z2_uncorrelated / kDraws;
      std::printf("%4zu   a%zu    %10.4f        %7.4f   %10.4f          %7.4f%s\n", k + kFirstPose,
                  j + 1, c.sigma_stated / kDraws * 1e3, z2, c.sigma_uncorrelated / kDraws * 1e3,
                  z2_v2, (z2_v2 < lo || z2_v2 > hi) ? "  <- fails without correlations" : "");
      EXPECT_GE(z2, lo) << "pose " << k + kFirstPose << " sensor a" << j + 1;
      EXPECT_LE(z2, hi) << "pose " << k + kFirstPose << " sensor a" << j + 1;
      uncorrelated_outside += (z2_v2 < lo || z2_v2 > hi);
    }
  }
  // and the criterion can fail: dropping the correlations (the σ predicted before) misstates
  // sensor 1's residual in the 30° tilt (pose 13) beyond the band, and others.
  const double z2_a1_tilt = cells[0][0].z2_uncorrelated / kDraws;
  EXPECT_TRUE(z2_a1_tilt < lo || z2_a1_tilt > hi) << z2_a1_tilt;
  EXPECT_GT(uncorrelated_outside, 0);
  std::printf("%d of %zu cells fail the band when the correlations are dropped\n",
              uncorrelated_outside, kPoses.size() * 6);
}

// The tail of Student's t against closed forms written here (not the tool's continued fraction):
// ν = 1 (Cauchy) P(|T| ≥ t) = 1 − 2 atan(t)/π; ν = 2: 1 − t/√(2 + t²); ν = 3:
// 1 − (2/π)(atan(t/√3) + (t/√3)/(1 + t²/3)); ν = ∞: erfc(t/√2). Each to 1e-12 relative (the
// fraction converges to 1e-15 per step; a wrong term makes it fail by far more).
TEST(VerifySigma, StudentTTailMatchesTheClosedForms) {
  const double pi = 3.14159265358979323846;
  for (const double t : {0.0, 0.3, 1.0, 2.5, 5.0, 19.2, 300.0}) {
    const double u = t / std::sqrt(3.0);
    const double want[] = {1.0 - 2.0 * std::atan(t) / pi, 1.0 - t / std::sqrt(2.0 + t * t),
                           1.0 - 2.0 / pi * (std::atan(u) + u / (1.0 + u * u))};
    for (int k = 0; k < 3; ++k) {
      const double got = student_t_two_sided_p(t, k + 1.0);
      EXPECT_NEAR(got, want[k], 1e-12 * std::max(want[k], 1e-300) + 1e-15)
          << "t " << t << " dof " << k + 1;
      EXPECT_NEAR(student_t_two_sided_p(-t, k + 1.0), got, 1e-15);
    }
    EXPECT_NEAR(student_t_two_sided_p(t, std::numeric_limits<double>::infinity()),
                std::erfc(t / std::sqrt(2.0)), 1e-15);
    // Many degrees of freedom approach the Gaussian: the tail's relative difference is about
    // (t⁴ + 2t² − 1)/(4ν) (the expansion of the t density in 1/ν); bound: four times its size.
    const double gauss = std::erfc(t / std::sqrt(2.0));
    EXPECT_NEAR(student_t_two_sided_p(t, 1e7), gauss,
                (t * t * t * t + 2 * t * t + 1) / 1e7 * gauss + 1e-300);
  }
}

// The paper's route writes σ from the fit residuals with 2 degrees of freedom per sensor: the
// file's σ is then an estimate, s = σ √(χ²₂/2), and a residual of a verification pose divided by
// its predicted σ is a Student-t with 2 dof (|t| > 3 with probability 9.5 %, not 0.27 %). The
// tool maps it to the Gaussian z of the same tail probability.
//
// Monte-Carlo, oracle written here: the true covariance is the paper file's; each draw makes a
// file off the truth by an error drawn from it, whose stated σ (the whole 4×4 covariance: a
// residual-based covariance is s² times a fixed matrix) are scaled per sensor by √(χ²₂/2), as a
// fit with 2 residual dof would have stated them; the true board is captured in the 30° tilt
// (pose 13), one row per sensor, and verified. Sensors are independent, so each draw gives 6
// independent rows: 2000 draws, 12,000 rows. Criteria (Poisson counts, expected from the
// Gaussian tails):
//  - |z_gauss| > 3: 0.27 %, 32.4 expected; accepted 12..60 (P(outside) < 3e-5 each way);
//  - |z_gauss| > 2: 4.55 %, 546 expected; accepted 546 ± 5·√546 (±117);
//  - the naive |z| > 3 (the verdict before): more than 500 (9.5 %: 1,140 expected), which is why
//    the paper's file failed a correct verification that often.
TEST(VerifySigma, AResidualBasedSigmaIsJudgedAsTheStudentTItIs) {
  const calib_file::CalibrationData truth = paper_file();
  for (const auto& s : truth.sensors) {
    ASSERT_EQ(s.sigma_source.basis, calib_file::SigmaBasis::kResiduals);
    ASSERT_EQ(s.sigma_source.dof, 2);
  }
  std::array<Eigen::Matrix4d, 6> chol{};
  for (std::size_t j = 0; j < 6; ++j) {
    const Eigen::LLT<Eigen::Matrix4d> llt(stated_covariance(truth, j));
    ASSERT_EQ(llt.info(), Eigen::Success);
    chol[j] = llt.matrixL();
  }
  const auto theta_true = axes_of(truth);
  const std::vector<Pose> poses = verify_poses();
  std::mt19937_64 rng(20261129);
  std::chi_squared_distribution<double> chi2(2.0);
  constexpr int kT3Draws = 2000;
  int over3 = 0, over2 = 0, naive_over3 = 0, rows_seen = 0;
  for (int draw = 0; draw < kT3Draws; ++draw) {
    calib_file::CalibrationData file = draw_file(rng, truth, chol);
    for (std::size_t j = 0; j < 6; ++j) {
      const double scale = std::sqrt(chi2(rng) / 2.0);
      auto& s = file.sensors[j];
      s.scale_sigma_v_per_g *= scale;
      s.bias_sigma_g *= scale;
      const Place p = place_of(j);
      auto& sig = p.alpha ? file.alpha.angle_sigma_deg : file.beta.angle_sigma_deg;
      sig[2 * p.row] *= scale;
      sig[2 * p.row + 1] *= scale;
    }
    std::vector<MeanRow> rows = capture(rng, truth, theta_true);
    rows.resize(6);  // pose 13, sensors 1..6
    const auto rep = verify_calibration(rows, poses, file, "t.csv");
    ASSERT_TRUE(rep.is_ok()) << rep.error().message;
    for (const VerifyRow& r : rep.value().rows) {
      ++rows_seen;
      over3 += std::abs(r.z_gauss) > 3.0 ? 1 : 0;
      over2 += std::abs(r.z_gauss) > 2.0 ? 1 : 0;
      naive_over3 += std::abs(r.z) > 3.0 ? 1 : 0;
      // The capture's stated part adds dof (Welch–Satterthwaite): never fewer than the file's 2.
      EXPECT_GE(r.dof, 2.0);
    }
  }
  std::printf("%d rows: |z_gauss| > 3: %d, > 2: %d; naive |z| > 3: %d\n", rows_seen, over3, over2,
              naive_over3);
  ASSERT_EQ(rows_seen, 6 * kT3Draws);
  EXPECT_GE(over3, 12);
  EXPECT_LE(over3, 60);
  EXPECT_GE(over2, 546 - 117);
  EXPECT_LE(over2, 546 + 117);
  EXPECT_GT(naive_over3, 500);
}

TEST(VerifySigma, TheReportSaysWhichSigmaAndAnOldFileTakesCorrelationsAsZero) {
  const calib_file::CalibrationData truth = paper_file();
  const auto theta_true = axes_of(truth);
  std::mt19937_64 rng(5);
  const std::vector<MeanRow> rows = capture(rng, truth, theta_true);
  const auto text_of = [&](const calib_file::CalibrationData& d) {
    const auto rep = verify_calibration(rows, verify_poses(), d, "v.csv");
    EXPECT_TRUE(rep.is_ok()) << rep.error().message;
    std::string t;
    for (const auto& l : rep.value().lines) t += l + "\n";
    return t;
  };
  const std::string stated = text_of(truth);
  EXPECT_NE(stated.find("(their sigma and correlations)"), std::string::npos) << stated;
  calib_file::CalibrationData old = truth;  // as loaded from a format version 1 or 2 file
  old.correlations_known = false;
  for (auto& s : old.sensors) s.correlation = {};
  const std::string unknown = text_of(old);
  EXPECT_NE(unknown.find("correlations unknown: taken as 0"), std::string::npos) << unknown;
  // The paper's file has σ from residuals: said, and each row says its dof and Gaussian z; a file
  // older than format 4 does not say where its σ came from, and the note says what is assumed.
  EXPECT_NE(stated.find("sigma of a1 a2 a3 a4 a5 a6 from fit residuals"), std::string::npos)
      << stated;
  EXPECT_NE(stated.find("(Student-t, "), std::string::npos) << stated;
  calib_file::CalibrationData v3 = truth;
  for (auto& s : v3.sensors) s.sigma_source = {calib_file::SigmaBasis::kUnknown, 0};
  const std::string older = text_of(v3);
  EXPECT_NE(older.find("does not say where the sigma of a1 a2 a3 a4 a5 a6 came from"),
            std::string::npos)
      << older;
  EXPECT_EQ(older.find("(Student-t, "), std::string::npos) << older;
}

}  // namespace
}  // namespace gfins::tools
