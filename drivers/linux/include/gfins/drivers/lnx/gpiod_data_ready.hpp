// hal::DataReadyLine on a GPIO line through libgpiod 1.6 (the v1 character-device uAPI).
//
// The line is found by chip ("gpiochip0", "/dev/gpiochip0", a number or a label, as
// gpiod_chip_open_lookup accepts) and either an offset or a line name, then requested for
// events of the edge that marks a new conversion: the falling one by default, because the
// ADS131M06's DRDY is an active-low output whose high-to-low transition says new data are ready
// and whose falling edges are one data-rate period apart (ADS131M06 datasheet, DRDY pin
// description, §8.5.1 "SPI interface", DRDY). wait_edge() waits with gpiod_line_event_wait and
// reads every queued event at once with gpiod_line_event_read_multiple into a buffer allocated once
// at open() and reused forever; the events are then handed out one per call, so a burst queued
// during a stall is counted, not lost.
//
// Timestamps: the kernel stamps each edge in its interrupt handler; since Linux 5.7 the v1 uAPI
// uses CLOCK_MONOTONIC (gpio-cdev "lineevent_irq_handler": ktime_get_ns), the clock of
// MonotonicClock, so edge times and loop times compare directly.
//
// Sequence numbers: v1 events carry none (the v2 uAPI's line_seqno is not reachable through
// libgpiod 1.6). The sequence is therefore inferred from the spacing of the kernel timestamps
// against the nominal period P: an edge dt after the previous one advances the sequence by
// k = round(dt / P) (at least 1), and k - 1 edges are counted as missed. This detects edges the
// kernel dropped (its event FIFO holds 16) and edges the ADC never produced, provided the ADC's
// clock is within ±50 % of nominal over one interval; an edge closer than P/2 to the previous
// one (a glitch, a double edge) advances the sequence by 1 and is counted as early.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "gfins/hal/data_ready.hpp"
#include "gfins/status/status.hpp"

struct gpiod_chip;
struct gpiod_line;
struct gpiod_line_event;  // NOLINT(readability-identifier-naming): libgpiod's
struct timespec;          // NOLINT(readability-identifier-naming): <time.h>'s

namespace gfins::drivers::lnx {

/// The libgpiod 1.6 calls the backend makes (real_gpiod() forwards to the library; tests fake).
class GpiodApi {
 public:
  virtual ~GpiodApi() = default;
  virtual gpiod_chip* chip_open_lookup(const char* descr);
  virtual void chip_close(gpiod_chip* chip);
  virtual gpiod_line* chip_get_line(gpiod_chip* chip, unsigned offset);
  virtual gpiod_line* chip_find_line(gpiod_chip* chip, const char* name);
  virtual int line_request_rising_edge_events(gpiod_line* line, const char* consumer);
  virtual int line_request_falling_edge_events(gpiod_line* line, const char* consumer);
  virtual void line_release(gpiod_line* line);
  virtual int line_event_wait(gpiod_line* line, const timespec* timeout);
  virtual int line_event_read_multiple(gpiod_line* line, gpiod_line_event* events, unsigned n);
  /// CLOCK_MONOTONIC in ns: what is left of a wait that a signal interrupted.
  virtual std::int64_t monotonic_now_ns();
};
GpiodApi& real_gpiod();

/// Which transition of the line is the data-ready event.
enum class DataReadyEdgeKind : std::uint8_t {
  kFalling,  // ADS131M06 DRDY (active low): high-to-low = new data
  kRising,   // an inverted wiring (e.g. through an inverting level shifter)
};

struct GpiodDataReadyConfig {
  std::string chip = "gpiochip0";  // anything gpiod_chip_open_lookup accepts
  int line_offset = -1;            // offset on the chip, or -1 to look the line up by name
  std::string line_name;           // used when line_offset < 0 (e.g. "ADC_DRDY")
  std::string consumer = "gfins-drdy";
  std::int64_t nominal_period_ns = 1000000;  // 1 kHz sample clock
  DataReadyEdgeKind edge = DataReadyEdgeKind::kFalling;
};

/// Counters only grow.
struct DataReadyCounters {
  std::uint32_t edges = 0;              // data-ready edges read from the kernel
  std::uint32_t missed_edges = 0;       // inferred from timestamp gaps (see the file comment)
  std::uint32_t early_edges = 0;        // closer than half a period to the previous one
  std::uint32_t full_reads = 0;         // reads that filled the whole buffer (more may have waited)
  std::uint32_t interrupted_waits = 0;  // waits a signal ended (EINTR), resumed for the time left
};

class GpiodDataReady final : public hal::DataReadyLine {
 public:
  /// Events read per gpiod_line_event_read_multiple call; the kernel's v1 FIFO holds 16.
  static constexpr unsigned kEventBufferSize = 16;

  /// Opens the chip, finds the line, requests events of config.edge. Errors (os_error() = errno):
  /// kInvalidArgument (no offset and no name, non-positive period); kUnavailable (no such chip,
  /// no such line offset or name); kIoError (the request failed, e.g. EBUSY: line in use).
  static Result<std::unique_ptr<GpiodDataReady>> open(const GpiodDataReadyConfig& config,
                                                      GpiodApi& api = real_gpiod());

  ~GpiodDataReady() override;
  GpiodDataReady(const GpiodDataReady&) = delete;
  GpiodDataReady& operator=(const GpiodDataReady&) = delete;

  const DataReadyCounters& counters() const { return counters_; }

 private:
  GpiodDataReady(GpiodApi& api, gpiod_chip* chip, gpiod_line* line, std::int64_t period_ns);
  Result<hal::DataReadyEdge> do_wait_edge(std::int64_t timeout_ns) override;
  hal::DataReadyEdge next_buffered();

  GpiodApi& api_;
  gpiod_chip* chip_;
  gpiod_line* line_;
  std::int64_t period_ns_;
  std::unique_ptr<gpiod_line_event[]> events_;  // kEventBufferSize, allocated once at open()
  unsigned buffered_ = 0;                       // events read from the kernel
  unsigned next_ = 0;                           // next one to hand out
  bool have_previous_ = false;
  std::int64_t previous_t_ns_ = 0;
  std::uint32_t seq_ = 0;
  DataReadyCounters counters_;
};

/// The sequence advance for an edge `dt_ns` after the previous one at nominal period
/// `period_ns`: round(dt / P), at least 1 (see the file comment). Public for its tests.
std::uint32_t inferred_sequence_step(std::int64_t dt_ns, std::int64_t period_ns);

}  // namespace gfins::drivers::lnx
