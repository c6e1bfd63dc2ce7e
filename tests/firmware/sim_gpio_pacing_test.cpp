// The simulated board paced by a real data-ready line (sim.pacing = "gpio"): SimSampleSource over
// lnx::GpiodDataReady over a fake libgpiod (the backend's kernel seam, GpiodApi). The fake hands
// out falling-edge events with kernel timestamps written here; the oracle for the codes is the
// same scenario converted at the same conversion indices by the index-paced (fast) source, and
// for seq / t_ns / missed edges the timestamps and gaps this test writes.
#include <gpiod.h>
#include <gtest/gtest.h>

#include <cerrno>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "gfins/drivers/lnx/gpiod_data_ready.hpp"
#include "gfins/host_sim/board/sim_board.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins {
namespace {

namespace lnx = drivers::lnx;

// Fake handles: never dereferenced by the backend, only passed back to the API.
gpiod_chip* const kChip = reinterpret_cast<gpiod_chip*>(0x1000);
gpiod_line* const kLine = reinterpret_cast<gpiod_line*>(0x2000);

/// libgpiod 1.6 as the kernel would answer: one read per queued batch of edge times.
class FakeKernelGpio final : public lnx::GpiodApi {
 public:
  gpiod_chip* chip_open_lookup(const char*) override { return kChip; }
  void chip_close(gpiod_chip*) override {}
  gpiod_line* chip_get_line(gpiod_chip*, unsigned) override { return kLine; }
  gpiod_line* chip_find_line(gpiod_chip*, const char* name) override {
    line_name = name;
    return kLine;
  }
  int line_request_rising_edge_events(gpiod_line*, const char*) override {
    requested = "rising";
    return 0;
  }
  int line_request_falling_edge_events(gpiod_line*, const char*) override {
    requested = "falling";
    return 0;
  }
  void line_release(gpiod_line*) override {}
  int line_event_wait(gpiod_line*, const timespec* t) override {
    last_timeout_ns = static_cast<std::int64_t>(t->tv_sec) * 1000000000 + t->tv_nsec;
    return batches.empty() ? 0 : 1;
  }
  int line_event_read_multiple(gpiod_line*, gpiod_line_event* ev, unsigned n) override {
    const std::vector<std::int64_t> batch = batches.front();
    batches.pop_front();
    unsigned i = 0;
    for (; i < batch.size() && i < n; ++i) {
      ev[i].ts.tv_sec = static_cast<time_t>(batch[i] / 1000000000);
      ev[i].ts.tv_nsec = static_cast<long>(batch[i] % 1000000000);
      ev[i].event_type = GPIOD_LINE_EVENT_FALLING_EDGE;
    }
    return static_cast<int>(i);
  }

  std::string requested, line_name;
  std::int64_t last_timeout_ns = -1;
  std::deque<std::vector<std::int64_t>> batches;
};

constexpr double kRateHz = 1000.0;           // the "rest" scenario's rate (host_sim/scenarios)
constexpr std::int64_t kPeriodNs = 1000000;  // 1 / kRateHz
constexpr std::int64_t kT0Ns = 5000000000;   // an arbitrary CLOCK_MONOTONIC time of the 1st edge
// Kernel timestamps jitter around the nominal period; 20 % of a period still rounds to the
// right sequence step (GpiodDataReady infers steps by rounding dt / P).
constexpr std::int64_t kJitterNs = kPeriodNs / 5;

struct Rig {
  Rig() {
    const auto p = sim::load_scenario("rest", GFINS_SCENARIO_DIR);
    if (!p.is_ok()) throw std::runtime_error(p.error().message);
    scenario = p.value();
  }
  sim::Scenario scenario;
};

/// The codes of conversions 0..n-1 of the scenario, index-paced (the fast board's path).
std::vector<RawSample> reference_samples(const sim::Scenario& s, std::uint32_t n) {
  auto made = sim_board::make_scenario_stream(s);
  EXPECT_TRUE(made.is_ok()) << made.error().message;
  if (!made.is_ok()) return {};
  auto stream = std::move(made).value();
  sim_board::ChipAdc adc(s.rate_hz);
  EXPECT_TRUE(adc.start().is_ok());
  app::SampleClock clock;
  sim_board::SimSampleSource src(*stream, adc, clock, &clock, sim_board::Pacing::kFast, s.rate_hz,
                                 n);
  std::vector<RawSample> out;
  for (std::uint32_t i = 0; i < n; ++i) out.push_back(src.read_sample(kPeriodNs).value());
  return out;
}

TEST(SimGpioPacing, EachConversionTakesItsEdgesKernelTimeAndSequenceAndMissedEdgesAreCounted) {
  Rig rig;
  ASSERT_EQ(rig.scenario.rate_hz, kRateHz);
  FakeKernelGpio kernel;
  lnx::GpiodDataReadyConfig dc;
  dc.line_name = "adc-drdy";
  dc.nominal_period_ns = kPeriodNs;
  auto line = lnx::GpiodDataReady::open(dc, kernel);
  ASSERT_TRUE(line.is_ok()) << line.status().message();
  // The ADS131M06's DRDY is active low: new data on the falling edge (datasheet, DRDY pin).
  EXPECT_EQ(kernel.requested, "falling");

  // Edges of conversions 0, 1, 2, then 3 lost (the next edge two periods later), 4, 5; the
  // second batch arrives at once, as the kernel queues them while the reader is busy.
  const std::vector<std::int64_t> t = {kT0Ns, kT0Ns + kPeriodNs + kJitterNs,
                                       kT0Ns + 2 * kPeriodNs - kJitterNs, kT0Ns + 4 * kPeriodNs,
                                       kT0Ns + 5 * kPeriodNs + kJitterNs};
  kernel.batches = {{t[0]}, {t[1], t[2]}, {t[3], t[4]}};
  const std::vector<std::uint32_t> expected_seq = {0, 1, 2, 4, 5};

  auto made = sim_board::make_scenario_stream(rig.scenario);
  ASSERT_TRUE(made.is_ok()) << made.error().message;
  auto stream = std::move(made).value();
  sim_board::ChipAdc adc(rig.scenario.rate_hz);
  ASSERT_TRUE(adc.start().is_ok());
  sim_board::SteadyClock clock;
  constexpr std::uint32_t kSamples = 100;
  sim_board::SimSampleSource src(*stream, adc, clock, *line.value(), kSamples);

  const std::vector<RawSample> ref = reference_samples(rig.scenario, 6);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const Result<RawSample> r = src.read_sample(3 * kPeriodNs);
    ASSERT_TRUE(r.is_ok()) << i << ": " << r.status().message();
    EXPECT_EQ(r.value().seq, expected_seq[i]) << i;
    EXPECT_EQ(r.value().t_ns, t[i]) << i;  // the kernel's timestamp, untouched
    EXPECT_EQ(r.value().counts, ref[expected_seq[i]].counts) << "conversion " << expected_seq[i];
  }
  // The edge of conversion 3 is missing: counted once by the line (timestamp gap) and once by
  // the ADC driver from the sequence gap (the counter the health frame reports, as on the board).
  EXPECT_EQ(line.value()->counters().missed_edges, 1u);
  EXPECT_EQ(src.counters().missed_edges, 1u);
  EXPECT_EQ(src.counters().crc_errors, 0u);

  // A silent line: the loop's timeout goes to the kernel and comes back as a timeout.
  const Result<RawSample> quiet = src.read_sample(7 * kPeriodNs);
  EXPECT_EQ(quiet.status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(kernel.last_timeout_ns, 7 * kPeriodNs);
  EXPECT_FALSE(src.finished());
}

TEST(SimGpioPacing, TheRunEndsAfterItsSamplesEvenWhenEdgesWereMissed) {
  Rig rig;
  FakeKernelGpio kernel;
  lnx::GpiodDataReadyConfig dc;
  dc.line_offset = 0;
  dc.nominal_period_ns = kPeriodNs;
  auto line = lnx::GpiodDataReady::open(dc, kernel);
  ASSERT_TRUE(line.is_ok());
  auto made = sim_board::make_scenario_stream(rig.scenario);
  ASSERT_TRUE(made.is_ok()) << made.error().message;
  auto stream = std::move(made).value();
  sim_board::ChipAdc adc(rig.scenario.rate_hz);
  ASSERT_TRUE(adc.start().is_ok());
  sim_board::SteadyClock clock;
  // Three conversions in the run; edges of conversions 0 and 3: the second edge is past the end.
  sim_board::SimSampleSource src(*stream, adc, clock, *line.value(), 3);
  kernel.batches = {{kT0Ns}, {kT0Ns + 3 * kPeriodNs}};
  ASSERT_TRUE(src.read_sample(kPeriodNs).is_ok());
  EXPECT_FALSE(src.finished());
  const Result<RawSample> r = src.read_sample(kPeriodNs);
  EXPECT_EQ(r.status().code(), ErrorCode::kUnavailable);
  EXPECT_TRUE(src.finished());
}

}  // namespace
}  // namespace gfins
