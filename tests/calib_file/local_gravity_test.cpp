// A board calibrated at one latitude and navigating at rest at another senses
// its own site's gravity, to the noise floor, once the calibration file carries the local
// gravity of the calibration site and the front end converts V/g with it. Converting with
// standard gravity (the defect) leaves every specific force 9.80665/g_cal − 1 off.
//
// The simulated board is written here from physics: sensor j outputs P_j = k_j (θ*_j·f) + o_j
// volts for the specific force f in m/s², with a physical sensitivity k_j (V per m/s²) and
// offset o_j; nothing in it knows about g. Calibration: poses at site A, where |f| = g_A; the
// solver sees the poses as unit vectors in "g" (paper §4.1), so its V/g are V per g_A.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "calib_file/calib_test_data.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/nav_core/calibration/multi_attitude.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/nav_core/misalignment.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::calib_file {
namespace {

using Vec3d = nav::Vec3<double>;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kLatCalDeg = 24.8;       // Hsinchu: g = 9.7894 m/s²
constexpr double kLatNavDeg = 60.0;       // g = 9.8192 m/s²
constexpr double kRho = 0.1;              // m
constexpr double kLsb = 5.0 / 8388608.0;  // V/count: ±5 V over 24 bits (outputs reach 2.5 V)
// Per-sample output noise of every sensor, V (QA-1100 at ~0.5 V/g: about 0.2 mg).
constexpr double kNoiseV = 100e-6;
constexpr std::uint32_t kSamplesPerPose = 2000;
constexpr std::uint32_t kAlignSamples = 1000;
constexpr std::uint32_t kNavSamples = 2000;
// |r| ≤ 5σ of its predicted standard deviation: two-sided Gaussian tail 5.7e-7 per run.
constexpr double kSigmaBound = 5.0;

// The board's truth: physical sensitivities (V per m/s²), offsets (V), axes θ*_j (Table 1 with
// the paper's Table 6 orientation errors, eqs. (14)/(15)).
struct Board {
  std::array<double, 6> k_v_per_mps2{};
  std::array<double, 6> offset_v{};
  nav::ArrayGeometry<double, 6> geometry;
};

Board make_board() {
  Board b;
  const std::array<double, 6> sf_v_per_g = {0.51, 0.33, 0.50, 2.49, 0.34, 2.48};
  const std::array<double, 6> bias_mps2 = {-0.007, -0.002, 0.008, -0.078, -0.009, -0.046};
  for (std::size_t j = 0; j < 6; ++j) {
    b.k_v_per_mps2[j] = sf_v_per_g[j] / 9.8;  // any physical constant; the board has no "g"
    b.offset_v[j] = b.k_v_per_mps2[j] * bias_mps2[j];
  }
  nav::Misalignment<double> m;
  const std::array<double, 6> beta = {1.117, -0.176, -0.581, -0.739, 2.454, 2.482};
  const std::array<double, 6> alpha = {-2.655, 2.597, -0.839, -0.737, 0.120, -1.451};
  for (std::size_t i = 0; i < 6; ++i) {
    m.orientation.beta[i] = beta[i] * kDeg;
    m.orientation.alpha[i] = alpha[i] * kDeg;
  }
  b.geometry = nav::misaligned_geometry(nav::table1_geometry<double>(kRho), m);
  return b;
}

// Noise-free output of sensor j for the specific force f (m/s², body), at rest.
double output_v(const Board& b, std::size_t j, const Vec3d& f_mps2) {
  return b.k_v_per_mps2[j] * b.geometry.theta_b[j].dot(f_mps2) + b.offset_v[j];
}

double normal_gravity(double lat_deg) {
  return static_cast<double>(
      nav::GravityModel<double>::normal(lat_deg * kDeg, 0.0).magnitude_at_origin());
}

// Six faces and eight body diagonals, "up" unit vectors in body axes.
std::vector<Vec3d> poses() {
  std::vector<Vec3d> p;
  for (int k = 0; k < 3; ++k) {
    p.push_back(Vec3d::Unit(k));
    p.push_back(-Vec3d::Unit(k));
  }
  for (int sx : {-1, 1})
    for (int sy : {-1, 1})
      for (int sz : {-1, 1}) p.push_back(Vec3d(sx, sy, sz).normalized());
  return p;
}

// Calibration at site A: every pose senses f = g_A·up; the means carry the white noise of
// kSamplesPerPose samples and state it (std_v, count).
calib::MultiAttitudeResult<double> calibrate_at(const Board& b, double g_site,
                                                std::mt19937_64& rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<calib::AttitudeObservation<double>> obs;
  for (const Vec3d& up : poses()) {
    calib::AttitudeObservation<double> o;
    o.f_b_g = {up.x(), up.y(), up.z()};  // in units of the local g: |f| = 1
    for (std::size_t j = 0; j < 6; ++j) {
      o.mean_v[j] =
          output_v(b, j, g_site * up) + kNoiseV / std::sqrt(double(kSamplesPerPose)) * unit(rng);
      o.sample_std_v[j] = kNoiseV;
    }
    o.sample_count = kSamplesPerPose;
    obs.push_back(o);
  }
  const auto r = calib::calibrate_multi_attitude<double>(
      std::span<const calib::AttitudeObservation<double>>(obs.data(), obs.size()));
  EXPECT_TRUE(r.is_ok()) << r.status().message();
  return r.value();
}

CalibrationData file_data(const calib::MultiAttitudeResult<double>& r, double g_cal) {
  CalibrationData d = testing::table6_data();
  d.geometry.rho_m = kRho;
  d.gravity_mps2 = g_cal;
  d.gravity_source = "test";
  for (std::size_t j = 0; j < 6; ++j) {
    d.sensors[j].adc_lsb_v_per_count = kLsb;
    d.sensors[j].scale_v_per_g = r.scale_v_per_g[j];
    d.sensors[j].bias_g = r.bias_g[j];
    d.sensors[j].location_error_m = {0, 0, 0};
  }
  for (std::size_t i = 0; i < 6; ++i) {
    d.beta.angle_deg[i] = r.orientation.beta[i] / kDeg;
    d.alpha.angle_deg[i] = r.orientation.alpha[i] / kDeg;
  }
  return d;
}

// Navigation at rest at site B through the whole pipeline (front end, exact compensator,
// alignment, strapdown): mean over kNavSamples of |f_b| − g_B.
double residual_at_rest(const CalibrationData& d, const Board& b, double lat_nav_deg,
                        double noise_v, std::mt19937_64& rng) {
  nav::PipelineConfig<double> cfg;
  apply_to(d, cfg);
  cfg.gravity = nav::GravityModel<double>::normal(lat_nav_deg * kDeg, 0.0);
  cfg.alignment_samples = kAlignSamples;
  nav::NavPipeline<double> p;
  EXPECT_TRUE(p.configure(cfg).is_ok());
  const double g_nav = normal_gravity(lat_nav_deg);
  const Vec3d up = Vec3d(0.1, -0.2, -1.0).normalized();  // tilted, body z roughly down
  std::normal_distribution<double> unit(0.0, 1.0);
  double sum = 0.0;
  for (std::uint32_t k = 0; k < kAlignSamples + kNavSamples; ++k) {
    RawSample raw;
    raw.seq = k;
    raw.t_ns = std::int64_t(k) * 1'000'000;
    for (std::size_t j = 0; j < 6; ++j) {
      const double v = output_v(b, j, g_nav * up) + noise_v * unit(rng);
      raw.counts[j] = static_cast<std::int32_t>(std::lround(v / kLsb));
    }
    const auto phase = p.process(raw);
    if (k >= kAlignSamples) {
      EXPECT_EQ(phase, nav::PipelinePhase::kNavigating);
      sum += p.state().f_b.norm() - g_nav;
    }
  }
  return sum / kNavSamples;
}

// σ of the residual from the calibration's own covariance (first order, numerical Jacobian of
// the noise-free residual with respect to each sensor's SF, b and two angles).
double calibration_sigma(const CalibrationData& d, const calib::MultiAttitudeResult<double>& r,
                         const Board& b) {
  std::mt19937_64 unused(0);
  const double r0 = residual_at_rest(d, b, kLatNavDeg, 0.0, unused);
  double var = 0.0;
  for (std::size_t j = 0; j < 6; ++j) {
    std::array<double, 4> jac{};
    const std::array<double, 4> step = {1e-6, 1e-6, 1e-6, 1e-6};  // V/g, g, rad, rad
    for (std::size_t q = 0; q < 4; ++q) {
      CalibrationData e = d;
      if (q == 0) e.sensors[j].scale_v_per_g += step[q];
      if (q == 1) e.sensors[j].bias_g += step[q];
      if (q >= 2) {
        const std::uint8_t a = r.covariance_angle[j][q - 2];
        const bool alpha = j == 0 || j == 3 || j == 5;
        (alpha ? e.alpha : e.beta).angle_deg[a] += step[q] / kDeg;
      }
      jac[q] = (residual_at_rest(e, b, kLatNavDeg, 0.0, unused) - r0) / step[q];
    }
    for (std::size_t q = 0; q < 4; ++q)
      for (std::size_t s = 0; s < 4; ++s) var += jac[q] * r.covariance[j][q * 4 + s] * jac[s];
  }
  return std::sqrt(var);
}

TEST(LocalGravity, CalibratedAtOneLatitudeAtRestAtAnotherReadsTheLocalGravity) {
  // Given a board calibrated at 24.8° (g_A = 9.7894 m/s²), its file carrying g_A,
  const Board b = make_board();
  const double g_cal = normal_gravity(kLatCalDeg);
  const double g_nav = normal_gravity(kLatNavDeg);
  std::mt19937_64 rng(11);
  const auto cal = calibrate_at(b, g_cal, rng);
  ASSERT_EQ(cal.verdict, calib::Verdict::kGood);
  const testing::TempDir dir;
  const auto path = dir.path() / "cal.toml";
  ASSERT_TRUE(save_calibration_file(path, file_data(cal, g_cal)).is_ok());
  const auto loaded = load_calibration_file(path);
  ASSERT_TRUE(loaded.is_ok()) << loaded.status().message();
  // when it navigates at rest at 60° (g_B = 9.8192 m/s²),
  const double r = residual_at_rest(loaded.value(), b, kLatNavDeg, kNoiseV, rng);

  // then |f| − g_B is at the noise floor. Its σ has two parts: the navigation noise, per axis
  // σ_s/√2 per sample for Table 1 (f = T s/2, T Tᵀ = 2I) with σ_s = g·σ_v/SF, averaged over
  // kNavSamples (largest σ_s taken: smallest SF); and the calibration's own stated
  // uncertainty, propagated.
  double min_sf = 1e9;
  for (const auto& s : loaded.value().sensors) min_sf = std::min(min_sf, s.scale_v_per_g);
  const double sigma_nav = g_cal * kNoiseV / min_sf / std::sqrt(2.0 * kNavSamples);
  const double sigma_cal = calibration_sigma(loaded.value(), cal, b);
  const double bound = kSigmaBound * std::hypot(sigma_nav, sigma_cal);
  // The defect: the same file converted with standard gravity.
  CalibrationData bug = loaded.value();
  bug.gravity_mps2 = nav::kStandardGravity;
  std::mt19937_64 rng_bug(11);
  (void)calibrate_at(b, g_cal, rng_bug);
  const double r_bug = residual_at_rest(bug, b, kLatNavDeg, kNoiseV, rng_bug);
  const double r_bug_predicted = g_nav * (nav::kStandardGravity / g_cal - 1.0);
  std::printf(
      "local gravity: g_cal %.5f g_nav %.5f m/s^2; residual |f|-g_nav %.2e m/s^2, noise floor "
      "sigma %.2e (nav %.2e, cal %.2e), bound %.2e; standard-gravity conversion %.3e "
      "(predicted %.3e)\n",
      g_cal, g_nav, r, std::hypot(sigma_nav, sigma_cal), sigma_nav, sigma_cal, bound, r_bug,
      r_bug_predicted);
  EXPECT_LT(std::abs(r), bound);
  // And the plausible bug violates the bound (0.17 %, 1.7e-2 m/s², against a bound ~1e-4).
  EXPECT_GT(std::abs(r_bug), bound);
  EXPECT_NEAR(r_bug, r_bug_predicted, bound);
}

TEST(LocalGravity, FrontEndConvertsWithTheCalibrationGravity) {
  // Given SF = 0.5 V/g_cal, b = 0, g_cal = 9.7894 and an output of exactly 0.5 V,
  nav::FrontEndParams<double, 6> p;
  p.volts_per_count.fill(0.5);
  p.scale_v_per_g.fill(0.5);
  p.gravity_mps2 = 9.7894;
  const auto fe = nav::FrontEnd<double, 6>::create(p);
  ASSERT_TRUE(fe.is_ok());
  nav::FrontEnd<double, 6>::Outputs s;
  (void)fe.value().convert({1, 1, 1, 1, 1, 1}, s);
  // then each sensor reads 1 g_cal in m/s² (eq. (21) with g the calibration site's).
  for (int j = 0; j < 6; ++j) EXPECT_DOUBLE_EQ(s(j), 9.7894);
  // and a gravity that is not a positive finite number is refused.
  p.gravity_mps2 = 0.0;
  using FrontEnd6 = nav::FrontEnd<double, 6>;
  EXPECT_EQ(FrontEnd6::create(p).status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace gfins::calib_file
