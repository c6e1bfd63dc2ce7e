#include "gfins/drivers/lnx/socket_can.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <time.h>

#include <cerrno>
#include <cstring>

namespace gfins::drivers::lnx {
namespace {

static_assert(SocketCan::kNameMax == IFNAMSIZ, "interface name buffer must be IFNAMSIZ");
static_assert(sizeof(can_frame) == CAN_MTU, "classic CAN frames only");

// Error classes the socket subscribes to (linux/can/error.h). Every class is decoded below.
constexpr can_err_mask_t kErrorMask = CAN_ERR_TX_TIMEOUT | CAN_ERR_LOSTARB | CAN_ERR_CRTL |
                                      CAN_ERR_PROT | CAN_ERR_TRX | CAN_ERR_ACK | CAN_ERR_BUSOFF |
                                      CAN_ERR_BUSERROR | CAN_ERR_RESTARTED;

// Upper bound of frames read per drain, so service() stays bounded on a flooded bus.
constexpr int kMaxReadsPerDrain = 128;

bool would_block(int err) { return err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS; }
bool interface_gone(int err) { return err == ENETDOWN || err == ENODEV || err == ENXIO; }

}  // namespace

Result<std::unique_ptr<SocketCan>> SocketCan::open(const SocketCanConfig& config, Os& os) {
  if (config.interface.empty()) {
    return Status(ErrorCode::kInvalidArgument, "socketcan: empty interface name");
  }
  if (config.interface.size() >= kNameMax) {
    return Status(ErrorCode::kInvalidArgument,
                  "socketcan: interface name longer than 15 characters (IFNAMSIZ)");
  }
  if (config.interface.find('\0') != std::string_view::npos) {
    return Status(ErrorCode::kInvalidArgument, "socketcan: interface name contains a NUL");
  }
  // What the kernel's dev_valid_name() refuses (".", "..", '/', ':', white space), and every
  // other control character: a name holding ESC or a newline would reach the terminal in
  // every message that names the interface.
  if (config.interface == "." || config.interface == "..") {
    return Status(ErrorCode::kInvalidArgument,
                  "socketcan: \".\" and \"..\" are not interface names");
  }
  for (const char ch : config.interface) {
    const auto c = static_cast<unsigned char>(ch);
    if (c <= 0x20 || c == 0x7F || c == '/' || c == ':') {
      return Status(ErrorCode::kInvalidArgument,
                    "socketcan: interface name holds a control character, a space, '/' or ':'");
    }
  }
  if (config.tx_queue_capacity == 0 || config.tx_queue_capacity > kMaxTxQueue) {
    return Status(ErrorCode::kInvalidArgument, "socketcan: tx queue capacity must be 1..256");
  }
  if (config.filters.size() > kMaxFilters) {
    return Status(ErrorCode::kInvalidArgument, "socketcan: more than 16 receive filters");
  }
  std::unique_ptr<SocketCan> bus(new SocketCan(os));
  std::memcpy(bus->name_.data(), config.interface.data(), config.interface.size());
  bus->name_[config.interface.size()] = '\0';
  bus->tx_capacity_ = config.tx_queue_capacity;
  for (const CanFilter& f : config.filters) bus->filters_[bus->filter_count_++] = f;
  const Status s = bus->open_socket();
  if (!s.is_ok()) return s;
  return bus;
}

SocketCan::SocketCan(Os& os) : os_(os) {}

SocketCan::~SocketCan() {
  if (fd_ >= 0) (void)os_.close(fd_);
}

Status SocketCan::open_socket() {
  const int fd = os_.socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int err = errno;
    return Status(ErrorCode::kUnavailable,
                  err == EAFNOSUPPORT || err == EPROTONOSUPPORT
                      ? "socket(PF_CAN, SOCK_RAW, CAN_RAW) failed: this kernel has no SocketCAN "
                        "(modules can, can-raw)"
                      : "socket(PF_CAN, SOCK_RAW, CAN_RAW) failed",
                  err);
  }
  if (fd_ >= 0) (void)os_.close(fd_);
  fd_ = fd;
  const unsigned index = os_.if_nametoindex(name_.data());
  if (index == 0) {
    return Status(ErrorCode::kUnavailable, "socketcan: no such network interface", errno);
  }
  ifindex_ = index;
  const can_err_mask_t mask = kErrorMask;
  if (os_.setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof mask) != 0) {
    return Status(ErrorCode::kIoError, "socketcan: setsockopt(CAN_RAW_ERR_FILTER) failed", errno);
  }
  // The kernel's count of frames it dropped because this socket's receive queue was full, sent
  // as ancillary data (SOL_SOCKET, SO_RXQ_OVFL: a u32, total since the socket was created) with
  // every frame read after the first drop (socket(7)). A new socket starts from zero.
  const int one = 1;
  if (os_.setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one) != 0) {
    return Status(ErrorCode::kIoError, "socketcan: setsockopt(SO_RXQ_OVFL) failed", errno);
  }
  kernel_drops_seen_ = 0;
  Status s = apply_filters();
  if (!s.is_ok()) return s;
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(ifindex_);
  if (os_.bind(fd_, &addr, sizeof addr) != 0) {
    return Status(ErrorCode::kIoError, "socketcan: bind to the interface failed", errno);
  }
  return Status::ok();
}

Status SocketCan::set_filters(std::span<const CanFilter> filters) {
  if (filters.size() > kMaxFilters) {
    return Status(ErrorCode::kInvalidArgument, "socketcan: more than 16 receive filters");
  }
  filter_count_ = 0;
  for (const CanFilter& f : filters) filters_[filter_count_++] = f;
  return apply_filters();
}

Status SocketCan::apply_filters() {
  if (filter_count_ == 0) {
    // The raw socket's default: one filter passing everything (can.rst 4.1.1). Set it again so
    // that clearing the filters after set_filters() restores it.
    can_filter all{};
    all.can_id = 0;
    all.can_mask = 0;
    if (os_.setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, &all, sizeof all) != 0) {
      return Status(ErrorCode::kIoError, "socketcan: setsockopt(CAN_RAW_FILTER) failed", errno);
    }
    return Status::ok();
  }
  std::array<can_filter, kMaxFilters> raw{};
  for (std::size_t i = 0; i < filter_count_; ++i) {
    const CanFilter& f = filters_[i];
    // The EFF and RTR flags in the mask make a filter match only data frames of its format.
    raw[i].can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0U);
    raw[i].can_mask =
        (f.mask & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK)) | CAN_EFF_FLAG | CAN_RTR_FLAG;
  }
  const auto len = static_cast<unsigned>(filter_count_ * sizeof(can_filter));
  if (os_.setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, raw.data(), len) != 0) {
    return Status(ErrorCode::kIoError, "socketcan: setsockopt(CAN_RAW_FILTER) failed", errno);
  }
  return Status::ok();
}

bool SocketCan::tx_push(const hal::CanFrame& f) {
  if (tx_size_ == tx_capacity_) return false;
  tx_[(tx_head_ + tx_size_) % tx_capacity_] = f;
  ++tx_size_;
  ++counters_.tx_queued;
  return true;
}

// One write(2) of one frame; kOk, kResourceExhausted for "try later", kUnavailable for a gone
// interface, kIoError otherwise (the caller decides what to do with the frame).
Status SocketCan::write_frame(const hal::CanFrame& f) {
  can_frame raw{};
  raw.can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0U);
  raw.len = f.len;
  std::memcpy(raw.data, f.data.data(), f.len);
  const long n = os_.write(fd_, &raw, sizeof raw);
  if (n == static_cast<long>(sizeof raw)) {
    ++counters_.tx_frames;
    return Status::ok();
  }
  if (n >= 0) return Status(ErrorCode::kIoError, "socketcan: short write of a frame");
  const int err = errno;
  if (would_block(err)) {
    return Status(ErrorCode::kResourceExhausted, "socketcan: kernel tx queue full", err);
  }
  if (interface_gone(err)) {
    go_down();
    return Status(ErrorCode::kUnavailable, "socketcan: interface down", err);
  }
  return Status(ErrorCode::kIoError, "socketcan: write of a frame failed", err);
}

Status SocketCan::do_send(const hal::CanFrame& f) {
  if (tx_size_ > 0) flush_tx();  // older frames go first; this may find the interface down
  if (state_ == hal::CanBusState::kDown) {
    ++counters_.tx_dropped;
    return Status(ErrorCode::kUnavailable, "socketcan: interface down, frame dropped");
  }
  if (state_ == hal::CanBusState::kBusOff) {
    ++counters_.tx_dropped;
    return Status(ErrorCode::kUnavailable, "socketcan: bus-off, frame dropped");
  }
  if (tx_size_ > 0) {  // the kernel still refuses: wait behind the older frames
    if (tx_push(f)) return Status::ok();
    ++counters_.tx_dropped;
    return Status(ErrorCode::kResourceExhausted, "socketcan: tx queue full, frame dropped");
  }
  const Status s = write_frame(f);
  if (s.is_ok()) return s;
  if (s.code() == ErrorCode::kResourceExhausted) {
    if (tx_push(f)) return Status::ok();
    ++counters_.tx_dropped;
    return Status(ErrorCode::kResourceExhausted, "socketcan: tx queue full, frame dropped",
                  s.os_error());
  }
  ++counters_.tx_dropped;
  return s;
}

void SocketCan::flush_tx() {
  while (tx_size_ > 0 && state_ != hal::CanBusState::kDown) {
    const Status s = write_frame(tx_[tx_head_]);
    if (s.code() == ErrorCode::kResourceExhausted) return;  // still full: try next cycle
    if (state_ == hal::CanBusState::kDown) return;          // go_down() dropped the queue
    if (!s.is_ok()) ++counters_.tx_dropped;                 // a frame the kernel refuses
    tx_head_ = (tx_head_ + 1) % tx_capacity_;
    --tx_size_;
  }
}

void SocketCan::go_down() {
  if (state_ != hal::CanBusState::kDown) ++errors_.interface_down;
  state_ = hal::CanBusState::kDown;
  counters_.tx_dropped += static_cast<std::uint32_t>(tx_size_);  // stale once the link is down
  tx_size_ = 0;
  tx_head_ = 0;
}

void SocketCan::try_recover() {
  const unsigned index = os_.if_nametoindex(name_.data());
  if (index == 0) return;  // interface still absent
  if (index != ifindex_) {
    // Deleted and re-created: the old binding is gone (NETDEV_UNREGISTER), bind a new socket.
    if (!open_socket().is_ok()) return;
  }
  ifreq req{};
  std::memcpy(req.ifr_name, name_.data(), kNameMax);  // NUL-terminated, length checked at open
  if (os_.ioctl(fd_, SIOCGIFFLAGS, &req) != 0) return;
  if ((req.ifr_flags & IFF_UP) == 0) return;
  state_ = hal::CanBusState::kErrorActive;
  ++counters_.restarts;
}

void SocketCan::handle_error_frame(std::uint32_t can_id, const std::array<std::uint8_t, 8>& d) {
  ++counters_.error_frames;
  if (can_id & CAN_ERR_TX_TIMEOUT) ++errors_.tx_timeouts;
  if (can_id & CAN_ERR_LOSTARB) ++errors_.lost_arbitration;
  if (can_id & CAN_ERR_PROT) ++errors_.protocol_violations;
  if (can_id & CAN_ERR_TRX) ++errors_.transceiver_errors;
  if (can_id & CAN_ERR_ACK) ++errors_.no_ack;
  if (can_id & CAN_ERR_BUSERROR) ++errors_.bus_errors;
  if (can_id & CAN_ERR_CRTL) {
    ++errors_.controller_problems;
    const std::uint8_t c = d[1];  // controller status byte (error.h, data[1])
    if (c & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) ++counters_.rx_dropped;
    if (c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      if (state_ != hal::CanBusState::kErrorPassive) ++counters_.error_passive_events;
      state_ = hal::CanBusState::kErrorPassive;
    } else if (c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      state_ = hal::CanBusState::kErrorWarning;
    } else if (c & CAN_ERR_CRTL_ACTIVE) {
      state_ = hal::CanBusState::kErrorActive;
    }
  }
  if (can_id & CAN_ERR_BUSOFF) {
    if (state_ != hal::CanBusState::kBusOff) ++counters_.bus_off_events;
    state_ = hal::CanBusState::kBusOff;
    // The controller sends nothing in bus-off; what waits would go out stale after restart.
    counters_.tx_dropped += static_cast<std::uint32_t>(tx_size_);
    tx_size_ = 0;
  }
  if (can_id & CAN_ERR_RESTARTED) {
    state_ = hal::CanBusState::kErrorActive;
    ++counters_.restarts;
  }
}

void SocketCan::note_kernel_drops(const void* msg_header) {
  const auto* msg = static_cast<const msghdr*>(msg_header);
  for (const cmsghdr* c = CMSG_FIRSTHDR(msg); c != nullptr;
       c = CMSG_NXTHDR(const_cast<msghdr*>(msg), const_cast<cmsghdr*>(c))) {
    if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SO_RXQ_OVFL) continue;
    if (c->cmsg_len < CMSG_LEN(sizeof(std::uint32_t))) continue;
    std::uint32_t total = 0;
    std::memcpy(&total, CMSG_DATA(c), sizeof total);
    // A running total that wraps at 2^32: the unsigned difference is the drops since the last
    // report, across a wrap too.
    counters_.rx_kernel_dropped += total - kernel_drops_seen_;
    kernel_drops_seen_ = total;
  }
}

void SocketCan::drain_rx() {
  for (int i = 0; i < kMaxReadsPerDrain && state_ != hal::CanBusState::kDown; ++i) {
    // A full queue stops the drain: what is still in the socket stays in the kernel's buffer
    // (which is much larger) until the caller has collected, instead of being dropped here.
    if (rx_size_ == kRxQueue) return;
    can_frame raw{};
    iovec iov{&raw, sizeof raw};
    // Room for the SO_RXQ_OVFL count (and a timestamp, should one ever be enabled).
    alignas(cmsghdr)
        std::array<unsigned char, CMSG_SPACE(sizeof(std::uint32_t)) + CMSG_SPACE(sizeof(timespec))>
            control{};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control.data();
    msg.msg_controllen = control.size();
    const long n = os_.recvmsg(fd_, &msg, 0);
    if (n < 0) {
      const int err = errno;
      if (interface_gone(err)) go_down();
      return;  // EAGAIN: nothing more; other errors: reported by the next send
    }
    note_kernel_drops(&msg);
    if (n != static_cast<long>(sizeof raw)) continue;  // not a classic frame
    if (raw.can_id & CAN_ERR_FLAG) {
      std::array<std::uint8_t, 8> d{};
      std::memcpy(d.data(), raw.data, d.size());
      handle_error_frame(raw.can_id & CAN_ERR_MASK, d);
      continue;
    }
    if (raw.can_id & CAN_RTR_FLAG) continue;  // remote requests carry no data for us
    if (state_ == hal::CanBusState::kBusOff) {
      // Receiving means the controller is back on the bus even if no RESTARTED frame came.
      state_ = hal::CanBusState::kErrorActive;
      ++counters_.restarts;
    }
    ++counters_.rx_frames;
    hal::CanFrame& f = rx_[(rx_head_ + rx_size_) % kRxQueue];
    f.extended = (raw.can_id & CAN_EFF_FLAG) != 0;
    f.id = raw.can_id & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    f.len = raw.len > 8 ? 8 : raw.len;
    f.data = {};
    std::memcpy(f.data.data(), raw.data, f.len);
    ++rx_size_;
  }
}

void SocketCan::do_service() {
  if (state_ == hal::CanBusState::kDown) try_recover();
  if (state_ == hal::CanBusState::kDown) return;
  drain_rx();
  flush_tx();
}

Result<hal::CanFrame> SocketCan::do_receive(std::int64_t timeout_ns) {
  const std::int64_t deadline = monotonic_ns(os_) + timeout_ns;
  for (;;) {
    if (rx_size_ == 0) drain_rx();
    if (rx_size_ > 0) {
      const hal::CanFrame f = rx_[rx_head_];
      rx_head_ = (rx_head_ + 1) % kRxQueue;
      --rx_size_;
      return f;
    }
    if (state_ == hal::CanBusState::kDown) {
      try_recover();
      if (state_ == hal::CanBusState::kDown) {
        return Status(ErrorCode::kUnavailable, "socketcan: interface down");
      }
    }
    const std::int64_t left = deadline - monotonic_ns(os_);
    if (left <= 0) return Status(ErrorCode::kTimeout, "socketcan: no frame before the timeout");
    pollfd p{};
    p.fd = fd_;
    p.events = POLLIN;
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(left / 1000000000);
    ts.tv_nsec = static_cast<long>(left % 1000000000);
    const int r = os_.ppoll(&p, 1, &ts);
    if (r < 0 && errno != EINTR) {
      return Status(ErrorCode::kIoError, "socketcan: ppoll failed", errno);
    }
    if (r == 0) return Status(ErrorCode::kTimeout, "socketcan: no frame before the timeout");
  }
}

}  // namespace gfins::drivers::lnx
