#include "gfins/drivers/lnx/gpiod_data_ready.hpp"

#include "gfins/drivers/lnx/os.hpp"

#include <gpiod.h>
#include <time.h>

#include <cerrno>
#include <limits>

namespace gfins::drivers::lnx {

gpiod_chip* GpiodApi::chip_open_lookup(const char* descr) {
  return ::gpiod_chip_open_lookup(descr);
}
void GpiodApi::chip_close(gpiod_chip* chip) { ::gpiod_chip_close(chip); }
gpiod_line* GpiodApi::chip_get_line(gpiod_chip* chip, unsigned offset) {
  return ::gpiod_chip_get_line(chip, offset);
}
gpiod_line* GpiodApi::chip_find_line(gpiod_chip* chip, const char* name) {
  return ::gpiod_chip_find_line(chip, name);
}
int GpiodApi::line_request_rising_edge_events(gpiod_line* line, const char* consumer) {
  return ::gpiod_line_request_rising_edge_events(line, consumer);
}
int GpiodApi::line_request_falling_edge_events(gpiod_line* line, const char* consumer) {
  return ::gpiod_line_request_falling_edge_events(line, consumer);
}
void GpiodApi::line_release(gpiod_line* line) { ::gpiod_line_release(line); }
std::int64_t GpiodApi::monotonic_now_ns() { return monotonic_ns(real_os()); }
int GpiodApi::line_event_wait(gpiod_line* line, const timespec* timeout) {
  return ::gpiod_line_event_wait(line, timeout);
}
int GpiodApi::line_event_read_multiple(gpiod_line* line, gpiod_line_event* events, unsigned n) {
  return ::gpiod_line_event_read_multiple(line, events, n);
}
GpiodApi& real_gpiod() {
  static GpiodApi api;
  return api;
}

std::uint32_t inferred_sequence_step(std::int64_t dt_ns, std::int64_t period_ns) {
  if (dt_ns <= period_ns / 2) return 1;  // early: a glitch or a double edge, not a gap
  // round(dt / P) in integers; dt > 0 and P > 0 here.
  const std::int64_t k = (dt_ns + period_ns / 2) / period_ns;
  constexpr std::int64_t kMax = std::numeric_limits<std::uint32_t>::max();
  return static_cast<std::uint32_t>(k > kMax ? kMax : k);
}

Result<std::unique_ptr<GpiodDataReady>> GpiodDataReady::open(const GpiodDataReadyConfig& config,
                                                             GpiodApi& api) {
  if (config.line_offset < 0 && config.line_name.empty()) {
    return Status(ErrorCode::kInvalidArgument, "gpiod: give a line offset or a line name");
  }
  if (config.nominal_period_ns <= 0) {
    return Status(ErrorCode::kInvalidArgument, "gpiod: nominal period must be > 0");
  }
  gpiod_chip* chip = api.chip_open_lookup(config.chip.c_str());
  if (chip == nullptr) {
    return Status(ErrorCode::kUnavailable, "gpiod: cannot open the GPIO chip", errno);
  }
  gpiod_line* line = config.line_offset >= 0
                         ? api.chip_get_line(chip, static_cast<unsigned>(config.line_offset))
                         : api.chip_find_line(chip, config.line_name.c_str());
  if (line == nullptr) {
    const int err = errno;
    api.chip_close(chip);
    return Status(ErrorCode::kUnavailable,
                  config.line_offset >= 0 ? "gpiod: no line at this offset on the chip"
                                          : "gpiod: no line of this name on the chip",
                  err);
  }
  const bool falling = config.edge == DataReadyEdgeKind::kFalling;
  const int requested = falling
                            ? api.line_request_falling_edge_events(line, config.consumer.c_str())
                            : api.line_request_rising_edge_events(line, config.consumer.c_str());
  if (requested < 0) {
    const int err = errno;
    api.chip_close(chip);
    return Status(ErrorCode::kIoError,
                  err == EBUSY ? "gpiod: line already requested by another consumer"
                  : falling    ? "gpiod: requesting falling-edge events failed"
                               : "gpiod: requesting rising-edge events failed",
                  err);
  }
  std::unique_ptr<GpiodDataReady> d(new GpiodDataReady(api, chip, line, config.nominal_period_ns));
  return d;
}

GpiodDataReady::GpiodDataReady(GpiodApi& api, gpiod_chip* chip, gpiod_line* line,
                               std::int64_t period_ns)
    : api_(api),
      chip_(chip),
      line_(line),
      period_ns_(period_ns),
      events_(new gpiod_line_event[kEventBufferSize]()) {}

GpiodDataReady::~GpiodDataReady() {
  api_.line_release(line_);
  api_.chip_close(chip_);
}

hal::DataReadyEdge GpiodDataReady::next_buffered() {
  const gpiod_line_event& e = events_[next_++];
  const std::int64_t t_ns =
      static_cast<std::int64_t>(e.ts.tv_sec) * 1000000000 + static_cast<std::int64_t>(e.ts.tv_nsec);
  if (have_previous_) {
    const std::uint32_t step = inferred_sequence_step(t_ns - previous_t_ns_, period_ns_);
    if (t_ns - previous_t_ns_ <= period_ns_ / 2) ++counters_.early_edges;
    counters_.missed_edges += step - 1;
    seq_ += step;
  }
  have_previous_ = true;
  previous_t_ns_ = t_ns;
  ++counters_.edges;
  return hal::DataReadyEdge{t_ns, seq_};
}

Result<hal::DataReadyEdge> GpiodDataReady::do_wait_edge(std::int64_t timeout_ns) {
  if (next_ < buffered_) return next_buffered();
  // A signal handled by the process (SIGTERM asking the firmware to stop) ends the kernel's wait
  // with EINTR: not a fault of the line. Wait again for what is left of the timeout (signal(7):
  // poll-style waits are never restarted, SA_RESTART or not); the caller sees its stop flag after
  // this edge or timeout, at most the timeout later.
  const std::int64_t deadline_ns = api_.monotonic_now_ns() + timeout_ns;
  std::int64_t left_ns = timeout_ns;
  int w = 0;
  for (;;) {
    timespec timeout{};
    timeout.tv_sec = static_cast<time_t>(left_ns / 1000000000);
    timeout.tv_nsec = static_cast<long>(left_ns % 1000000000);
    w = api_.line_event_wait(line_, &timeout);
    if (w >= 0 || errno != EINTR) break;
    ++counters_.interrupted_waits;
    left_ns = deadline_ns - api_.monotonic_now_ns();
    if (left_ns <= 0) {
      w = 0;
      break;
    }
  }
  if (w < 0) {
    return Status(ErrorCode::kIoError, "gpiod: waiting for a data-ready edge failed", errno);
  }
  if (w == 0) return Status(ErrorCode::kTimeout, "gpiod: no data-ready edge before the timeout");
  const int n = api_.line_event_read_multiple(line_, events_.get(), kEventBufferSize);
  if (n < 0) return Status(ErrorCode::kIoError, "gpiod: reading edge events failed", errno);
  if (n == 0) return Status(ErrorCode::kTimeout, "gpiod: woken without an event");
  buffered_ = static_cast<unsigned>(n);
  next_ = 0;
  if (buffered_ == kEventBufferSize) ++counters_.full_reads;
  return next_buffered();
}

}  // namespace gfins::drivers::lnx
