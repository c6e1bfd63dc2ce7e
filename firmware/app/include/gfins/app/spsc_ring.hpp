// A single-producer/single-consumer ring of fixed-size values in static storage: the sample loop
// pushes (never waits, never allocates), a helper thread pops. A full ring drops the value and
// counts it: the loop's timing comes first. Used for the log (log_queue.hpp) and the raw-sample
// recorder (recorder.hpp).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace gfins::app {

/// Lock-free: one acquire/release pair per push and per pop.
template <typename T, std::size_t kCapacity>
class SpscRing {
  static_assert((kCapacity & (kCapacity - 1)) == 0, "capacity must be a power of two");

 public:
  /// Copies the value in; false (and counted) when the ring is full.
  bool push(const T& v) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) >= kCapacity) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    ring_[head & (kCapacity - 1)] = v;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer side: the oldest value, false when empty.
  bool pop(T& out) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = ring_[tail & (kCapacity - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  std::uint32_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  /// Producer side: whether a push now would find room.
  bool has_room() const {
    return head_.load(std::memory_order_relaxed) - tail_.load(std::memory_order_acquire) <
           kCapacity;
  }
  static constexpr std::size_t capacity() { return kCapacity; }

 private:
  std::array<T, kCapacity> ring_{};
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::atomic<std::uint32_t> dropped_{0};
};

}  // namespace gfins::app
