// Re-reading the calibration file is file I/O and parsing (allocation, blocking): it runs on a
// worker thread. The loop posts a request and polls for the outcome once per cycle; nothing on
// the loop's side blocks or allocates.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "gfins/nav_core/pipeline.hpp"

namespace gfins::app {

/// The calibration parts the loop applies, and how it identifies them.
struct CalibrationSet {
  nav::PipelineConfig<float> config{};  // full pipeline configuration built from the calibration
  std::uint32_t cal_id = 0;             // 0 = uncalibrated defaults
  bool calibrated = false;
};

/// What a reload asks for: the loop's current configuration to start from, and whether a file of
/// another device may replace the calibration in use (ReloadCalibration's ReloadForced).
struct ReloadRequest {
  nav::PipelineConfig<float> current{};
  bool forced = false;
};

/// What a load made of the file: a new set, or nothing and why.
struct ReloadOutcome {
  std::optional<CalibrationSet> set;
  bool other_device = false;  // refused: the file's device_id is not the one in use
};

class ReloadWorker {
 public:
  /// `load` runs on the worker thread: a new set, or none when the file is missing, bad or
  /// another device's (it logs why).
  using LoadFn = std::function<ReloadOutcome(const ReloadRequest&)>;

  explicit ReloadWorker(LoadFn load);
  ~ReloadWorker();
  ReloadWorker(const ReloadWorker&) = delete;
  ReloadWorker& operator=(const ReloadWorker&) = delete;

  /// Loop side: starts a reload; false when one is already running.
  bool request(const ReloadRequest& r);

  enum class Poll : std::uint8_t { kNothing, kReady, kFailed, kOtherDevice };
  /// Loop side, non-blocking: kReady copies the new set into `out`. The first poll after the
  /// worker finished sees the outcome (it takes no lock that the worker could be holding).
  Poll poll(CalibrationSet& out);

  /// Host side only (tests, shutdown), blocking: returns once no reload is requested or
  /// running, so that the next poll() reports the outcome. Never call it from the loop.
  void wait_settled();

 private:
  void run();

  LoadFn load_;
  std::mutex mutex_;  // guards request_ and the wake-up; the loop only ever try_locks it
  std::condition_variable wake_;     // worker: a request or stop arrived
  std::condition_variable settled_;  // wait_settled(): the worker finished a request
  ReloadRequest request_{};
  CalibrationSet result_{};
  std::atomic<int> state_{0};  // 0 idle, 1 requested, 2 running, 3 ready, 4 failed, 5 refused
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace gfins::app
