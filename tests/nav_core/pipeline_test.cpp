#include "gfins/nav_core/pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace gfins::nav {
namespace {

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // ±10 V input range (QA-1100 at 2.5 V/g needs more than the ADC's ±1.2 V: a divider).
    config_.front_end.volts_per_count.fill(10.0 / 8388608.0);
    config_.front_end.scale_v_per_g = {0.509874, 0.332572, 0.500242, 2.493301, 0.339215, 2.476663};
    config_.front_end.bias_g = {-0.000731, -0.000242, 0.000867, -0.007977, -0.000891, -0.004691};
    config_.alignment_samples = 200;
    ASSERT_TRUE(pipeline_.configure(config_).is_ok());
  }

  // ADC counts of an ideal array held still with attitude q_nb (NED, standard gravity).
  std::array<std::int32_t, 6> counts_at_rest(const Quat<double>& q_nb) const {
    const Vec3<double> f_b = -(q_nb.conjugate() * Vec3<double>(0, 0, kStandardGravity));
    const Vec6<double> s =
        pipeline_.solver().predict(Vec3<double>::Zero(), f_b, Vec3<double>::Zero());
    std::array<std::int32_t, 6> c{};
    for (int j = 0; j < 6; ++j) {
      c[static_cast<std::size_t>(j)] =
          static_cast<std::int32_t>(std::lround(pipeline_.front_end().counts_for(j, s(j))));
    }
    return c;
  }

  // One frame as the ADC driver hands it over.
  static RawSample frame(const std::array<std::int32_t, 6>& counts, std::int64_t t_ns,
                         std::uint32_t seq, std::uint32_t flags = 0) {
    RawSample s;
    s.counts = counts;
    s.t_ns = t_ns;
    s.seq = seq;
    s.flags = flags;
    return s;
  }

  // The bound on |δω̇| the rounding of the counts to one LSB leaves (see the first test): at
  // most half an LSB per channel through M, per axis, times √3 for the norm.
  double rounding_wdot_bound() const {
    double bound = 0.0;
    for (int i = 0; i < 3; ++i) {
      double row = 0.0;
      for (int j = 0; j < 6; ++j) {
        const auto jj = static_cast<std::size_t>(j);
        const double lsb_mps2 = config_.front_end.volts_per_count[jj] * kStandardGravity /
                                config_.front_end.scale_v_per_g[jj];
        row += std::abs(pipeline_.solver().m()(i, j)) * lsb_mps2 / 2;
      }
      bound = std::max(bound, row);
    }
    return bound * std::sqrt(3.0);
  }

  PipelineConfig<double> config_;
  NavPipeline<double> pipeline_;
};

TEST_F(PipelineTest, AlignsThenNavigatesAndStaysAtRest) {
  config_.heading_rad = 1.0;  // given, not sensed
  ASSERT_TRUE(pipeline_.configure(config_).is_ok());
  const auto q = quat_from_euler(0.05, -0.02, 1.0);
  const auto counts = counts_at_rest(q);
  std::uint32_t seq = 0;
  for (; seq < config_.alignment_samples - 1; ++seq) {
    EXPECT_EQ(pipeline_.process(frame(counts, seq * 1'000'000LL, seq)), PipelinePhase::kAligning);
  }
  EXPECT_EQ(pipeline_.process(frame(counts, seq * 1'000'000LL, seq)), PipelinePhase::kNavigating);
  const std::uint32_t first_nav_seq = seq;
  for (++seq; seq < 2200; ++seq) pipeline_.process(frame(counts, seq * 1'000'000LL, seq));
  const auto& st = pipeline_.state();
  const double t = (seq - 1 - first_nav_seq) * 1e-3;

  // The only error left is the rounding of the counts to one LSB: at most half an LSB of
  // specific force per channel, which M turns into a constant angular-acceleration bias
  // δω̇ ≤ Σ_j |M_ij| · LSB_j / 2. Kinematics then bound the drift (docs/math.md, error growth):
  // attitude δω̇ t²/2, velocity g δω̇ t³/6, position g δω̇ t⁴/24. The specific-force part of the
  // rounding is absorbed by the alignment (same samples), so tilt alone drives v and r.
  const double wdot_bound = rounding_wdot_bound();
  const double g = kStandardGravity;
  EXPECT_LT(st.q_nb.angularDistance(q), wdot_bound * t * t / 2 + 1e-6);
  EXPECT_LT(st.v_n.norm(), g * wdot_bound * t * t * t / 6);
  EXPECT_LT(st.r_n.norm(), g * wdot_bound * t * t * t * t / 24);
  // And it is a real drift, not zero: the test would notice a pipeline that ignores its input.
  EXPECT_GT(st.v_n.norm(), 0.0);
  EXPECT_EQ(st.seq, seq - 1);
  EXPECT_EQ(st.t_ns, (seq - 1) * 1'000'000LL);
  EXPECT_TRUE(st.status & nav_status::kAligned);
  EXPECT_EQ(pipeline_.counters().gaps, 0u);
  EXPECT_NEAR(pipeline_.alignment().roll_rad, 0.05, 1e-4);
  EXPECT_NEAR(pipeline_.alignment().pitch_rad, -0.02, 1e-4);
}

TEST_F(PipelineTest, CountsSampleGapsAndIntegratesAcrossThem) {
  const auto counts = counts_at_rest(Quat<double>::Identity());
  std::uint32_t seq = 0;
  for (; seq < config_.alignment_samples; ++seq) pipeline_.process(frame(counts, 0, seq));
  ASSERT_EQ(pipeline_.phase(), PipelinePhase::kNavigating);
  pipeline_.process(frame(counts, 0, seq + 3));  // three samples lost
  EXPECT_EQ(pipeline_.counters().gaps, 1u);
  EXPECT_EQ(pipeline_.counters().missed_samples, 3u);
  EXPECT_TRUE(pipeline_.state().status & nav_status::kSampleGap);
  pipeline_.process(frame(counts, 0, seq + 4));
  EXPECT_FALSE(pipeline_.state().status & nav_status::kSampleGap);
  EXPECT_EQ(pipeline_.counters().gaps, 1u);
}

// A counter that repeats or goes back (a recording spliced or rewound) is no gap and no time to
// integrate: the frame leaves the state as it was (bit for bit), counts as out of order, and the
// next frame is one period after it. Integrating it instead would take a step of 2^32 - k periods
// (49 days at 1 kHz) and count as many missing samples.
TEST_F(PipelineTest, ACounterThatRepeatsOrGoesBackIsNotIntegrated) {
  const auto counts = counts_at_rest(quat_from_euler(0.02, -0.01, 0.0));
  std::uint32_t seq = 100;
  std::int64_t t = 0;
  const auto next = [&](std::uint32_t s) {
    pipeline_.process(frame(counts, t, s));
    t += 1'000'000;
  };
  for (std::uint32_t i = 0; i < config_.alignment_samples + 10; ++i) next(seq++);
  ASSERT_EQ(pipeline_.phase(), PipelinePhase::kNavigating);
  for (const std::uint32_t bad : {seq - 1, seq - 50}) {  // a repeat, then 49 back
    const NavState<double> before = pipeline_.state();
    next(bad);
    EXPECT_EQ(pipeline_.state().v_n, before.v_n);
    EXPECT_EQ(pipeline_.state().r_n, before.r_n);
    EXPECT_EQ(pipeline_.state().q_nb.coeffs(), before.q_nb.coeffs());
    EXPECT_TRUE(pipeline_.state().status & nav_status::kSampleGap);
    seq = bad + 1;
  }
  EXPECT_EQ(pipeline_.counters().out_of_order, 2u);
  EXPECT_EQ(pipeline_.counters().gaps, 0u);
  EXPECT_EQ(pipeline_.counters().missed_samples, 0u);
  // Navigation goes on from the rewound counter, one period per frame, still at rest: the
  // velocity stays within the drift the rounding of the counts allows over the 1.01 s
  // navigated, g·δω̇·t³/6 (first test), which one 49-day step exceeds by orders of magnitude.
  for (int i = 0; i < 1000; ++i) next(seq++);
  EXPECT_FALSE(pipeline_.state().status & nav_status::kSampleGap);
  const double t_nav = 1.01;
  EXPECT_LT(pipeline_.state().v_n.norm(),
            kStandardGravity * rounding_wdot_bound() * t_nav * t_nav * t_nav / 6);
  EXPECT_TRUE(pipeline_.state().r_n.allFinite());
}

TEST_F(PipelineTest, RejectsSaturatedSamplesAndCountsThem) {
  auto counts = counts_at_rest(Quat<double>::Identity());
  counts[3] = kAdcCodeMax;
  pipeline_.process(frame(counts, 0, 0));
  EXPECT_EQ(pipeline_.counters().saturated, 1u);
  EXPECT_EQ(pipeline_.counters().rejected, 1u);
  EXPECT_EQ(pipeline_.counters().samples, 1u);
}

TEST_F(PipelineTest, FramesFlaggedSaturatedAreRejectedOffTheRailsToo) {
  // A producer's saturation flag (a clipped input) rejects the frame even when no count sits on a
  // rail, as a CRC error does: sample_flags::kNotMeasured, the rule every loop shares.
  const auto counts = counts_at_rest(Quat<double>::Identity());
  std::uint32_t seq = 0;
  for (; seq < config_.alignment_samples; ++seq) pipeline_.process(frame(counts, 0, seq));
  ASSERT_EQ(pipeline_.phase(), PipelinePhase::kNavigating);
  const NavState<double> before = pipeline_.state();
  pipeline_.process(frame(counts, 0, seq, sample_flags::kSaturated));
  EXPECT_EQ(pipeline_.counters().rejected, 1u);
  EXPECT_EQ(pipeline_.counters().saturated, 1u);
  EXPECT_EQ(pipeline_.state().seq, before.seq);
  EXPECT_EQ(pipeline_.state().v_n, before.v_n);
  // A frame flagged only as read late is a measurement.
  pipeline_.process(frame(counts, 0, seq + 1, sample_flags::kLateRead));
  EXPECT_EQ(pipeline_.counters().rejected, 1u);
  EXPECT_EQ(pipeline_.state().seq, seq + 1);
}

TEST_F(PipelineTest, CrcErrorFramesAreRejectedAndAreNotGaps) {
  // Given a navigating pipeline,
  const auto counts = counts_at_rest(Quat<double>::Identity());
  std::uint32_t seq = 0;
  for (; seq < config_.alignment_samples; ++seq) pipeline_.process(frame(counts, 0, seq));
  ASSERT_EQ(pipeline_.phase(), PipelinePhase::kNavigating);
  const NavState<double> before = pipeline_.state();
  // when a frame arrives with a CRC error (its counts could be anything),
  auto garbage = counts;
  garbage[0] = 1234567;
  pipeline_.process(frame(garbage, 0, seq, sample_flags::kCrcError));
  // then it is counted as rejected, leaves the state untouched, and is not a counter jump;
  EXPECT_EQ(pipeline_.counters().rejected, 1u);
  EXPECT_EQ(pipeline_.counters().saturated, 0u);
  EXPECT_EQ(pipeline_.counters().gaps, 0u);
  EXPECT_EQ(pipeline_.state().seq, before.seq);
  EXPECT_EQ(pipeline_.state().v_n, before.v_n);
  // and the next good frame integrates across the hole (two periods) and says so.
  pipeline_.process(frame(counts, 0, seq + 1));
  EXPECT_EQ(pipeline_.counters().gaps, 0u);
  EXPECT_EQ(pipeline_.state().seq, seq + 1);
  EXPECT_TRUE(pipeline_.state().status & nav_status::kSampleGap);
}

TEST_F(PipelineTest, GapsAreCountedOnceWhileAligningToo) {
  // A jump of the counter is a gap whatever the phase, counted once per jump, with its size.
  const auto counts = counts_at_rest(Quat<double>::Identity());
  pipeline_.process(frame(counts, 0, 0xFFFFFFFDu));
  pipeline_.process(frame(counts, 0, 0xFFFFFFFEu));
  pipeline_.process(frame(counts, 0, 0));  // 0xFFFFFFFF lost, across the wrap of the counter
  pipeline_.process(frame(counts, 0, 1));
  pipeline_.process(frame(counts, 0, 5));  // 2..4 lost
  EXPECT_EQ(pipeline_.phase(), PipelinePhase::kAligning);
  EXPECT_EQ(pipeline_.counters().gaps, 2u);
  EXPECT_EQ(pipeline_.counters().missed_samples, 4u);
  EXPECT_EQ(pipeline_.counters().samples, 5u);
}

TEST_F(PipelineTest, BadConfigurationKeepsTheLastGoodOne) {
  PipelineConfig<double> bad = config_;
  bad.front_end.scale_v_per_g[0] = -1.0;
  EXPECT_EQ(pipeline_.configure(bad).code(), ErrorCode::kInvalidArgument);
  bad = config_;
  bad.nominal.theta_b[1] = bad.nominal.theta_b[0];  // two identical sensors: singular
  bad.nominal.rho_b[1] = bad.nominal.rho_b[0];
  EXPECT_EQ(pipeline_.configure(bad).code(), ErrorCode::kSingular);
  bad = config_;
  bad.misalignment.orientation.beta[0] = 1.5;  // rad: far outside the small-angle model
  bad.compensator = CompensatorKind::kPaper;
  EXPECT_EQ(pipeline_.configure(bad).code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(pipeline_.configured());
  EXPECT_EQ(pipeline_.config().front_end.scale_v_per_g[0], config_.front_end.scale_v_per_g[0]);
  EXPECT_EQ(pipeline_.solver().geometry().theta_b[1], config_.nominal.theta_b[1]);
}

}  // namespace
}  // namespace gfins::nav
