#include "gfins/app/service_status.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>

namespace gfins::app {
namespace {

// Appends printf-style text at `*len`, cutting it at the end of `out` (NUL kept).
[[gnu::format(printf, 3, 4)]] void append(std::span<char> out, std::size_t* len, const char* fmt,
                                          ...) {
  if (*len + 1 >= out.size()) return;
  std::va_list args;
  va_start(args, fmt);
  const int n = std::vsnprintf(out.data() + *len, out.size() - *len, fmt, args);
  va_end(args);
  if (n < 0) return;
  *len = std::min(out.size() - 1, *len + static_cast<std::size_t>(n));
}

const char* mode_text(can::Mode m, bool degraded) {
  switch (m) {
    case can::Mode::kStartup:
      return "starting (no sample yet)";
    case can::Mode::kAligning:
      return "aligning (keep the board still)";
    case can::Mode::kNavigating:
      return degraded ? "DEGRADED (navigating on a faulty input)" : "navigating";
    case can::Mode::kCalibrating:
      return degraded ? "DEGRADED (navigating on a faulty input), calibration capture running"
                      : "navigating, calibration capture running";
    case can::Mode::kFault:
      return "FAULT (navigation stopped)";
    case can::Mode::kReplay:
      return "replaying";
  }
  return "unknown mode";
}

}  // namespace

std::size_t format_service_status(std::span<char> out, const StatusSnapshot& s, double rate_hz) {
  if (out.empty()) return 0;
  out[0] = '\0';
  std::size_t len = 0;
  append(out, &len, "%s at %.0f Hz, ", mode_text(s.mode, s.degraded), rate_hz);
  if (s.calibrated) {
    append(out, &len, "calibration %08x", static_cast<unsigned>(s.cal_id));
  } else {
    append(out, &len, "UNCALIBRATED (nominal parameters)");
  }
  append(out, &len, "; faults:");
  // The health frame's counters (docs/can-interface.md) plus the two the CAN frames do not
  // carry as counters (data-ready timeouts, CAN frames lost on receive); zeros are left out.
  struct Counter {
    const char* name;
    std::uint32_t value;
  };
  const std::array<Counter, 8> counters = {{{"missed data-ready edges", s.missed_edges},
                                            {"data-ready timeouts", s.drdy_timeouts},
                                            {"ADC CRC errors", s.crc_errors},
                                            {"ADC resets", s.adc_resets},
                                            {"CAN tx dropped", s.can_tx_dropped},
                                            {"CAN rx lost", s.can_rx_dropped},
                                            {"bus-off", s.bus_off_events},
                                            {"loop overruns", s.loop_overruns}}};
  bool any = false;
  for (const Counter& c : counters) {
    if (c.value == 0) continue;
    append(out, &len, "%s %s %u", any ? "," : "", c.name, static_cast<unsigned>(c.value));
    any = true;
  }
  if (s.stuck_mask != 0) {
    append(out, &len, "%s stuck channels 0x%02x", any ? "," : "",
           static_cast<unsigned>(s.stuck_mask));
    any = true;
  }
  if (!any) append(out, &len, " none");
  return len;
}

StatusReporter::StatusReporter(hal::Watchdog& watchdog, const StatusBoard& board, double rate_hz,
                               std::chrono::milliseconds period)
    : watchdog_(watchdog), board_(board), rate_hz_(rate_hz), period_(period) {}

StatusReporter::~StatusReporter() { stop(); }

void StatusReporter::start() {
  if (thread_.joinable()) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = false;
  }
  thread_ = std::thread([this] {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      lock.unlock();
      const Status s = report_now();
      if (!s.is_ok() && failures() == 1) {
        // Once: the service manager refusing a status says the same every second after.
        spdlog::warn("service status not sent: {}", s.message());
      }
      lock.lock();
      wake_.wait_for(lock, period_, [this] { return stop_; });
    }
  });
}

void StatusReporter::stop() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

Status StatusReporter::report_now() {
  std::array<char, kServiceStatusMax> text{};
  format_service_status(text, board_.read(), rate_hz_);
  if (sent_.load() > 0 && std::strcmp(text.data(), last_.data()) == 0) return Status::ok();
  const Status s = watchdog_.notify_status(text.data());
  if (!s.is_ok()) {
    failures_.fetch_add(1);
    return s;
  }
  last_ = text;
  sent_.fetch_add(1);
  return s;
}

std::uint32_t StatusReporter::sent() const { return sent_.load(); }
std::uint32_t StatusReporter::failures() const { return failures_.load(); }

}  // namespace gfins::app
