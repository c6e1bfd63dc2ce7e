// Logging from the sample loop without allocating, blocking or formatting there: the loop pushes
// fixed-size records into a preallocated single-producer/single-consumer ring; a logger thread
// pops and formats them (LogDrain, logger.hpp). A full ring drops the record and counts it (the
// loop never waits for the logger).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "gfins/app/spsc_ring.hpp"

namespace gfins::app {

enum class LogLevel : std::uint8_t { kTrace, kDebug, kInfo, kWarn, kError };

struct LogRecord {
  static constexpr std::size_t kMaxArgs = 4;
  std::int64_t t_ns = 0;    // monotonic time of the event (the sample's edge time)
  const char* format = "";  // fmt-style "{}" placeholders; a literal (static storage)
  std::array<std::int64_t, kMaxArgs> args{};
  LogLevel level = LogLevel::kInfo;
};

/// The sample loop's log: an SpscRing of records (spsc_ring.hpp) that can also be filled from
/// a level, a format and its arguments.
template <std::size_t kCapacity>
class LogQueue : public SpscRing<LogRecord, kCapacity> {
 public:
  using SpscRing<LogRecord, kCapacity>::push;

  bool push(LogLevel level, std::int64_t t_ns, const char* format, std::int64_t a0 = 0,
            std::int64_t a1 = 0, std::int64_t a2 = 0, std::int64_t a3 = 0) {
    LogRecord r;
    r.t_ns = t_ns;
    r.format = format;
    r.args = {a0, a1, a2, a3};
    r.level = level;
    return push(r);
  }
};

/// The firmware's queue: 1024 records absorb a burst of one event per sample for a second at
/// 1 kHz while the logger thread (10 ms period) is descheduled.
inline constexpr std::size_t kLogQueueCapacity = 1024;
using FwLogQueue = LogQueue<kLogQueueCapacity>;

}  // namespace gfins::app
