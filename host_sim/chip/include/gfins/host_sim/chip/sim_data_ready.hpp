// A data-ready line driven by the simulation's sample clock instead of a GPIO.
//
// Edges are queued by the simulation (raise) and handed to the driver by wait_edge, in order,
// with the sequence numbers a kernel would give them: every edge the "kernel" sees takes the
// next number, including edges it then loses (raise_lost: the gap the driver counts as a missed
// edge) and glitches (raise_glitch: an edge with no conversion behind it). Simulated time does
// not pass while the driver waits: an empty queue answers kTimeout at once, whatever the
// timeout. A listener is told when a conversion edge is delivered, so the chip model can latch
// the conversion at that instant (after any glitch before it was handled). No heap: a fixed ring.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "gfins/hal/data_ready.hpp"

namespace gfins::sim {

class SimDataReadyLine : public hal::DataReadyLine {
 public:
  static constexpr std::size_t kCapacity = 16;

  class Listener {
   public:
    virtual ~Listener() = default;
    /// A conversion edge is being delivered to the driver.
    virtual void on_conversion_edge(const hal::DataReadyEdge& e) = 0;
  };

  void set_listener(Listener* l) { listener_ = l; }
  /// The sequence number the next edge will carry.
  void set_next_seq(std::uint32_t seq) { next_seq_ = seq; }
  std::uint32_t next_seq() const { return next_seq_; }

  /// A conversion edge at t_ns. false (and counted) when the queue is full.
  bool raise(std::int64_t t_ns) { return push(t_ns, true); }
  /// A spurious edge (no conversion) at t_ns.
  bool raise_glitch(std::int64_t t_ns) { return push(t_ns, false); }
  /// An edge the kernel counted but lost: consumes a sequence number, delivers nothing.
  void raise_lost() { ++next_seq_; }

  std::size_t pending() const { return count_; }
  std::uint32_t overflows() const { return overflows_; }
  void clear() { head_ = count_ = 0; }

 private:
  struct Entry {
    hal::DataReadyEdge edge;
    bool conversion = false;
  };

  bool push(std::int64_t t_ns, bool conversion) {
    if (count_ == kCapacity) {
      ++overflows_;
      ++next_seq_;  // the kernel saw it; the event is lost like in an overflowing kfifo
      return false;
    }
    ring_[(head_ + count_) % kCapacity] = Entry{hal::DataReadyEdge{t_ns, next_seq_++}, conversion};
    ++count_;
    return true;
  }

  Result<hal::DataReadyEdge> do_wait_edge(std::int64_t /*timeout_ns*/) override {
    if (count_ == 0) return Status(ErrorCode::kTimeout, "sim data-ready: no edge pending");
    const Entry e = ring_[head_];
    head_ = (head_ + 1) % kCapacity;
    --count_;
    if (e.conversion && listener_ != nullptr) listener_->on_conversion_edge(e.edge);
    return e.edge;
  }

  std::array<Entry, kCapacity> ring_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::uint32_t next_seq_ = 0;
  std::uint32_t overflows_ = 0;
  Listener* listener_ = nullptr;
};

}  // namespace gfins::sim
