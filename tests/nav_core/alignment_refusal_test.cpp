// The static alignment refuses a window in which the board was not at rest and says why
// (PipelineCounters::last_refusal, docs/math.md, "Alignment"), with aiding on: the array's forward
// physics written in filter_truth.hpp for a board that is shaken (specific force scattered), one
// that oscillates about the vertical (angular acceleration, the specific force unchanged) and
// one that accelerates smoothly (neither scattered: only |f̄| differs from gravity). Each
// disturbance is far beyond its limit (PipelineConfig: 0.05 m/s² of scatter, 0.5 rad/s² RMS,
// 0.1 m/s² of |f̄| − g) so that only the check it is made for can explain the refusal; a board at
// rest aligns at the end of its first window.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>

#include "gfins/nav_core/pipeline.hpp"
#include "nav_core/filter_truth.hpp"

namespace gfins::nav {
namespace {

constexpr double kRateHz = 1000.0;
constexpr double kPi = 3.14159265358979323846;

class Board {
 public:
  Board() {
    config_.front_end.volts_per_count.fill(10.0 / 8388608.0);
    config_.front_end.scale_v_per_g.fill(1.33);
    config_.gravity = GravityModel<double>::constant(testing::kG);
    config_.aiding.enabled = true;
    configured_ = pipeline_.configure(config_).is_ok();
  }
  bool configured() const { return configured_; }
  const NavPipeline<double>& pipeline() const { return pipeline_; }

  /// Samples k0..k1-1 of the truth x(t), plus per-sensor white noise of noise_mps2 (seeded).
  void run(std::uint32_t k0, std::uint32_t k1, const std::function<testing::Truth(double)>& x,
           double noise_mps2 = 0.0) {
    testing::SensorErrors errors(0.0, noise_mps2, 20261129);
    for (std::uint32_t k = k0; k < k1; ++k) {
      const double t = k / kRateHz;
      const Vec6<double> s =
          errors.apply(testing::ideal_outputs(pipeline_.solver().geometry(), x(t)));
      RawSample r;
      for (int j = 0; j < 6; ++j) {
        r.counts[static_cast<std::size_t>(j)] =
            static_cast<std::int32_t>(std::lround(pipeline_.front_end().counts_for(j, s(j))));
      }
      r.t_ns = static_cast<std::int64_t>(k) * 1'000'000;
      r.seq = k;
      (void)pipeline_.process(r);
    }
  }

 private:
  PipelineConfig<double> config_;
  NavPipeline<double> pipeline_;
  bool configured_ = false;
};

testing::Truth at_rest(double) { return testing::rest(Quat<double>::Identity()); }

// Three 1 s windows of the disturbance x: each refused, for `why`; the board still aligning.
void expect_three_refusals(Board& b, const std::function<testing::Truth(double)>& x, double noise,
                           AlignmentRefusal why) {
  ASSERT_TRUE(b.configured());
  b.run(0, 3001, x, noise);
  EXPECT_EQ(b.pipeline().phase(), PipelinePhase::kAligning);
  EXPECT_EQ(b.pipeline().counters().alignment_restarts, 3u);
  EXPECT_EQ(b.pipeline().counters().last_refusal, why);
}

TEST(AlignmentRefusal, ABoardAtRestAlignsAtTheEndOfItsFirstWindow) {
  Board b;
  ASSERT_TRUE(b.configured());
  b.run(0, 1001, at_rest, 1e-3);
  EXPECT_EQ(b.pipeline().phase(), PipelinePhase::kNavigating);
  EXPECT_EQ(b.pipeline().counters().alignment_restarts, 0u);
  EXPECT_EQ(b.pipeline().counters().last_refusal, AlignmentRefusal::kNone);
}

// Shaken: 0.5 m/s² of white noise per sensor scatters the specific force by about that (and the
// angular acceleration too; the scatter is checked first).
TEST(AlignmentRefusal, AShakenBoardIsRefusedForItsSpecificForce) {
  Board b;
  expect_three_refusals(b, at_rest, 0.5, AlignmentRefusal::kSpecificForce);
}

// Turning back and forth about the vertical: ω̇ = 3 sin(2π·2 t) rad/s² (RMS 2.1 rad/s²); a turn
// about down leaves the specific force at the centre at −g, and the array's centripetal terms
// (|ω| ≤ 0.24 rad/s over 0.1 m: 6 mm/s²) stay below the scatter limit.
TEST(AlignmentRefusal, ABoardTurningToAndFroIsRefusedForItsAngularAcceleration) {
  Board b;
  const auto turning = [](double t) {
    constexpr double kAmp = 3.0;
    constexpr double kW = 2 * kPi * 2.0;
    testing::Truth x;
    const double angle = -kAmp / (kW * kW) * std::sin(kW * t);
    x.q_nb = Quat<double>(Eigen::AngleAxisd(angle, Vec3<double>::UnitZ()));
    x.w_b = Vec3<double>(0, 0, -kAmp / kW * std::cos(kW * t));
    x.wdot_b = Vec3<double>(0, 0, kAmp * std::sin(kW * t));
    return x;
  };
  expect_three_refusals(b, turning, 1e-3, AlignmentRefusal::kAngularAccel);
}

// Accelerating north at a steady 2 m/s²: nothing scatters, the window reads like a tilt of 11.5°,
// and only |f̄| = √(g² + 2²) = 10.008 m/s², 0.20 above g, gives it away.
TEST(AlignmentRefusal, ASmoothlyAcceleratingBoardIsRefusedForTheGravityMagnitude) {
  Board b;
  const auto accelerating = [](double t) {
    testing::Truth x = testing::rest(Quat<double>::Identity());
    x.a_n = Vec3<double>(2.0, 0, 0);
    x.v_n = x.a_n * t;
    return x;
  };
  expect_three_refusals(b, accelerating, 1e-3, AlignmentRefusal::kGravityMagnitude);
  // Once it stands still, a window at rest is accepted (the one in progress holds a sample of the
  // acceleration, which scatters it beyond the limit: 2 m/s² / √1000 = 0.063 m/s²).
  b.run(3001, 5001, at_rest, 1e-3);
  EXPECT_EQ(b.pipeline().phase(), PipelinePhase::kNavigating);
}

}  // namespace
}  // namespace gfins::nav
