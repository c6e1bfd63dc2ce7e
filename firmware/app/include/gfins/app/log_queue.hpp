// Logging from the sample loop without allocating, blocking or formatting there: the loop pushes
// fixed-size records into a preallocated single-producer/single-consumer ring; a logger thread
// pops and formats them (LogDrain, logger.hpp). A full ring drops the record and counts it (the
// loop never waits for the logger).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace gfins::app {

enum class LogLevel : std::uint8_t { kTrace, kDebug, kInfo, kWarn, kError };

struct LogRecord {
  static constexpr std::size_t kMaxArgs = 4;
  std::int64_t t_ns = 0;    // monotonic time of the event (the sample's edge time)
  const char* format = "";  // fmt-style "{}" placeholders; a literal (static storage)
  std::array<std::int64_t, kMaxArgs> args{};
  LogLevel level = LogLevel::kInfo;
};

/// Single producer (the sample loop), single consumer (the logger thread). Lock-free: one
/// acquire/release pair per push and per pop.
template <std::size_t kCapacity>
class LogQueue {
  static_assert((kCapacity & (kCapacity - 1)) == 0, "capacity must be a power of two");

 public:
  /// Copies the record in; false (and counted) when the ring is full.
  bool push(const LogRecord& r) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) >= kCapacity) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    ring_[head & (kCapacity - 1)] = r;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  bool push(LogLevel level, std::int64_t t_ns, const char* format, std::int64_t a0 = 0,
            std::int64_t a1 = 0, std::int64_t a2 = 0, std::int64_t a3 = 0) {
    LogRecord r;
    r.t_ns = t_ns;
    r.format = format;
    r.args = {a0, a1, a2, a3};
    r.level = level;
    return push(r);
  }

  /// Consumer side: the oldest record, false when empty.
  bool pop(LogRecord& out) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = ring_[tail & (kCapacity - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  std::uint32_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  static constexpr std::size_t capacity() { return kCapacity; }

 private:
  std::array<LogRecord, kCapacity> ring_{};
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::atomic<std::uint32_t> dropped_{0};
};

/// The firmware's queue: 1024 records absorb a burst of one event per sample for a second at
/// 1 kHz while the logger thread (10 ms period) is descheduled.
inline constexpr std::size_t kLogQueueCapacity = 1024;
using FwLogQueue = LogQueue<kLogQueueCapacity>;

}  // namespace gfins::app
