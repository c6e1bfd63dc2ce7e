// Zero heap allocations in the firmware's sample loop after start-up: many thousand cycles of the
// simulated board (reading frames, navigating, publishing, servicing the CAN bus, polling for
// commands, logging events, detecting faults) with every malloc-family call of the process
// counted. The loop's logger thread is not running during the window (it allocates by design:
// formatting happens there); the queue it drains is what the loop writes to. The raw-sample
// recorder's writer is counted too: it writes what the loop queues without allocating.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "gfins/app/recorder.hpp"

#include "sim_rig.hpp"
#include "support/heap_counter.hpp"

namespace gfins::app {
namespace {

using testing::HeapCounter;
using testing::SimRig;

// Cycles counted (printed by the test): 20 s at 1 kHz after alignment — long enough for every
// periodic path (event bits expiring after kEventHoldSamples, rate-limited log records, the stuck
// detector's window).
constexpr std::uint32_t kCountedCycles = 20000;
constexpr std::uint32_t kWarmUpCycles = 1500;  // alignment (1000 samples) plus margin
constexpr std::uint32_t kDeadCycles = 1000;    // 1 s of a dead ADC: every path of an outage

TEST(NoAlloc, TheDetectorSeesOperatorNewAndMalloc) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  const long before = HeapCounter::calls();
  auto* p = new int(3);
  void* q = std::malloc(16);
  const long after = HeapCounter::calls();
  delete p;
  std::free(q);
  EXPECT_GE(after - before, 2);
}

TEST(NoAlloc, SampleLoopAllocatesNothingAfterStartUp) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  // Given a started board with faults scheduled inside the counted window, so their paths run
  sim_board::FaultPlan f;
  f.crc_error_at = {3000, 9000};
  f.missing_edges = {4000, 4001};
  f.extra_edge_after = {5000};
  f.reset_at = 6000;
  f.stuck_channel = 1;
  f.stuck_from = 7000;
  f.stuck_until = 7200;
  f.saturated_channel = 3;
  f.saturated_from = 8000;
  f.saturated_until = 8050;
  f.silent_from = 10000;
  f.silent_edges = 6;
  SimRig rig("rest", (kWarmUpCycles + kCountedCycles + 100) / 1000.0, f, 4096);
  app::StatusBoard status_board;  // as gfins-fw wires it: the service status published per cycle
  rig.loop->set_status_board(&status_board);
  rig.configure();
  rig.run_cycles(kWarmUpCycles);
  ASSERT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  // When many thousand cycles run, with the CAN sink refusing and going bus-off in between, ADC
  // reads failing (the no-sample epochs and the paced retry) and the ADC dead for a while.
  // The window, phase by phase; the phases add up to kCountedCycles (docs/firmware.md quotes it).
  constexpr std::uint32_t kToFaultsEnd = 11000 - kWarmUpCycles;  // faults at samples 3000..10006
  constexpr std::uint32_t kRefusing = 500;
  constexpr std::uint32_t kBusOff = 500;
  constexpr std::uint32_t kAfter =
      kCountedCycles - kToFaultsEnd - kRefusing - kBusOff - kDeadCycles;
  static_assert(kToFaultsEnd + kRefusing + kBusOff + kAfter + kDeadCycles == kCountedCycles);
  std::uint32_t cycles = 0;
  const auto run = [&](std::uint32_t n) {  // counts the cycles that really ran
    for (std::uint32_t i = 0; i < n && !rig.source->finished(); ++i, ++cycles) rig.loop->step();
  };
  const long before = HeapCounter::calls();
  run(kToFaultsEnd);
  rig.bus->refuse(true);
  run(kRefusing);
  rig.bus->refuse(false);
  rig.bus->bus_off(true);
  run(kBusOff);
  rig.bus->bus_off(false);
  rig.faulty->fail_reads(3);  // three SPI errors at the start of this phase
  run(kAfter);
  rig.faulty->set_dead(true);  // reads fail at once: the paced no-sample cycles
  run(kDeadCycles);
  rig.faulty->set_dead(false);
  const long after = HeapCounter::calls();
  std::printf("[ counted  ] %u sample-loop cycles after start-up, %ld heap calls\n", cycles,
              after - before);
  EXPECT_EQ(cycles, kCountedCycles);
  // Then the faults happened (the window exercised their paths) and nothing was allocated
  EXPECT_GT(rig.loop->health().crc_errors, 0u);
  EXPECT_GT(rig.loop->health().stuck_events, 0u);
  EXPECT_GT(rig.loop->health().drdy_timeouts, 0u);
  EXPECT_GT(rig.loop->health().can_tx_dropped, 0u);
  EXPECT_EQ(rig.loop->health().adc_read_errors, 3u + kDeadCycles);
  EXPECT_GE(rig.loop->health().samples, kCountedCycles - kDeadCycles);
  EXPECT_EQ(after - before, 0) << "heap calls inside the sample loop";
}

TEST(NoAlloc, RecordingAllocatesNothingInTheLoopOrItsWriter) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  // Given a started board recording to a file (record.file), the writer's block buffer and the
  // file's stdio buffer in place (the header is written at open),
  SimRig rig("rest", (kWarmUpCycles + kCountedCycles + 100) / 1000.0);
  rig.configure();
  const std::string path =
      (std::filesystem::temp_directory_path() / "gfins_no_alloc_recording.gfr").string();
  Recorder::Opened opened = Recorder::open(path, testing::recording_header(rig));
  ASSERT_TRUE(opened.recorder) << opened.error;
  rig.loop->set_recorder(&opened.recorder->queue());
  rig.run_cycles(kWarmUpCycles);
  opened.recorder->drain();
  // when the loop records many thousand cycles and the writer's work (drain: blocks, CRCs,
  // writes) runs between them, as its thread would,
  const long before = HeapCounter::calls();
  for (std::uint32_t done = 0; done < kCountedCycles; done += 1000) {
    rig.run_cycles(1000);
    opened.recorder->drain();
  }
  const long after = HeapCounter::calls();
  // then every sample was recorded and nothing was allocated on either side.
  EXPECT_EQ(rig.loop->health().record_dropped, 0u);
  EXPECT_EQ(after - before, 0) << "heap calls while recording";
  EXPECT_EQ(opened.recorder->stop(), "");
  EXPECT_EQ(opened.recorder->records_written(), rig.loop->health().samples);
  std::filesystem::remove(path);
}

TEST(NoAlloc, TheLoopWithAidingAllocatesNothingWithFixesArriving) {
  if (!HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  // Given a started board with aiding on (the filter's propagation, standstill updates at rest:
  // the QA-1100 model, whose noise the aiding's detector is configured for),
  SimRig rig("rest-qa1100", (kWarmUpCycles + kCountedCycles + 100) / 1000.0);
  rig.config.aiding = true;
  rig.cal = load_calibration(rig.config, rig.factory, &rig.factory).set;
  rig.configure();
  rig.run_cycles(kWarmUpCycles);
  ASSERT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  // when GNSS fixes (5 Hz: the board's true position and velocity at rest, zero) and an external
  // heading (1 Hz, the one it was given) arrive as input frames over many thousand cycles,
  can::GnssFix fix = testing::gnss_fix_at_rest(0);
  can::HeadingFix heading;
  heading.sigma_rad = 0.01;
  heading.age_s = 0.01;
  const long before = HeapCounter::calls();
  for (std::uint32_t done = 0; done < kCountedCycles; done += 200) {
    fix.fix_id = static_cast<std::uint8_t>(fix.fix_id + 1);
    for (const hal::CanFrame& f : can::encode_gnss_fix(fix, SimRig::kNode)) {
      ASSERT_TRUE(rig.bus->inject_rx(f));
    }
    if (done % 1000 == 0) {
      heading.sequence = static_cast<std::uint8_t>(heading.sequence + 1);
      ASSERT_TRUE(rig.bus->inject_rx(can::encode_heading_fix(heading, SimRig::kNode)));
    }
    rig.run_cycles(200);
  }
  const long after = HeapCounter::calls();
  // then every kind of update ran and nothing was allocated.
  const auto& c = rig.loop->pipeline().aiding().filter().counters();
  const auto accepted = [&c](nav::AidingKind k) { return c.accepted[static_cast<std::size_t>(k)]; };
  EXPECT_GT(accepted(nav::AidingKind::kZupt), 0u);
  EXPECT_GT(accepted(nav::AidingKind::kZaru), 0u);
  EXPECT_EQ(accepted(nav::AidingKind::kGnssPosition), kCountedCycles / 200);
  EXPECT_EQ(accepted(nav::AidingKind::kGnssVelocity), kCountedCycles / 200);
  EXPECT_EQ(accepted(nav::AidingKind::kHeading), kCountedCycles / 1000);
  EXPECT_EQ(after - before, 0) << "heap calls in the aided loop";
}

}  // namespace
}  // namespace gfins::app
