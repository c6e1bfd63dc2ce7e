// GpiodDataReady against a fake libgpiod: line lookup, the edge request
// (falling by default: the ADS131M06's DRDY is active low), timeouts, the
// one preallocated event buffer, bursts read at once, and the sequence numbers inferred from
// kernel timestamps; plus the real library's answer for a chip that does not exist.
#include "gfins/drivers/lnx/gpiod_data_ready.hpp"

#include <gmock/gmock.h>
#include <gpiod.h>
#include <gtest/gtest.h>

#include <cerrno>
#include <deque>
#include <string>
#include <vector>

#include "gfins/drivers/lnx/error_text.hpp"

namespace gfins::drivers::lnx {
namespace {

using ::testing::HasSubstr;

constexpr std::int64_t kPeriodNs = 1000000;  // 1 kHz, the configuration's default

// Fake handles: never dereferenced by the backend, only passed back to the API.
gpiod_chip* const kChip = reinterpret_cast<gpiod_chip*>(0x1000);
gpiod_line* const kLine = reinterpret_cast<gpiod_line*>(0x2000);

class FakeGpiod : public GpiodApi {
 public:
  gpiod_chip* chip_open_lookup(const char* descr) override {
    opened = descr;
    if (!chip_exists) {
      errno = ENOENT;
      return nullptr;
    }
    return kChip;
  }
  void chip_close(gpiod_chip*) override { ++chip_closes; }
  gpiod_line* chip_get_line(gpiod_chip*, unsigned offset) override {
    got_offset = static_cast<int>(offset);
    if (offset >= num_lines) {
      errno = EINVAL;
      return nullptr;
    }
    return kLine;
  }
  gpiod_line* chip_find_line(gpiod_chip*, const char* name) override {
    found_name = name;
    if (found_name != "ADC_DRDY") {
      errno = ENOENT;
      return nullptr;
    }
    return kLine;
  }
  int line_request_rising_edge_events(gpiod_line* l, const char* c) override {
    requested_edge = "rising";
    return request(l, c);
  }
  int line_request_falling_edge_events(gpiod_line* l, const char* c) override {
    requested_edge = "falling";
    return request(l, c);
  }
  int request(gpiod_line*, const char* c) {
    consumer = c;
    if (request_errno != 0) {
      errno = request_errno;
      return -1;
    }
    return 0;
  }
  void line_release(gpiod_line*) override { ++releases; }
  int line_event_wait(gpiod_line*, const timespec* t) override {
    ++waits;
    last_timeout = *t;
    timeouts.push_back(*t);
    if (eintr_waits > 0) {  // a signal arrives during the wait, after wait_ns_per_eintr
      --eintr_waits;
      now_ns += wait_ns_per_eintr;
      errno = EINTR;
      return -1;
    }
    if (wait_errno != 0) {
      errno = wait_errno;
      return -1;
    }
    return batches.empty() ? 0 : 1;
  }
  int line_event_read_multiple(gpiod_line*, gpiod_line_event* ev, unsigned n) override {
    buffers.push_back(ev);
    capacities.push_back(n);
    const std::vector<std::int64_t> batch = batches.front();
    batches.pop_front();
    unsigned i = 0;
    for (; i < batch.size() && i < n; ++i) {
      ev[i].ts.tv_sec = static_cast<time_t>(batch[i] / 1000000000);
      ev[i].ts.tv_nsec = static_cast<long>(batch[i] % 1000000000);
      ev[i].event_type =
          requested_edge == "rising" ? GPIOD_LINE_EVENT_RISING_EDGE : GPIOD_LINE_EVENT_FALLING_EDGE;
    }
    return static_cast<int>(i);
  }

  std::int64_t monotonic_now_ns() override { return now_ns; }

  bool chip_exists = true;
  int eintr_waits = 0;                 // how many waits a signal interrupts
  std::int64_t wait_ns_per_eintr = 0;  // time each interrupted wait lasted
  std::int64_t now_ns = 5000000000;    // the fake CLOCK_MONOTONIC
  std::vector<timespec> timeouts;      // every timeout passed to the kernel
  unsigned num_lines = 8;
  int request_errno = 0;
  int wait_errno = 0;
  std::string opened, found_name, consumer, requested_edge;
  int got_offset = -1;
  int chip_closes = 0, releases = 0, waits = 0;
  timespec last_timeout{};
  std::deque<std::vector<std::int64_t>> batches;  // edge times (ns) per kernel read
  std::vector<gpiod_line_event*> buffers;
  std::vector<unsigned> capacities;
};

GpiodDataReadyConfig by_offset(int offset) {
  GpiodDataReadyConfig c;
  c.chip = "gpiochip3";
  c.line_offset = offset;
  c.nominal_period_ns = kPeriodNs;
  return c;
}

TEST(GpiodDataReady, FindsTheLineByOffsetAndRequestsFallingEdgesUnderItsConsumerName) {
  FakeGpiod api;
  auto d = GpiodDataReady::open(by_offset(5), api);
  ASSERT_TRUE(d.is_ok()) << d.status().message();
  EXPECT_EQ(api.opened, "gpiochip3");
  EXPECT_EQ(api.got_offset, 5);
  EXPECT_EQ(api.consumer, "gfins-drdy");
  // ADS131M06 datasheet, DRDY pin: active low, the high-to-low transition marks new data.
  EXPECT_EQ(api.requested_edge, "falling");
  d.value().reset();
  EXPECT_EQ(api.releases, 1);
  EXPECT_EQ(api.chip_closes, 1);
}

TEST(GpiodDataReady, AnInvertedWiringAsksForRisingEdges) {
  FakeGpiod api;
  GpiodDataReadyConfig c = by_offset(2);
  c.edge = DataReadyEdgeKind::kRising;
  ASSERT_TRUE(GpiodDataReady::open(c, api).is_ok());
  EXPECT_EQ(api.requested_edge, "rising");
  api.request_errno = EBUSY;
  c.edge = DataReadyEdgeKind::kFalling;
  auto busy = GpiodDataReady::open(c, api);
  EXPECT_EQ(busy.status().code(), ErrorCode::kIoError);
  EXPECT_EQ(api.requested_edge, "falling");
}

TEST(GpiodDataReady, FindsTheLineByName) {
  FakeGpiod api;
  GpiodDataReadyConfig c;
  c.line_name = "ADC_DRDY";
  ASSERT_TRUE(GpiodDataReady::open(c, api).is_ok());
  EXPECT_EQ(api.found_name, "ADC_DRDY");
  c.line_name = "NO_SUCH_LINE";
  auto missing = GpiodDataReady::open(c, api);
  EXPECT_EQ(missing.status().code(), ErrorCode::kUnavailable);
  EXPECT_THAT(missing.status().message(), HasSubstr("no line of this name"));
}

TEST(GpiodDataReady, EachOpenFailureIsReportedWithErrnoAndReleasesTheChip) {
  FakeGpiod api;
  api.chip_exists = false;
  auto r = GpiodDataReady::open(by_offset(0), api);
  EXPECT_EQ(r.status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(r.status().os_error(), ENOENT);

  FakeGpiod api2;
  auto r2 = GpiodDataReady::open(by_offset(99), api2);
  EXPECT_EQ(r2.status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(api2.chip_closes, 1);

  FakeGpiod api3;
  api3.request_errno = EBUSY;
  auto r3 = GpiodDataReady::open(by_offset(1), api3);
  EXPECT_EQ(r3.status().code(), ErrorCode::kIoError);
  EXPECT_EQ(r3.status().os_error(), EBUSY);
  EXPECT_THAT(r3.status().message(), HasSubstr("already requested"));
  EXPECT_EQ(api3.chip_closes, 1);

  GpiodDataReadyConfig none;
  EXPECT_EQ(GpiodDataReady::open(none, api3).status().code(), ErrorCode::kInvalidArgument);
}

TEST(GpiodDataReady, TheTimeoutIsPassedToTheKernelAndAQuietLineTimesOut) {
  FakeGpiod api;
  auto d = GpiodDataReady::open(by_offset(0), api);
  ASSERT_TRUE(d.is_ok());
  const auto r = d.value()->wait_edge(2500000000);  // 2.5 s
  EXPECT_EQ(r.status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(api.last_timeout.tv_sec, 2);
  EXPECT_EQ(api.last_timeout.tv_nsec, 500000000);
  api.wait_errno = EIO;
  const auto e = d.value()->wait_edge(0);
  EXPECT_EQ(e.status().code(), ErrorCode::kIoError);
  EXPECT_EQ(e.status().os_error(), EIO);
}

TEST(GpiodDataReady, ASignalDuringTheWaitIsNotAnErrorAndTheWaitGoesOnForWhatIsLeft) {
  // Given a 3 ms wait that two signals interrupt after 1 ms each (SIGTERM to the firmware: the
  // kernel returns EINTR, poll-style waits are never restarted), then an edge,
  FakeGpiod api;
  auto d = GpiodDataReady::open(by_offset(0), api);
  ASSERT_TRUE(d.is_ok());
  api.eintr_waits = 2;
  api.wait_ns_per_eintr = 1000000;
  api.batches.push_back({7000000});
  // the edge is returned, no error, and each wait asked the kernel for the time left: 3, 2, 1 ms.
  const auto r = d.value()->wait_edge(3000000);
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  EXPECT_EQ(r.value().t_ns, 7000000);
  ASSERT_EQ(api.timeouts.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(api.timeouts[i].tv_sec, 0);
    EXPECT_EQ(api.timeouts[i].tv_nsec, static_cast<long>(3000000 - 1000000 * i)) << i;
  }
  EXPECT_EQ(d.value()->counters().interrupted_waits, 2u);
  // When the signals take the whole timeout, it is a timeout, not an I/O error.
  api.eintr_waits = 3;
  const auto t = d.value()->wait_edge(3000000);
  EXPECT_EQ(t.status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(api.timeouts.size(), 6u);
}

TEST(GpiodDataReady, ABurstQueuedDuringAStallIsReadAtOnceAndHandedOutEdgeByEdge) {
  FakeGpiod api;
  auto d = GpiodDataReady::open(by_offset(0), api);
  ASSERT_TRUE(d.is_ok());
  // Given five edges queued in the kernel while the loop stalled
  api.batches.push_back(
      {10 * kPeriodNs, 11 * kPeriodNs, 12 * kPeriodNs, 13 * kPeriodNs, 14 * kPeriodNs});
  // When the loop asks five times
  std::vector<std::uint32_t> seqs;
  std::vector<std::int64_t> times;
  for (int i = 0; i < 5; ++i) {
    const auto e = d.value()->wait_edge(kPeriodNs);
    ASSERT_TRUE(e.is_ok()) << i;
    seqs.push_back(e->seq);
    times.push_back(e->t_ns);
  }
  // Then the kernel was waited on and read once, and every edge came out in order, none missed
  EXPECT_EQ(api.waits, 1);
  EXPECT_EQ(seqs, (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(times.front(), 10 * kPeriodNs);
  EXPECT_EQ(times.back(), 14 * kPeriodNs);
  EXPECT_EQ(d.value()->counters().edges, 5u);
  EXPECT_EQ(d.value()->counters().missed_edges, 0u);
  EXPECT_EQ(api.capacities, std::vector<unsigned>{GpiodDataReady::kEventBufferSize});
}

TEST(GpiodDataReady, TheOneEventBufferIsReusedForEveryRead) {
  FakeGpiod api;
  auto d = GpiodDataReady::open(by_offset(0), api);
  ASSERT_TRUE(d.is_ok());
  for (int i = 0; i < 3; ++i) api.batches.push_back({(i + 1) * kPeriodNs});
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(d.value()->wait_edge(kPeriodNs).is_ok());
  ASSERT_EQ(api.buffers.size(), 3u);
  EXPECT_EQ(api.buffers[0], api.buffers[1]);
  EXPECT_EQ(api.buffers[1], api.buffers[2]);
}

TEST(GpiodDataReady, GapsInTheKernelTimestampsAdvanceTheSequenceAndCountMissedEdges) {
  FakeGpiod api;
  auto d = GpiodDataReady::open(by_offset(0), api);
  ASSERT_TRUE(d.is_ok());
  // Edges at 0, 1, 2 periods; then 5 (two lost: 3 and 4); then a glitch 0.2 period later;
  // then at 7.3 periods: 2.1 periods after the glitch rounds to 2, so one edge was lost.
  api.batches.push_back({0, kPeriodNs, 2 * kPeriodNs});
  api.batches.push_back({5 * kPeriodNs, 5 * kPeriodNs + kPeriodNs / 5});
  api.batches.push_back({7 * kPeriodNs + 3 * kPeriodNs / 10});
  std::vector<std::uint32_t> seqs;
  for (int i = 0; i < 6; ++i) {
    const auto e = d.value()->wait_edge(kPeriodNs);
    ASSERT_TRUE(e.is_ok()) << i;
    seqs.push_back(e->seq);
  }
  EXPECT_EQ(seqs, (std::vector<std::uint32_t>{0, 1, 2, 5, 6, 8}));
  EXPECT_EQ(d.value()->counters().missed_edges, 3u);
  EXPECT_EQ(d.value()->counters().early_edges, 1u);
  EXPECT_EQ(d.value()->counters().edges, 6u);
}

TEST(InferredSequenceStep, RoundsTheSpacingToWholePeriodsAndNeverStandsStill) {
  // Boundaries of round(dt / P): half a period either side of each multiple.
  EXPECT_EQ(inferred_sequence_step(kPeriodNs, kPeriodNs), 1u);
  EXPECT_EQ(inferred_sequence_step(kPeriodNs * 149 / 100, kPeriodNs), 1u);
  EXPECT_EQ(inferred_sequence_step(kPeriodNs * 151 / 100, kPeriodNs), 2u);
  EXPECT_EQ(inferred_sequence_step(3 * kPeriodNs, kPeriodNs), 3u);
  EXPECT_EQ(inferred_sequence_step(kPeriodNs / 3, kPeriodNs), 1u);  // early edge
  EXPECT_EQ(inferred_sequence_step(0, kPeriodNs), 1u);              // same timestamp twice
}

TEST(GpiodDataReadyRealLibrary, AChipThatDoesNotExistIsUnavailableWithAReadableMessage) {
  GpiodDataReadyConfig c;
  c.chip = "/dev/gpiochip-gfins-none";
  c.line_offset = 0;
  auto d = GpiodDataReady::open(c);
  ASSERT_FALSE(d.is_ok());
  EXPECT_EQ(d.status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(d.status().os_error(), ENOENT);
  EXPECT_EQ(describe(c.chip, d.status()),
            "/dev/gpiochip-gfins-none: gpiod: cannot open the GPIO chip: No such file or "
            "directory (errno 2)");
}

}  // namespace
}  // namespace gfins::drivers::lnx
