// gfins-calibrate on raw .gfr recordings: still intervals found by the static
// detector, poses that moved or saturated refused with the reason, too few intervals listed;
// and the location calibration from rate-table runs (paper §4.2) with its observability report.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "calib_file/calib_test_data.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/host_sim/recording.hpp"
#include "support/run_cli.hpp"

namespace gfins::calib_file {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::read_text;
using testing::TempDir;
using testing::write_text;
using Vec3d = nav::Vec3<double>;

constexpr double kRateHz = 100.0;
constexpr double kNoiseV = 1e-4;          // per sample
constexpr double kLsb = 5.0 / 8388608.0;  // ±5 V over 24 bits

using RunResult = test::CliResult;

// The tool runs without a shell (tests/support/run_cli.hpp).
RunResult run_cli(const TempDir& dir, const std::string& args) {
  return test::run_tool(GFINS_CALIBRATE_EXE, args, dir.path());
}

// A board obeying eq. (16) with Table 6 as truth, recorded through a 24-bit ADC: each pose of
// Tables 2/3 held 3 s with 1 s linear turns between them. Pose `shaken` (if ≥ 0) carries 20 mV
// of extra noise (the board moved); in pose `clipped` channel 4 sits at the positive full scale.
class GfrBuilder {
 public:
  GfrBuilder() : truth_(testing::table6_data()) {
    const nav::Misalignment<double> m = misalignment<double>(truth_);
    axes_ = nav::misaligned_geometry(nav::table1_geometry<double>(1.0), m).theta_b;
  }

  void write(const std::filesystem::path& path, int num_poses, int shaken, int clipped) {
    const double k = 1.0 / std::numbers::sqrt2;
    const double poses[12][3] = {{-k, 0, k}, {k, 0, -k},  {k, 0, k},  {-k, 0, -k},
                                 {0, k, k},  {0, -k, -k}, {0, -k, k}, {0, k, -k},
                                 {k, k, 0},  {-k, -k, 0}, {-k, k, 0}, {k, -k, 0}};
    for (int p = 0; p < num_poses; ++p) {
      const Vec3d f(poses[p][0], poses[p][1], poses[p][2]);
      for (int i = 0; i < 300; ++i) emit(f, p == shaken ? 20e-3 : 0.0, p == clipped);
      if (p + 1 == num_poses) break;
      const Vec3d next(poses[p + 1][0], poses[p + 1][1], poses[p + 1][2]);
      for (int i = 1; i < 100; ++i) emit(f + (next - f) * (i / 100.0), 0.0, false);
    }
    sim::RecordingHeader h;
    h.sample_rate_hz = kRateHz;
    h.volts_per_count.fill(kLsb);
    h.geometry = nav::table1_geometry<double>(0.1);
    ASSERT_TRUE(sim::write_recording(path.string(), h, samples_).is_ok());
  }
  const CalibrationData& truth() const { return truth_; }

 private:
  void emit(const Vec3d& f, double extra_noise_v, bool clip) {
    RawSample s;
    s.seq = static_cast<std::uint32_t>(samples_.size());
    s.t_ns = static_cast<std::int64_t>(samples_.size()) * 10'000'000;
    for (std::size_t j = 0; j < 6; ++j) {
      const auto& c = truth_.sensors[j];
      const double v = c.scale_v_per_g * (c.bias_g + axes_[j].dot(f)) + kNoiseV * unit_(rng_) +
                       extra_noise_v * unit_(rng_);
      s.counts[j] = static_cast<std::int32_t>(std::lround(v / kLsb));
    }
    if (clip) {
      s.counts[3] = kAdcCodeMax;
      s.flags |= sample_flags::kSaturated;
    }
    samples_.push_back(s);
  }

  CalibrationData truth_;
  std::array<Vec3d, 6> axes_{};
  std::vector<RawSample> samples_;
  std::mt19937_64 rng_{5};
  std::normal_distribution<double> unit_{0.0, 1.0};
};

TEST(CalibrateGfr, PosesThatMovedOrSaturatedAreRefusedSayingWhichAndWhy) {
  // Given a .gfr recording of the twelve poses where pose 3 was shaken and pose 8 saturated
  // channel 4,
  const TempDir dir;
  GfrBuilder b;
  const auto rec = dir.path() / "rec.gfr";
  b.write(rec, 12, 2, 7);
  const auto out = dir.path() / "cal.toml";
  // when calibrated (rate and ADC LSB come from the recording's header),
  const RunResult r = run_cli(dir, "--recording " + rec.string() +
                                       " --nominal-sf 0.5 0.33 0.5 2.5 0.34 2.5 --latitude 24.8 "
                                       "--device-id gfr -o " +
                                       out.string());
  // then the two poses are refused with their time and reason, and the other ten are used.
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("samples at 100 Hz"));
  EXPECT_THAT(r.output, HasSubstr("refused: the board moved (or vibrated) during it: channel(s) "
                                  "1, 2, 3, 4, 5, 6 have a standard deviation up to"));
  EXPECT_THAT(r.output, HasSubstr("refused: channel(s) 4 saturated (ADC code at full scale) in"));
  EXPECT_THAT(r.output, HasSubstr("2 poses refused"));
  EXPECT_THAT(r.output, HasSubstr("pose T3.6"));
  const auto d = load_calibration_file(out);
  ASSERT_TRUE(d.is_ok()) << d.status().message();
  EXPECT_EQ(d.value().sensors[2].adc_lsb_v_per_count, kLsb);  // from the .gfr header
  // Ten poses still determine every parameter: within 8σ of a pose mean's noise through the
  // smallest SF (1e-4 V/√240 / 0.33 V/g = 2e-5 g → 2e-4 g, 1e-2° as for the CSV recording).
  for (std::size_t j = 0; j < 6; ++j) {
    EXPECT_NEAR(d.value().sensors[j].bias_g, b.truth().sensors[j].bias_g, 2e-4) << j;
  }
}

TEST(CalibrateGfr, FewerThanFourStillIntervalsListsWhatWasFoundAndWhy) {
  // Given a recording of four poses, one of them shaken,
  const TempDir dir;
  GfrBuilder b;
  const auto rec = dir.path() / "short.gfr";
  b.write(rec, 4, 1, -1);
  const RunResult r = run_cli(dir, "--recording " + rec.string() + " --nominal-sf 0.5 --dry-run");
  // then nothing is solved and the message lists the intervals and the refused pose.
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("3 usable still intervals, at least 4 non-coplanar poses"));
  EXPECT_THAT(r.output, HasSubstr("still intervals found:\n    0."));
  EXPECT_THAT(r.output, HasSubstr("poses refused:\n    pose at 4."));
  EXPECT_THAT(r.output, HasSubstr("the board moved"));
}

// Location runs (paper §4.2) for the file of table6_data(): the outputs of each sensor on a
// table spinning at ω about the vertical axis u (up, body), eq. (20) with ω×(ω×ρ) and eq. (21):
//   P_j = SF_j (θ*_j·(g u + ω×(ω×ρ*_j))/g + b_j),  ρ*_j = ρ_j + Δρ_j.
std::string location_csv(const CalibrationData& cal, const std::array<Vec3d, 6>& drho,
                         const std::vector<Vec3d>& axes, std::mt19937_64& rng) {
  const auto geo = nav::table1_geometry<double>(cal.geometry.rho_m);
  nav::Misalignment<double> m = misalignment<double>(cal);
  const auto theta = nav::misaligned_geometry(geo, m).theta_b;
  const double g = cal.gravity_mps2;
  const double sigma_v = 2e-3;  // per sample, V
  const std::uint32_t count = 2000;
  std::normal_distribution<double> noise(0.0, sigma_v / std::sqrt(double(count)));
  std::string csv = "mounting,axis_x,axis_y,axis_z,rate_rad_s";
  for (int j = 1; j <= 6; ++j) csv += ",mean_v" + std::to_string(j);
  for (int j = 1; j <= 6; ++j) csv += ",std_v" + std::to_string(j);
  csv += ",count\n";
  for (std::size_t mnt = 0; mnt < axes.size(); ++mnt) {
    for (const double rate : {3.0, 6.0, 9.0}) {
      const Vec3d u = axes[mnt].normalized();
      const Vec3d w = rate * u;
      char buf[160];
      std::snprintf(buf, sizeof buf, "%zu,%.17g,%.17g,%.17g,%g", mnt, u.x(), u.y(), u.z(), rate);
      csv += buf;
      for (std::size_t j = 0; j < 6; ++j) {
        const Vec3d rho = geo.rho_b[j] + drho[j];
        const auto& s = cal.sensors[j];
        const double p =
            s.scale_v_per_g * (theta[j].dot(g * u + w.cross(w.cross(rho))) / g + s.bias_g) +
            noise(rng);
        std::snprintf(buf, sizeof buf, ",%.12g", p);
        csv += buf;
      }
      for (int j = 0; j < 6; ++j) csv += ",0.002";
      csv += "," + std::to_string(count) + "\n";
    }
  }
  return csv;
}

TEST(CalibrateLocation, RateTableRunsGiveTheLocationErrorsAndNameWhatIsNotObservable) {
  const TempDir dir;
  CalibrationData cal = testing::table6_data();
  for (auto& s : cal.sensors) s.location_error_m = {0, 0, 0};
  // The runs below are made with exactly these SF, biases and angles, so the base states a small
  // σ (the location σ includes the base's: docs/calibration.md §5); table6_data()'s made-up
  // angle σ of 0.04–0.08° would alone give σ(Δρ) of 0.1–0.2 mm.
  cal.beta.angle_sigma_deg.fill(1e-4);
  cal.alpha.angle_sigma_deg.fill(1e-4);
  const auto base = dir.path() / "base.toml";
  ASSERT_TRUE(save_calibration_file(base, cal).is_ok());
  const std::array<Vec3d, 6> drho = {Vec3d(1e-3, -5e-4, 2e-4),  Vec3d(-3e-4, 8e-4, 1e-3),
                                     Vec3d(6e-4, 2e-4, -7e-4),  Vec3d(-9e-4, -1e-4, 3e-4),
                                     Vec3d(2e-4, -6e-4, -4e-4), Vec3d(5e-4, 7e-4, -1e-3)};
  std::mt19937_64 rng(3);
  // Given runs about x, y, z only: the radial component of every sensor is not observable;
  write_text(dir.path() / "xyz.csv",
             location_csv(cal, drho, {Vec3d::UnitX(), Vec3d::UnitY(), Vec3d::UnitZ()}, rng));
  const auto out_xyz = dir.path() / "xyz.toml";
  RunResult r = run_cli(dir, "--location-runs " + (dir.path() / "xyz.csv").string() + " --base " +
                                 base.string() + " -o " + out_xyz.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("1 direction(s), e.g. ["));
  EXPECT_THAT(r.output, HasSubstr("held at 0, sigma = prior 1 mm"));
  EXPECT_THAT(r.output, HasSubstr("add the two face-diagonal mountings"));
  // and with the two face-diagonal mountings every component is, and comes back.
  write_text(dir.path() / "full.csv", location_csv(cal, drho,
                                                   {Vec3d::UnitX(), Vec3d::UnitY(), Vec3d::UnitZ(),
                                                    Vec3d(1, 1, 0), Vec3d(1, 0, 1)},
                                                   rng));
  const auto out = dir.path() / "full.toml";
  r = run_cli(dir, "--location-runs " + (dir.path() / "full.csv").string() + " --base " +
                       base.string() + " -o " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, Not(HasSubstr("direction(s)")));
  const auto d = load_calibration_file(out);
  ASSERT_TRUE(d.is_ok()) << d.status().message();
  // Every component within 5σ of its stated σ (Gaussian tail 5.7e-7 each, 18 components:
  // 1e-5), and σ small enough (< 0.1 mm) that the check has teeth against Δρ of up to 1 mm.
  for (std::size_t j = 0; j < 6; ++j) {
    for (std::size_t k = 0; k < 3; ++k) {
      const double sigma = d.value().sensors[j].location_error_sigma_m[k];
      EXPECT_GT(sigma, 0.0);
      EXPECT_LT(sigma, 1e-4);
      EXPECT_NEAR(d.value().sensors[j].location_error_m[k], drho[j](static_cast<int>(k)),
                  5.0 * sigma)
          << "sensor " << j + 1 << " component " << k;
    }
  }
  // The orientation part is the base's, untouched.
  EXPECT_EQ(d.value().sensors[1].scale_v_per_g, cal.sensors[1].scale_v_per_g);
  EXPECT_EQ(d.value().gravity_mps2, cal.gravity_mps2);
}

}  // namespace
}  // namespace gfins::calib_file
