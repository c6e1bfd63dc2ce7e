// The logger thread: drains the loop's LogQueue every few milliseconds, formats each record and
// hands the line to spdlog (or to a test's callback). Allocation and I/O happen here, never in
// the sample loop.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <thread>

#include "gfins/app/log_queue.hpp"

namespace gfins::app {

/// Formats one record: the format's "{}" replaced by its arguments in order.
std::string format_record(const LogRecord& r);

class LogDrain {
 public:
  using LineFn = std::function<void(LogLevel, const std::string&)>;

  /// `line` receives each formatted record; empty = spdlog's default logger.
  LogDrain(FwLogQueue& queue, LineFn line = {});
  ~LogDrain();
  LogDrain(const LogDrain&) = delete;
  LogDrain& operator=(const LogDrain&) = delete;

  void start();
  /// Drains what is left and joins the thread.
  void stop();
  /// Pops and emits everything queued now (the thread calls it; tests may call it directly).
  std::size_t drain();

 private:
  FwLogQueue& queue_;
  LineFn line_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// Sets up spdlog (stderr, "[time] [level] text") at a level named as in the configuration.
void init_spdlog(const std::string& level);

}  // namespace gfins::app
