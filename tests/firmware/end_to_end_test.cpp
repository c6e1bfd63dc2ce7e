// End to end on the simulated board: the NavState stream the sample loop hands to the publisher
// equals, bit for bit, a host-only run of the navigation core (NavPipeline<float> driven directly
// with the same RawSamples). The oracle is the core itself run without the firmware around it:
// any difference means the firmware changed, reordered, dropped or duplicated a sample, or
// configured the core differently from what the configuration and calibration say.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>

#include "sim_rig.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

std::uint32_t bits(float x) { return std::bit_cast<std::uint32_t>(x); }

// Compares the navigation values bit for bit; reports the first difference.
::testing::AssertionResult same_values(const nav::NavState<float>& a,
                                       const nav::NavState<float>& b) {
  const auto cmp = [&](const char* what, const float* x, const float* y, int n) {
    for (int i = 0; i < n; ++i) {
      if (bits(x[i]) != bits(y[i])) {
        return ::testing::AssertionFailure() << what << "[" << i << "] differs at seq " << a.seq
                                             << ": " << x[i] << " vs " << y[i];
      }
    }
    return ::testing::AssertionSuccess();
  };
  for (auto r :
       {cmp("q_nb", a.q_nb.coeffs().data(), b.q_nb.coeffs().data(), 4),
        cmp("w_b", a.w_b.data(), b.w_b.data(), 3),
        cmp("wdot_b", a.wdot_b.data(), b.wdot_b.data(), 3),
        cmp("f_b", a.f_b.data(), b.f_b.data(), 3), cmp("a_n", a.a_n.data(), b.a_n.data(), 3),
        cmp("v_n", a.v_n.data(), b.v_n.data(), 3), cmp("r_n", a.r_n.data(), b.r_n.data(), 3)}) {
    if (!r) return r;
  }
  return ::testing::AssertionSuccess();
}

// The host-only reference: the same configuration the firmware derives from its configuration
// file and calibration, the same samples, the core's one entry per sample.
std::vector<nav::NavState<float>> host_only_run(const SimRig& rig) {
  nav::PipelineConfig<float> cfg = pipeline_config(rig.config, rig.factory);
  auto p = std::make_unique<nav::NavPipeline<float>>();
  EXPECT_TRUE(p->configure(cfg).is_ok());
  std::vector<nav::NavState<float>> out;
  out.reserve(rig.tap->samples().size());
  for (const RawSample& s : rig.tap->samples()) {
    p->process(s);
    out.push_back(p->state());
  }
  return out;
}

void expect_bit_exact(SimRig& rig) {
  const auto& epochs = rig.recording->epochs();
  const auto reference = host_only_run(rig);
  ASSERT_EQ(epochs.size(), reference.size());
  ASSERT_EQ(rig.recording->overflow(), 0u);
  const auto& samples = rig.tap->samples();
  std::size_t stepped = 0;
  for (std::size_t i = 0; i < epochs.size(); ++i) {
    const nav::NavState<float>& e = epochs[i].nav;
    // Every epoch is stamped with the sample just read ...
    ASSERT_EQ(e.seq, samples[i].seq) << "epoch " << i;
    ASSERT_EQ(e.t_ns, samples[i].t_ns) << "epoch " << i;
    // ... and carries the core's values after that sample, bit for bit.
    ASSERT_TRUE(same_values(e, reference[i])) << "epoch " << i;
    if (reference[i].seq == samples[i].seq) {
      // The core stepped on this sample: its status too.
      ASSERT_EQ(e.status, reference[i].status) << "epoch " << i;
      ++stepped;
    } else {
      // The core held its state (aligning, or a rejected sample, flagged as such).
      const bool rejected = (samples[i].flags & sample_flags::kCrcError) != 0 ||
                            (samples[i].flags & sample_flags::kSaturated) != 0;
      ASSERT_EQ((e.status & nav::nav_status::kInputInvalid) != 0, rejected) << "epoch " << i;
    }
  }
  // Alignment takes alignment_s · rate samples; every later valid sample is a step.
  EXPECT_GT(stepped, epochs.size() - 1100);
}

TEST(EndToEnd, RestScenarioNavStreamEqualsHostOnlyCoreBitForBit) {
  // Given the rest scenario (alignment, then 4 s of navigation) on the simulated board
  SimRig rig("rest", 5.0);
  rig.configure();
  // When the firmware loop runs it to the end
  rig.run();
  // Then every sample was read and handed on once, in order
  ASSERT_EQ(rig.tap->samples().size(), rig.samples);
  EXPECT_EQ(rig.loop->health().samples, rig.samples);
  EXPECT_EQ(rig.loop->mode(), Mode::kNavigating);
  // and the navigation states equal the core's own run on the same samples
  expect_bit_exact(rig);
}

TEST(EndToEnd, FaultyRunStillEqualsHostOnlyCoreOnTheSamplesRead) {
  // Faults change which samples arrive and which are rejected; the core must still see exactly
  // what it would see when driven directly with those samples.
  sim_board::FaultPlan f;
  f.crc_error_at = {1500, 2500};
  f.missing_edges = {1800, 1801};
  f.saturated_channel = 4;
  f.saturated_from = 3000;
  f.saturated_until = 3010;
  SimRig rig("rest", 4.0, f);
  rig.configure();
  rig.run();
  EXPECT_EQ(rig.tap->samples().size(), rig.samples - 2);
  expect_bit_exact(rig);
}

TEST(EndToEnd, EpochCarriesCalibrationIdentityAndMode) {
  SimRig rig("rest", 2.0);
  rig.configure();
  rig.run();
  const auto& epochs = rig.recording->epochs();
  ASSERT_FALSE(epochs.empty());
  // Alignment lasts alignment_s = 1 s = 1000 samples: aligning before, navigating after.
  EXPECT_EQ(epochs.front().mode, Mode::kAligning);
  EXPECT_EQ(epochs.front().status_bits & status_bits::kAligned, 0u);
  EXPECT_EQ(epochs.back().mode, Mode::kNavigating);
  EXPECT_NE(epochs.back().status_bits & status_bits::kAligned, 0u);
  EXPECT_EQ(epochs.back().status_bits & status_bits::kUncalibrated, 0u);
  EXPECT_EQ(epochs.back().cal_id, calib_file::cal_id_of(rig.factory));
  EXPECT_NE(epochs.back().cal_id, 0u);
}

}  // namespace
}  // namespace gfins::app
