// The firmware's one-line status for the service manager (systemd STATUS=, shown by
// `systemctl status gfins-fw` and `systemctl show -p StatusText gfins-fw`; docs/deploy.md):
// the mode, the rate, the calibration in use and every fault counter that is not zero, so an
// operator sees a faulty board without decoding its CAN frames.
//
// The text is made and sent by a reporter thread (StatusReporter) from the loop's StatusBoard,
// never on the sample loop: sd_notify is a socket write, formatting is string work.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <span>
#include <thread>

#include "gfins/app/status_board.hpp"
#include "gfins/hal/watchdog.hpp"
#include "gfins/status/status.hpp"

namespace gfins::app {

/// Room for the longest line (every counter at 2^32 - 1 is about 270 characters); a longer
/// text is cut, still NUL-terminated.
inline constexpr std::size_t kServiceStatusMax = 320;

/// Writes the status line for `s` at `rate_hz` into `out` (NUL-terminated, cut to fit);
/// returns its length. Examples (docs/deploy.md):
///   "navigating at 1000 Hz, calibration 4fd264c0; faults: none"
///   "aligning (keep the board still) at 500 Hz, NOMINAL calibration (no calibration file);
///    faults: missed data-ready edges 12, CAN tx dropped 452"
std::size_t format_service_status(std::span<char> out, const StatusSnapshot& s, double rate_hz);

/// Reports the loop's status to the service manager through hal::Watchdog::notify_status: at
/// start(), then every `period` whenever the text changed (an unchanged line is not re-sent).
class StatusReporter {
 public:
  StatusReporter(hal::Watchdog& watchdog, const StatusBoard& board, double rate_hz,
                 std::chrono::milliseconds period = std::chrono::milliseconds(1000));
  ~StatusReporter();
  StatusReporter(const StatusReporter&) = delete;
  StatusReporter& operator=(const StatusReporter&) = delete;

  void start();
  /// Joins the thread (no more reports after it returns).
  void stop();
  /// Formats the board's status now and sends it when it differs from the last one sent; the
  /// thread calls it, tests may too. The notify error, if any.
  Status report_now();

  std::uint32_t sent() const;
  std::uint32_t failures() const;
  /// The last line sent (empty before the first).
  const char* last_sent() const { return last_.data(); }

 private:
  hal::Watchdog& watchdog_;
  const StatusBoard& board_;
  double rate_hz_;
  std::chrono::milliseconds period_;
  std::array<char, kServiceStatusMax> last_{};
  std::atomic<std::uint32_t> sent_{0};
  std::atomic<std::uint32_t> failures_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace gfins::app
