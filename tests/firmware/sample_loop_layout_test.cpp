// The sample loop as its callers see it and as the library built it. The inline accessors of
// SampleLoop (mode(), health(), pipeline(), cal_id(), ...) are compiled into the caller; the
// members are written by sample_loop.cpp in libgfins_app. An object of that library compiled
// against older headers (an incremental build that missed an edit) made the loop report mode 0
// on armhf although it navigated: a grown member moved the ones after it, and the inline mode()
// read a byte the library never wrote (docs/ci.md, "armhf: ... reported mode 0").
//
// Keeping objects fresh is the build system's job (docs/ci.md says how); this test checks the
// symptom through behaviour only, with no hook in the firmware's API: after every cycle each
// inline accessor, spread over the class from its first member (pipeline_) to its last (mode_),
// must read what the out-of-line code published in that cycle's epoch (the epoch is a copy made
// by sample_loop.cpp with its own view of the layout, recorded by the test's sink), and the
// sample count must be the number of samples the test's own tap saw the loop read.
#include <gtest/gtest.h>

#include "sim_rig.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

// 1.2 s of the built-in "rest" scenario at 1 kHz: the 1000 alignment samples (docs/firmware.md),
// then 200 samples of navigation, so both modes and both pipeline phases are read.
constexpr double kRunSeconds = 1.2;

TEST(SampleLoopLayout, EveryInlineAccessorReadsWhatTheLoopPublished) {
  // Given the simulated board at rest,
  SimRig rig("rest", kRunSeconds);
  // before configure() the loop is starting up; configure() (out of line) starts alignment.
  EXPECT_EQ(rig.loop->mode(), can::Mode::kStartup);
  rig.configure();
  EXPECT_EQ(rig.loop->mode(), can::Mode::kAligning);
  bool navigated = false;
  // When it runs cycle by cycle,
  while (!rig.source->finished()) {
    rig.run_cycles(1);
    ASSERT_FALSE(rig.recording->epochs().empty());
    const can::Epoch& e = rig.recording->epochs().back();
    const std::size_t cycle = rig.recording->epochs().size();
    SCOPED_TRACE("cycle " + std::to_string(cycle));
    // then the inline accessors agree with the epoch the library wrote:
    ASSERT_EQ(rig.loop->mode(), e.mode);
    ASSERT_EQ(rig.loop->cal_id(), e.cal_id);
    ASSERT_EQ(rig.loop->calibrated(), (e.status_bits & status_bits::kNominalCalibration) == 0);
    ASSERT_EQ(rig.loop->capture_active(), (e.status_bits & status_bits::kCaptureActive) != 0);
    const HealthCounters& h = rig.loop->health();
    ASSERT_EQ(h.missed_edges, e.health.missed_drdy_edges);
    ASSERT_EQ(h.crc_errors, e.health.adc_crc_errors);
    ASSERT_EQ(h.saturated_samples, e.health.saturated_samples);
    ASSERT_EQ(h.log_dropped, e.health.log_dropped);
    ASSERT_EQ(h.stuck_mask, e.health.stuck_channel_mask);
    // the sample counter is the number of samples the tap saw the loop read,
    ASSERT_EQ(h.samples, rig.tap->samples().size());
    // and the navigation state read through pipeline() is the one the epoch copied, bit for bit
    // (the epoch only replaces t_ns, seq and status by the sample's).
    const nav::NavState<float>& s = rig.loop->pipeline().state();
    ASSERT_EQ(s.q_nb.coeffs(), e.nav.q_nb.coeffs());
    ASSERT_EQ(s.w_b, e.nav.w_b);
    ASSERT_EQ(s.v_n, e.nav.v_n);
    ASSERT_EQ(s.r_n, e.nav.r_n);
    navigated = navigated || e.mode == can::Mode::kNavigating;
  }
  // The run reached navigation (the rest scenario has no fault), so both modes were compared.
  EXPECT_TRUE(navigated);
  EXPECT_EQ(rig.loop->mode(), can::Mode::kNavigating);
}

}  // namespace
}  // namespace gfins::app
