// Static-interval detector on a synthetic continuous recording: the board held in ten poses with
// smooth turns between them, one pose held too briefly and one shaken. Then the detected
// intervals feed the multi-attitude solver end to end.
#include "gfins/nav_core/calibration/static_detector.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "gfins/nav_core/misalignment.hpp"

namespace gfins::calib {
namespace {

using Sample = std::array<double, 6>;

constexpr double kRateHz = 500.0;
constexpr double kNoiseV = 1e-3;        // σ of one sample of a still pose, V
constexpr double kShakenNoiseV = 2e-2;  // σ while the board is shaken (the noisy pose), V
constexpr double kMaxStdV = 3e-3;       // still threshold: 3 × the sensor noise
constexpr double kTurnS = 1.0;          // duration of each turn between poses
constexpr double kHoldS = 3.0;          // how long a good pose is held
constexpr double kShortHoldS = 1.0;     // the pose held too briefly (min_still_s = 2 s)

constexpr std::array<double, 6> kScale = {0.51, 0.33, 0.50, 2.49, 0.34, 2.48};
constexpr std::array<double, 6> kBias = {-7e-4, -2e-4, 9e-4, -8e-3, -9e-4, -4.7e-3};

enum class Kind { kGood, kShort, kNoisy };
struct Pose {
  std::array<double, 3> f_b_g;
  Kind kind;
  double hold_s;
};
struct TruePose {
  std::uint64_t start = 0;
  std::uint64_t end = 0;
  Kind kind = Kind::kGood;
  std::array<double, 3> f_b_g{};
};

nav::Vec3<double> unit(const std::array<double, 3>& v) {
  return nav::Vec3<double>(v[0], v[1], v[2]).normalized();
}

// Six faces, two diagonals, plus a too-short pose and a shaken pose (ten poses in all).
std::vector<Pose> script() {
  const double k = 1.0 / std::sqrt(3.0);
  return {{{0, 0, -1}, Kind::kGood, kHoldS},      {{1, 0, 0}, Kind::kGood, kHoldS},
          {{0, 1, 0}, Kind::kShort, kShortHoldS}, {{-1, 0, 0}, Kind::kGood, kHoldS},
          {{0, -1, 0}, Kind::kGood, kHoldS},      {{k, k, k}, Kind::kNoisy, kHoldS},
          {{0, 0, 1}, Kind::kGood, kHoldS},       {{0, 1, 0}, Kind::kGood, kHoldS},
          {{-k, k, -k}, Kind::kGood, kHoldS},     {{k, -k, k}, Kind::kGood, kHoldS}};
}

class Recording {
 public:
  explicit Recording(std::uint64_t seed) : rng_(seed) {
    nav::Misalignment<double> m;
    m.orientation.beta = {0.019, -0.003, -0.010, -0.013, 0.043, 0.043};
    m.orientation.alpha = {-0.046, 0.045, -0.015, -0.013, 0.002, -0.025};
    angles_ = m.orientation;
    geo_ = nav::misaligned_geometry(nav::table1_geometry(1.0), m);
  }

  // Generates the whole recording: 0.5 s still before the first pose is part of it.
  std::vector<Sample> generate(std::vector<TruePose>& truth) {
    std::vector<Sample> out;
    const auto poses = script();
    nav::Vec3<double> prev = unit(poses[0].f_b_g);
    for (std::size_t p = 0; p < poses.size(); ++p) {
      const nav::Vec3<double> next = unit(poses[p].f_b_g);
      if (p > 0) turn(prev, next, out);
      TruePose t;
      t.start = out.size();
      t.kind = poses[p].kind;
      t.f_b_g = poses[p].f_b_g;
      const double sigma = poses[p].kind == Kind::kNoisy ? kShakenNoiseV : kNoiseV;
      const auto n = static_cast<std::size_t>(poses[p].hold_s * kRateHz);
      for (std::size_t k = 0; k < n; ++k) out.push_back(sample(next, sigma));
      t.end = out.size();
      truth.push_back(t);
      prev = next;
    }
    return out;
  }

  Sample ideal(const nav::Vec3<double>& f) const {
    Sample s;
    for (std::size_t i = 0; i < 6; ++i) s[i] = kScale[i] * (kBias[i] + geo_.theta_b[i].dot(f));
    return s;
  }
  const nav::OrientationErrors<double>& angles() const { return angles_; }

 private:
  Sample sample(const nav::Vec3<double>& f, double sigma) {
    std::normal_distribution<double> noise(0.0, sigma);
    Sample s = ideal(f);
    for (double& x : s) x += noise(rng_);
    return s;
  }
  // Smooth turn (smoothstep in angle, slerp in direction): slow at both ends, as a hand does it.
  void turn(const nav::Vec3<double>& a, const nav::Vec3<double>& b, std::vector<Sample>& out) {
    const auto n = static_cast<std::size_t>(kTurnS * kRateHz);
    const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(a, b);
    for (std::size_t k = 0; k < n; ++k) {
      const double u = (static_cast<double>(k) + 0.5) / static_cast<double>(n);
      const double s = u * u * (3.0 - 2.0 * u);
      const nav::Vec3<double> f = Eigen::Quaterniond::Identity().slerp(s, q) * a;
      out.push_back(sample(f, kNoiseV));
    }
  }

  std::mt19937_64 rng_;
  nav::OrientationErrors<double> angles_{};
  nav::ArrayGeometry<double, 6> geo_{};
};

StaticDetectorConfig<double> detector_config() {
  StaticDetectorConfig<double> c;
  c.sample_rate_hz = kRateHz;
  c.window_s = 0.1;
  c.max_std_v.fill(kMaxStdV);
  c.min_still_s = 2.0;
  c.min_pose_s = 0.5;
  return c;
}

struct Detected {
  std::vector<StaticInterval<double>> intervals;
  std::vector<RejectedPose<double>> rejected;
};

Detected run_detector(const std::vector<Sample>& rec) {
  auto d = StaticDetector<double>::create(detector_config());
  EXPECT_TRUE(d.is_ok()) << d.status().message();
  for (const Sample& s : rec) EXPECT_TRUE(d->push(s).is_ok());
  EXPECT_TRUE(d->finish().is_ok());
  return {{d->intervals().begin(), d->intervals().end()},
          {d->rejected().begin(), d->rejected().end()}};
}

// An interval lies inside its pose, losing at most the windows the detector trims plus the one
// that straddles each boundary: window 50 samples, trim 1 → up to 2 windows (100 samples) per end.
constexpr std::uint64_t kMaxLostPerEndSamples = 100;
// Interval mean vs the noise-free output: 5σ of a mean of ≥ 1300 samples of σ = 1 mV. A window of
// the turn left in the interval would shift it by far more (≥ 2 mV for the 0.33 V/g sensor).
constexpr double kMeanTolV = 5.0 * kNoiseV / 36.0;
// Interval std vs the true noise: σ of a sample std over n ≥ 1300 is σ/√(2n) ≈ 2 %; 15 % allowed.
constexpr double kStdRelTol = 0.15;

TEST(StaticDetector, FindsTheStillPosesAndReportsTheTwoBadOnes) {
  // Given a recording of ten poses, one held 1 s (too short) and one shaken (too noisy)
  Recording rec(42);
  std::vector<TruePose> truth;
  const auto samples = rec.generate(truth);
  // When the detector runs over it
  const Detected got = run_detector(samples);
  // Then the eight good poses are found, in order, inside their true spans
  std::vector<TruePose> good;
  for (const auto& t : truth) {
    if (t.kind == Kind::kGood) good.push_back(t);
  }
  ASSERT_EQ(got.intervals.size(), good.size());
  for (std::size_t k = 0; k < good.size(); ++k) {
    const auto& it = got.intervals[k];
    const auto& t = good[k];
    EXPECT_GE(it.start_index, t.start) << "interval " << k;
    EXPECT_LE(it.end_index, t.end) << "interval " << k;
    EXPECT_LE(it.start_index, t.start + kMaxLostPerEndSamples) << "interval " << k;
    EXPECT_GE(it.end_index + kMaxLostPerEndSamples, t.end) << "interval " << k;
    EXPECT_EQ(it.count, it.end_index - it.start_index);
    const Sample ideal = rec.ideal(unit(t.f_b_g));
    for (std::size_t c = 0; c < 6; ++c) {
      EXPECT_NEAR(it.mean_v[c], ideal[c], kMeanTolV) << "interval " << k << " channel " << c;
      EXPECT_NEAR(it.std_v[c], kNoiseV, kStdRelTol * kNoiseV);
    }
  }
  // and exactly the two bad poses are reported, with the right reason, where they were held
  ASSERT_EQ(got.rejected.size(), 2u);
  const TruePose& short_pose = truth[2];
  const TruePose& noisy_pose = truth[5];
  const RejectedPose<double>& r0 = got.rejected[0];
  const RejectedPose<double>& r1 = got.rejected[1];
  EXPECT_EQ(r0.reason, PoseRejection::kTooShort) << to_string(r0.reason);
  EXPECT_GE(r0.start_index, short_pose.start);
  EXPECT_LE(r0.end_index, short_pose.end);
  EXPECT_EQ(r1.reason, PoseRejection::kTooNoisy) << to_string(r1.reason);
  EXPECT_GE(r1.start_index + kMaxLostPerEndSamples, noisy_pose.start);
  EXPECT_LE(r1.end_index, noisy_pose.end + kMaxLostPerEndSamples);
  EXPECT_EQ(r1.noisy_channels, 0x3F);  // every channel was shaken
  for (std::size_t c = 0; c < 6; ++c) EXPECT_GT(r1.std_v[c], kMaxStdV);
}

TEST(StaticDetector, FloatDetectorFindsTheSameIntervals) {
  Recording rec(7);
  std::vector<TruePose> truth;
  const auto samples = rec.generate(truth);
  const Detected ref = run_detector(samples);
  StaticDetectorConfig<float> cf;
  cf.sample_rate_hz = static_cast<float>(kRateHz);
  cf.window_s = 0.1f;
  cf.max_std_v.fill(static_cast<float>(kMaxStdV));
  auto d = StaticDetector<float>::create(cf);
  ASSERT_TRUE(d.is_ok());
  for (const Sample& s : samples) {
    std::array<float, 6> f;
    for (std::size_t c = 0; c < 6; ++c) f[c] = static_cast<float>(s[c]);
    ASSERT_TRUE(d->push(f).is_ok());
  }
  ASSERT_TRUE(d->finish().is_ok());
  ASSERT_EQ(d->intervals().size(), ref.intervals.size());
  ASSERT_EQ(d->rejected().size(), ref.rejected.size());
  // Float means over ~1400 samples of values ≤ 2.5 V: rounding ≤ 1e-6 V, far below the noise.
  constexpr double kFloatMeanTolV = 1e-5;
  for (std::size_t k = 0; k < ref.intervals.size(); ++k) {
    EXPECT_EQ(d->intervals()[k].start_index, ref.intervals[k].start_index);
    EXPECT_EQ(d->intervals()[k].end_index, ref.intervals[k].end_index);
    for (std::size_t c = 0; c < 6; ++c) {
      EXPECT_NEAR(static_cast<double>(d->intervals()[k].mean_v[c]), ref.intervals[k].mean_v[c],
                  kFloatMeanTolV);
    }
  }
}

TEST(StaticDetector, IntervalsFeedTheSolverEndToEnd) {
  // Given the detected intervals and the list of poses the operator was asked to hold
  Recording rec(42);
  std::vector<TruePose> truth;
  const auto samples = rec.generate(truth);
  const Detected got = run_detector(samples);
  const auto poses = script();
  std::vector<std::array<double, 3>> expected;
  for (const auto& p : poses) {
    const nav::Vec3<double> u = unit(p.f_b_g);
    expected.push_back({u.x(), u.y(), u.z()});
  }
  PoseAssignmentConfig<double> pc;
  for (std::size_t i = 0; i < 6; ++i) pc.nominal_scale_v_per_g[i] = kScale[i] * 1.05;  // datasheet
  std::array<AttitudeObservation<double>, kMaxAttitudes> obs;
  std::vector<int> which(got.intervals.size());
  // When they are assigned to the nearest expected pose and calibrated
  const auto n = intervals_to_observations<double>(got.intervals, expected, pc, obs, which);
  ASSERT_TRUE(n.is_ok()) << n.status().message();
  ASSERT_EQ(n.value(), got.intervals.size());
  std::size_t g = 0;
  for (std::size_t p = 0; p < poses.size(); ++p) {
    if (poses[p].kind == Kind::kGood) {
      // pose 7 repeats pose 2's vector (0,1,0): the first of equal vectors is the nearest
      const int want = (p == 7) ? 2 : static_cast<int>(p);
      EXPECT_EQ(which[g++], want);
    }
  }
  const auto r = calibrate_multi_attitude<double>(
      std::span<const AttitudeObservation<double>>(obs.data(), n.value()));
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  // Then the calibration finds the truth within 5σ of its own stated uncertainty
  constexpr double kSigmas = 5.0;
  EXPECT_EQ(r->covariance_source[0], CovarianceSource::kStatedSigma);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_NEAR(r->scale_v_per_g[i], kScale[i], kSigmas * r->scale_std_v_per_g[i]);
    EXPECT_NEAR(r->bias_g[i], kBias[i], kSigmas * r->bias_std_g[i]);
    EXPECT_NEAR(r->orientation.beta[i], rec.angles().beta[i], kSigmas * r->orientation_std.beta[i]);
    EXPECT_NEAR(r->orientation.alpha[i], rec.angles().alpha[i],
                kSigmas * r->orientation_std.alpha[i]);
  }
  EXPECT_EQ(r->verdict, Verdict::kGood) << to_string(r->verdict);
}

TEST(StaticDetector, WithoutExpectedPosesTheDirectionIsEstimated) {
  Recording rec(3);
  std::vector<TruePose> truth;
  const auto samples = rec.generate(truth);
  const Detected got = run_detector(samples);
  PoseAssignmentConfig<double> pc;
  for (std::size_t i = 0; i < 6; ++i) pc.nominal_scale_v_per_g[i] = kScale[i] * 1.05;
  std::array<AttitudeObservation<double>, kMaxAttitudes> obs;
  std::vector<int> which(got.intervals.size());
  const auto n = intervals_to_observations<double>(got.intervals, {}, pc, obs, which);
  ASSERT_TRUE(n.is_ok());
  // A 5 % scale-factor mismatch scales every component alike (no direction error); the 3°
  // orientation errors and ≤ 8 mg biases tilt it by at most about 3.5°: 0.07 rad allowed.
  constexpr double kDirectionTolRad = 0.07;
  std::size_t g = 0;
  for (const auto& t : truth) {
    if (t.kind != Kind::kGood) continue;
    const auto& f = obs[g++].f_b_g;
    const double c = unit(t.f_b_g).dot(nav::Vec3<double>(f[0], f[1], f[2]));
    EXPECT_GT(c, std::cos(kDirectionTolRad));
  }
}

TEST(StaticDetector, NonFiniteSampleEndsThePose) {
  // Given 3 s still, one NaN sample, 3 s still: two intervals, split at the NaN
  auto d = StaticDetector<double>::create(detector_config());
  ASSERT_TRUE(d.is_ok());
  const Sample still = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  for (int k = 0; k < 1500; ++k) ASSERT_TRUE(d->push(still).is_ok());
  Sample bad = still;
  bad[3] = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(d->push(bad).is_ok());
  for (int k = 0; k < 1500; ++k) ASSERT_TRUE(d->push(still).is_ok());
  ASSERT_TRUE(d->finish().is_ok());
  ASSERT_EQ(d->intervals().size(), 2u);
  EXPECT_LE(d->intervals()[0].end_index, 1500u);
  EXPECT_GT(d->intervals()[1].start_index, 1500u);
}

TEST(StaticDetector, FullIntervalListIsResourceExhausted) {
  // Given a detector that holds one interval and a recording with two poses
  auto d = StaticDetector<double, 1, 4>::create(detector_config());
  ASSERT_TRUE(d.is_ok());
  Sample a = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  for (int k = 0; k < 1500; ++k) ASSERT_TRUE(d->push(a).is_ok());
  for (double& x : a) x += 0.5;  // an instant jump: a new pose
  for (int k = 0; k < 1500; ++k) ASSERT_TRUE(d->push(a).is_ok());
  // When the second pose closes, there is no room for it
  EXPECT_EQ(d->finish().code(), ErrorCode::kResourceExhausted);
  EXPECT_EQ(d->intervals().size(), 1u);
  EXPECT_EQ(d->dropped(), 1u);
}

TEST(StaticDetector, InvalidConfigIsInvalidArgument) {
  auto c = detector_config();
  c.sample_rate_hz = 0.0;
  EXPECT_EQ(StaticDetector<double>::create(c).status().code(), ErrorCode::kInvalidArgument);
  c = detector_config();
  c.max_std_v[4] = 0.0;
  EXPECT_EQ(StaticDetector<double>::create(c).status().code(), ErrorCode::kInvalidArgument);
  c = detector_config();
  c.window_s = 1.0 / kRateHz;  // one sample: no variance
  EXPECT_EQ(StaticDetector<double>::create(c).status().code(), ErrorCode::kInvalidArgument);
  c = detector_config();
  c.trim_windows = kMaxTrimWindows + 1;
  EXPECT_EQ(StaticDetector<double>::create(c).status().code(), ErrorCode::kInvalidArgument);
}

TEST(StaticDetector, ZeroNominalScaleFactorIsInvalidArgument) {
  PoseAssignmentConfig<double> pc;  // nominal scale factors left at zero
  std::array<StaticInterval<double>, 1> its{};
  std::array<AttitudeObservation<double>, 1> obs;
  std::array<int, 1> which{};
  const auto n = intervals_to_observations<double>(its, {}, pc, obs, which);
  EXPECT_EQ(n.status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace gfins::calib
