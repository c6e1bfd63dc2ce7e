// The simulated GNSS receiver: antenna geometry (lever arm, ω × l velocity term) and timing
// (time of validity, latency, outages, fix ids) against a circular drive written out here, and
// the noise's σ and mean from many fixes.
#include "gfins/host_sim/gnss_model.hpp"

#include "gfins/host_sim/scenario.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace gfins::sim {
namespace {

// A circle of radius R at angular rate Ω, at height h, heading along the track (yaw = Ωt + π/2),
// level: r = [R cos Ωt, R sin Ωt, -h], ψ = Ωt + π/2, ω_b = [0, 0, Ω].
constexpr double kR = 50.0;
constexpr double kOmega = 0.2;
constexpr double kH = 3.0;

class Circle final : public JetTrajectory {
 public:
  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    const JetD a = kOmega * t;
    r_n = {kR * cos(a), kR * sin(a), JetD(-kH)};
    q_nb = jet_rot_z(a + JetD(std::numbers::pi / 2));
  }
  std::string name() const override { return "circle"; }
};

/// The antenna of the circle, written out by hand (not with the model's formula): with
/// ψ = Ωt + π/2 the lever arm l rotates to [cos ψ l_x − sin ψ l_y, sin ψ l_x + cos ψ l_y, l_z].
Vec3d antenna_r(double t, const Vec3d& l) {
  const double psi = kOmega * t + std::numbers::pi / 2;
  return {kR * std::cos(kOmega * t) + std::cos(psi) * l.x() - std::sin(psi) * l.y(),
          kR * std::sin(kOmega * t) + std::sin(psi) * l.x() + std::cos(psi) * l.y(), -kH + l.z()};
}

/// Its time derivative, by hand.
Vec3d antenna_v(double t, const Vec3d& l) {
  const double psi = kOmega * t + std::numbers::pi / 2;
  return {-kR * kOmega * std::sin(kOmega * t) - kOmega * std::sin(psi) * l.x() -
              kOmega * std::cos(psi) * l.y(),
          kR * kOmega * std::cos(kOmega * t) + kOmega * std::cos(psi) * l.x() -
              kOmega * std::sin(psi) * l.y(),
          0.0};
}

// Truth evaluated in double through jets: agreement to a few ulp of the 50 m scale.
constexpr double kGeometryTol = 1e-9;

GnssSpec noiseless() {
  GnssSpec s;
  s.rate_hz = 5.0;
  s.sigma_pos_h_m = 0.0;
  s.sigma_pos_v_m = 0.0;
  s.sigma_vel_mps = 0.0;
  s.latency_s = 0.12;
  s.lever_arm_b_m = Vec3d(1.2, -0.4, -0.8);
  return s;
}

TEST(GnssModel, AntennaPositionAndVelocityIncludeTheLeverArmAtTheTimeOfValidity) {
  const Circle traj;
  const GnssSpec spec = noiseless();
  const auto fixes = GnssModel(spec, traj).fixes(20.0);
  ASSERT_EQ(fixes.size(), 101u);  // t = 0, 0.2, ..., 20
  for (const GnssSample& f : fixes) {
    SCOPED_TRACE(f.t_valid_s);
    EXPECT_NEAR(f.t_send_s - f.t_valid_s, spec.latency_s, 1e-12);
    EXPECT_LT((f.r_n_m - antenna_r(f.t_valid_s, spec.lever_arm_b_m)).norm(), kGeometryTol);
    EXPECT_LT((f.v_n_mps - antenna_v(f.t_valid_s, spec.lever_arm_b_m)).norm(), kGeometryTol);
  }
  // A fix describes its time of validity, not its transmission: 0.12 s later the antenna has
  // moved |v| × 0.12 ≈ 1.2 m, far beyond the tolerance.
  const GnssSample& f = fixes[10];
  EXPECT_GT((f.r_n_m - antenna_r(f.t_send_s, spec.lever_arm_b_m)).norm(), 1.0);
  // Without the ω × l term the velocity would be off by Ω |l_xy| ≈ 0.25 m/s.
  const Vec3d v_centre = antenna_v(f.t_valid_s, Vec3d::Zero());
  EXPECT_GT((f.v_n_mps - v_centre).norm(), 0.2);
}

TEST(GnssModel, PositionsAreFromTheNavigationOrigin) {
  const Circle traj;
  const Vec3d origin(kR, 0.0, -kH);  // the array centre at t = 0: the alignment point
  const auto fixes = GnssModel(noiseless(), traj, origin).fixes(1.0);
  ASSERT_FALSE(fixes.empty());
  EXPECT_LT((fixes[0].r_n_m - (antenna_r(0.0, noiseless().lever_arm_b_m) - origin)).norm(),
            kGeometryTol);
}

TEST(GnssModel, OutagesDropFixesAndIdsStayContiguous) {
  const Circle traj;
  GnssSpec spec = noiseless();
  spec.outages = {{2.0, 4.0}, {7.5, 8.0}};
  const auto fixes = GnssModel(spec, traj).fixes(10.0);
  // 51 times from 0 to 10 s; [2, 4) holds 10 of them, [7.5, 8) holds 7.6 and 7.8.
  ASSERT_EQ(fixes.size(), 51u - 10u - 2u);
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const double t = fixes[i].t_valid_s;
    EXPECT_FALSE(t >= 2.0 && t < 4.0) << t;
    EXPECT_FALSE(t >= 7.5 && t < 8.0) << t;
    EXPECT_EQ(fixes[i].index, i);
  }
}

TEST(GnssModel, SameSeedSameFixes) {
  const Circle traj;
  GnssSpec spec;
  spec.seed = 42;
  const auto a = GnssModel(spec, traj).fixes(5.0);
  const auto b = GnssModel(spec, traj).fixes(5.0);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].r_n_m, b[i].r_n_m);
    EXPECT_EQ(a[i].v_n_mps, b[i].v_n_mps);
  }
  spec.seed = 43;
  EXPECT_NE(GnssModel(spec, traj).fixes(5.0)[3].r_n_m, a[3].r_n_m);
}

// Noise statistics. N = 40 001 fixes (10 Hz for 4000 s). For Gaussian noise the sample standard
// deviation s of N draws has s/σ ≈ 1 + N(0, 1/(2N)), sd 0.0035; the mean has sd σ/√N. Both are
// checked at 5 sd: for a random seed each check fails with probability 5.7e-7 (two-sided normal
// tail at 5 sd), all twelve together with less than 7e-6. The seed is fixed, so the test itself
// is deterministic; the probability says how unlikely it is that a correct model fails it.
constexpr double kSigmaTol = 5.0 / 282.8;  // 5 / sqrt(2 N)
constexpr double kMeanTol = 5.0 / 200.0;   // 5 / sqrt(N), in units of σ

TEST(GnssModel, NoiseHasTheStatedSigmaAndNoBias) {
  const Circle traj;
  GnssSpec spec;
  spec.rate_hz = 10.0;
  spec.sigma_pos_h_m = 1.5;
  spec.sigma_pos_v_m = 3.0;
  spec.sigma_vel_mps = 0.07;
  spec.lever_arm_b_m = Vec3d(0.5, 0.2, -1.0);
  spec.seed = 12345;
  const auto fixes = GnssModel(spec, traj).fixes(4000.0);
  ASSERT_EQ(fixes.size(), 40001u);
  const double n = static_cast<double>(fixes.size());
  const double sigma[6] = {spec.sigma_pos_h_m, spec.sigma_pos_h_m, spec.sigma_pos_v_m,
                           spec.sigma_vel_mps, spec.sigma_vel_mps, spec.sigma_vel_mps};
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE(k);
    double sum = 0.0;
    double sum2 = 0.0;
    for (const GnssSample& f : fixes) {
      const double e =
          k < 3 ? f.r_n_m[k] - f.r_true_n_m[k] : f.v_n_mps[k - 3] - f.v_true_n_mps[k - 3];
      sum += e;
      sum2 += e * e;
    }
    const double mean = sum / n;
    const double sd = std::sqrt((sum2 - n * mean * mean) / (n - 1.0));
    EXPECT_NEAR(sd / sigma[k], 1.0, kSigmaTol);
    EXPECT_NEAR(mean / sigma[k], 0.0, kMeanTol);
  }
  // The truth behind the noise is the geometry checked above.
  EXPECT_LT((fixes[7].r_true_n_m - antenna_r(0.7, spec.lever_arm_b_m)).norm(), kGeometryTol);
}

constexpr const char* kBase = R"([scenario]
duration_s = 2.0
rate_hz = 100.0
[trajectory]
kind = "rest"
)";

TEST(GnssScenario, TheGnssTableIsOptionalAndParsed) {
  const auto none = parse_scenario(kBase, "base.toml");
  ASSERT_TRUE(none.is_ok()) << none.error().message;
  EXPECT_FALSE(none->gnss.has_value());
  const auto with = parse_scenario(std::string(kBase) + R"([gnss]
rate_hz = 5
sigma_pos_m = [1.5, 3.0]
sigma_vel_mps = 0.05
latency_s = 0.06
lever_arm_m = [-1.0, 0.0, -1.2]
outages = [[8.0, 12.0], [15, 16.5]]
seed = 3
)",
                                   "gnss.toml");
  ASSERT_TRUE(with.is_ok()) << with.error().message;
  ASSERT_TRUE(with->gnss.has_value());
  const GnssSpec& g = *with->gnss;
  EXPECT_EQ(g.rate_hz, 5.0);
  EXPECT_EQ(g.sigma_pos_h_m, 1.5);
  EXPECT_EQ(g.sigma_pos_v_m, 3.0);
  EXPECT_EQ(g.sigma_vel_mps, 0.05);
  EXPECT_EQ(g.latency_s, 0.06);
  EXPECT_EQ(g.lever_arm_b_m, Vec3d(-1.0, 0.0, -1.2));
  ASSERT_EQ(g.outages.size(), 2u);
  EXPECT_EQ(g.outages[1], std::make_pair(15.0, 16.5));
  EXPECT_EQ(g.seed, 3u);
}

TEST(GnssScenario, BadGnssKeysNameTheKeyAndLine) {
  for (const char* bad : {"[gnss]\nrate = 5\n", "[gnss]\noutages = [[3.0, 2.0]]\n",
                          "[gnss]\nsigma_pos_m = [1.0]\n", "[gnss]\nrate_hz = -1\n"}) {
    SCOPED_TRACE(bad);
    const auto r = parse_scenario(std::string(kBase) + bad, "bad.toml");
    ASSERT_FALSE(r.is_ok());
    EXPECT_NE(r.error().message.find("bad.toml:"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("gnss."), std::string::npos) << r.error().message;
  }
}

}  // namespace
}  // namespace gfins::sim
