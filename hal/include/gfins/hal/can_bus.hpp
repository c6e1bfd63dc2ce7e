// CAN bus seam: classic CAN 2.0 frames, a non-blocking send, a receive with a timeout, the
// controller's error state and counters (Linux backend: SocketCAN raw socket; simulation: a
// candump-format log file or an in-memory bus).
//
// send() never blocks the sample loop: a backend that cannot hand a frame to the controller
// now (ENOBUFS/EAGAIN, error-passive, bus-off, interface down) queues it in a bounded queue or
// drops it, and counts what it dropped.
#pragma once

#include <array>
#include <cstdint>

#include "gfins/status/status.hpp"

namespace gfins::hal {

struct CanFrame {
  static constexpr std::uint32_t kMaxStandardId = 0x7FF;
  static constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFF;
  static constexpr std::uint8_t kMaxLen = 8;

  std::uint32_t id = 0;   // 11-bit (standard) or 29-bit (extended) identifier, no flag bits
  bool extended = false;  // 29-bit identifier
  std::uint8_t len = 0;   // data length, 0..8
  std::array<std::uint8_t, kMaxLen> data{};
};

/// ISO 11898-1 fault confinement states, plus "down" for an interface that is not up.
enum class CanBusState : std::uint8_t {
  kErrorActive,
  kErrorWarning,
  kErrorPassive,
  kBusOff,
  kDown
};

constexpr const char* to_string(CanBusState s) {
  switch (s) {
    case CanBusState::kErrorActive:
      return "error-active";
    case CanBusState::kErrorWarning:
      return "error-warning";
    case CanBusState::kErrorPassive:
      return "error-passive";
    case CanBusState::kBusOff:
      return "bus-off";
    case CanBusState::kDown:
      return "down";
  }
  return "unknown";
}

/// Counters only grow (they wrap at 2^32).
struct CanCounters {
  std::uint32_t tx_frames = 0;          // frames handed to the controller / sink
  std::uint32_t tx_dropped = 0;         // frames dropped: queue full, bus-off, interface down
  std::uint32_t tx_queued = 0;          // frames that had to wait in the backend's queue
  std::uint32_t rx_frames = 0;          // data frames received
  std::uint32_t rx_dropped = 0;         // frames the controller or backend reported lost on receive
                                        // (SocketCAN: CAN_ERR_CRTL_RX_OVERFLOW error frames)
  std::uint32_t rx_kernel_dropped = 0;  // frames the kernel dropped from this socket's full
                                        // receive queue before we read them (SO_RXQ_OVFL)
  std::uint32_t error_frames = 0;       // error frames seen (SocketCAN CAN_ERR_FLAG)
  std::uint32_t bus_off_events = 0;     // transitions into bus-off
  std::uint32_t error_passive_events = 0;
  std::uint32_t restarts = 0;  // recoveries from bus-off / interface down
};

class CanBus {
 public:
  virtual ~CanBus() = default;

  /// Hands one frame to the bus without blocking. kInvalidArgument for a malformed frame (id
  /// beyond 11/29 bits, len > 8); kResourceExhausted when the frame was dropped because the
  /// queue is full; kUnavailable when the bus is off or down (frame dropped and counted).
  [[nodiscard]] Status send(const CanFrame& f) {
    if (f.len > CanFrame::kMaxLen) return Status(ErrorCode::kInvalidArgument, "can: len > 8");
    if (f.id > (f.extended ? CanFrame::kMaxExtendedId : CanFrame::kMaxStandardId)) {
      return Status(ErrorCode::kInvalidArgument, "can: identifier out of range");
    }
    return do_send(f);
  }

  /// Receives one data frame, waiting at most `timeout_ns` (0 = poll); kTimeout when none.
  [[nodiscard]] Result<CanFrame> receive(std::int64_t timeout_ns) {
    if (timeout_ns < 0) return Status(ErrorCode::kInvalidArgument, "can: negative timeout");
    return do_receive(timeout_ns);
  }

  /// Lets the backend flush its queue and read error frames/state; call once per loop cycle.
  /// Never blocks.
  void service() { do_service(); }

  CanBusState state() const { return do_state(); }
  CanCounters counters() const { return do_counters(); }

 private:
  virtual Status do_send(const CanFrame& f) = 0;
  virtual Result<CanFrame> do_receive(std::int64_t timeout_ns) = 0;
  virtual void do_service() {}
  virtual CanBusState do_state() const = 0;
  virtual CanCounters do_counters() const = 0;
};

}  // namespace gfins::hal
