// hal::CanBus on a SocketCAN raw socket (Documentation/networking/can.rst).
//
// - Bound by interface name (if_nametoindex; the name's length is checked against IFNAMSIZ,
//   never strcpy'd into ifr_name), non-blocking, close-on-exec.
// - Error frames are enabled (CAN_RAW_ERR_FILTER) and decoded into the fault-confinement state
//   (error-warning, error-passive, bus-off, restarted, back to error-active) and counters:
//   controller problems, protocol violations, transceiver errors, missing ACK, tx timeouts.
// - send() never blocks: a frame the kernel refuses now (EAGAIN, ENOBUFS: the interface's tx
//   queue, default txqueuelen 10, is full) goes into a bounded FIFO of fixed capacity that
//   service() flushes; when that is full the frame is dropped and counted. In bus-off or while
//   the interface is down frames are dropped (kUnavailable) and counted.
// - Interface down (ENETDOWN) → state kDown, queued frames dropped; service() notices the
//   interface up again (SIOCGIFFLAGS), or re-created with a new index (re-binds), and counts a
//   restart.
// - Receive filters (CAN_RAW_FILTER) for the firmware's command identifiers.
// - Frames the kernel dropped because the socket's receive queue was full are counted from the
//   SO_RXQ_OVFL ancillary data of recvmsg (hal::CanCounters::rx_kernel_dropped).
// No heap after open(): the queues are arrays inside the object.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "gfins/drivers/lnx/os.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

/// Accept a frame when (frame id & mask) == (id & mask) and its format (11/29-bit) matches.
struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = hal::CanFrame::kMaxStandardId;
  bool extended = false;
};

struct SocketCanConfig {
  std::string_view interface = "can0";
  std::size_t tx_queue_capacity = 64;  // frames waiting for the kernel; ≤ SocketCan::kMaxTxQueue
  std::span<const CanFilter> filters;  // empty: receive every data frame
};

/// What the error frames said, beyond hal::CanCounters. Counters only grow.
struct SocketCanErrorCounters {
  std::uint32_t tx_timeouts = 0;          // CAN_ERR_TX_TIMEOUT
  std::uint32_t lost_arbitration = 0;     // CAN_ERR_LOSTARB
  std::uint32_t controller_problems = 0;  // CAN_ERR_CRTL (overflows, warning/passive levels)
  std::uint32_t protocol_violations = 0;  // CAN_ERR_PROT
  std::uint32_t transceiver_errors = 0;   // CAN_ERR_TRX
  std::uint32_t no_ack = 0;               // CAN_ERR_ACK: nobody acknowledged our frame
  std::uint32_t bus_errors = 0;           // CAN_ERR_BUSERROR
  std::uint32_t interface_down = 0;       // ENETDOWN / ENODEV seen
};

class SocketCan final : public hal::CanBus {
 public:
  static constexpr std::size_t kMaxTxQueue = 256;
  static constexpr std::size_t kRxQueue = 64;  // frames read by service() for receive()
  static constexpr std::size_t kMaxFilters = 16;
  static constexpr std::size_t kNameMax = 16;  // IFNAMSIZ, including the terminating NUL

  /// Errors (os_error() = errno): kInvalidArgument (empty or too long name, queue capacity 0
  /// or > kMaxTxQueue, too many filters); kUnavailable (kernel without CAN: socket() fails with
  /// EAFNOSUPPORT; no such interface: ENODEV); kIoError (setsockopt or bind failed).
  static Result<std::unique_ptr<SocketCan>> open(const SocketCanConfig& config, Os& os = real_os());

  ~SocketCan() override;
  SocketCan(const SocketCan&) = delete;
  SocketCan& operator=(const SocketCan&) = delete;

  /// Replaces the receive filters (empty: everything). kInvalidArgument above kMaxFilters.
  [[nodiscard]] Status set_filters(std::span<const CanFilter> filters);

  const SocketCanErrorCounters& error_counters() const { return errors_; }
  const char* interface() const { return name_.data(); }

 private:
  explicit SocketCan(Os& os);
  Status open_socket();
  Status apply_filters();
  Status write_frame(const hal::CanFrame& f);
  void drain_rx();
  void note_kernel_drops(const void* msg_header);  // a struct msghdr just filled by recvmsg
  void handle_error_frame(std::uint32_t can_id, const std::array<std::uint8_t, 8>& data);
  void go_down();
  void try_recover();
  void flush_tx();
  bool tx_push(const hal::CanFrame& f);

  Status do_send(const hal::CanFrame& f) override;
  Result<hal::CanFrame> do_receive(std::int64_t timeout_ns) override;
  void do_service() override;
  hal::CanBusState do_state() const override { return state_; }
  hal::CanCounters do_counters() const override { return counters_; }

  Os& os_;
  int fd_ = -1;
  unsigned ifindex_ = 0;
  std::array<char, kNameMax> name_{};
  hal::CanBusState state_ = hal::CanBusState::kErrorActive;
  hal::CanCounters counters_;
  std::uint32_t kernel_drops_seen_ = 0;  // last SO_RXQ_OVFL total of the current socket
  SocketCanErrorCounters errors_;

  std::array<CanFilter, kMaxFilters> filters_{};
  std::size_t filter_count_ = 0;

  std::array<hal::CanFrame, kMaxTxQueue> tx_{};  // FIFO ring, capacity tx_capacity_
  std::size_t tx_capacity_ = 0;
  std::size_t tx_head_ = 0;
  std::size_t tx_size_ = 0;

  std::array<hal::CanFrame, kRxQueue> rx_{};
  std::size_t rx_head_ = 0;
  std::size_t rx_size_ = 0;
};

}  // namespace gfins::drivers::lnx
