// Hardware-in-the-loop replay link over TCP (docs/hil.md). POSIX sockets, non-blocking, poll(2)
// for every wait, so a silent host costs the loop one read timeout and never blocks it.
#include "gfins/drivers/lnx/hil_link.hpp"
#include "gfins/drivers/lnx/os.hpp"
#include "gfins/recording/codec.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace gfins::drivers::lnx {
namespace hil {
namespace {

constexpr std::uint32_t kExtendedFlag = 0x80000000u;

void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
std::uint64_t get_u64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
void header(std::uint8_t* p, FrameType t, std::size_t len) {
  p[0] = kMagic0;
  p[1] = kMagic1;
  p[2] = static_cast<std::uint8_t>(t);
  p[3] = static_cast<std::uint8_t>(len);
}
template <std::size_t N>
void seal(std::array<std::uint8_t, N>& f) {
  put_u32(f.data() + N - 4, crc32(std::span<const std::uint8_t>(f.data(), N - 4)));
}

}  // namespace

// The one CRC-32 of the project (the recording format's, nav_core/recording).
std::uint32_t crc32(std::span<const std::uint8_t> bytes) { return recording::crc32(bytes); }

SampleWire encode_sample(std::uint32_t index, const RawSample& s, bool last) {
  SampleWire f{};
  header(f.data(), last ? FrameType::kLastSample : FrameType::kSample, kSampleBytes);
  put_u32(f.data() + 4, index);
  put_u32(f.data() + 8, s.seq);
  put_u64(f.data() + 12, static_cast<std::uint64_t>(s.t_ns));
  for (std::size_t j = 0; j < kAdcChannels; ++j) {
    put_u32(f.data() + 20 + 4 * j, static_cast<std::uint32_t>(s.counts[j]));
  }
  put_u32(f.data() + 44, s.flags);
  seal(f);
  return f;
}

AckWire encode_ack(std::uint32_t index, AckVerdict v) {
  AckWire f{};
  header(f.data(), FrameType::kAck, kAckBytes);
  put_u32(f.data() + 4, index);
  f[8] = static_cast<std::uint8_t>(v);
  seal(f);
  return f;
}

CanWire encode_can(const hal::CanFrame& c, FrameType type) {
  CanWire f{};
  header(f.data(), type, kCanBytes);
  put_u32(f.data() + 4, c.id | (c.extended ? kExtendedFlag : 0u));
  f[8] = c.len;
  std::memcpy(f.data() + 12, c.data.data(), c.data.size());
  seal(f);
  return f;
}

std::size_t frame_bytes(std::uint8_t type) {
  switch (static_cast<FrameType>(type)) {
    case FrameType::kSample:
    case FrameType::kLastSample:
      return kSampleBytes;
    case FrameType::kAck:
      return kAckBytes;
    case FrameType::kCan:
    case FrameType::kCanIn:
      return kCanBytes;
  }
  return 0;
}

const char* to_string(ParseError e) {
  switch (e) {
    case ParseError::kNone:
      return "ok";
    case ParseError::kNeedMore:
      return "incomplete frame";
    case ParseError::kBadMagic:
      return "bad magic (not a gfins HIL frame: stream out of step)";
    case ParseError::kBadType:
      return "unknown frame type";
    case ParseError::kBadLength:
      return "frame length does not match its type";
    case ParseError::kBadCrc:
      return "CRC-32 mismatch";
    case ParseError::kMalformed:
      return "a field holds a value the protocol does not define";
  }
  return "?";
}

ParseResult parse(std::span<const std::uint8_t> b) {
  ParseResult r;
  if (b.size() < kHeaderBytes) {
    r.error = ParseError::kNeedMore;
    return r;
  }
  if (b[0] != kMagic0 || b[1] != kMagic1) {
    r.error = ParseError::kBadMagic;
    return r;
  }
  const std::size_t want = frame_bytes(b[2]);
  if (want == 0) {
    r.error = ParseError::kBadType;
    return r;
  }
  if (b[3] != want) {
    r.error = ParseError::kBadLength;
    return r;
  }
  if (b.size() < want) {
    r.error = ParseError::kNeedMore;
    return r;
  }
  r.used = want;
  r.frame.type = static_cast<FrameType>(b[2]);
  const std::uint8_t* p = b.data();
  r.frame.index = get_u32(p + 4);
  if (get_u32(p + want - 4) != crc32(b.first(want - 4))) {
    r.error = ParseError::kBadCrc;
    return r;
  }
  switch (r.frame.type) {
    case FrameType::kSample:
    case FrameType::kLastSample:
      r.frame.sample.seq = get_u32(p + 8);
      r.frame.sample.t_ns = static_cast<std::int64_t>(get_u64(p + 12));
      for (std::size_t j = 0; j < kAdcChannels; ++j) {
        r.frame.sample.counts[j] = static_cast<std::int32_t>(get_u32(p + 20 + 4 * j));
      }
      r.frame.sample.flags = get_u32(p + 44);
      break;
    case FrameType::kAck:
      // Exactly what encode_ack writes: a known verdict, zero padding.
      if (p[8] > static_cast<std::uint8_t>(AckVerdict::kBadCrc) || p[9] != 0 || p[10] != 0 ||
          p[11] != 0) {
        r.error = ParseError::kMalformed;
        return r;
      }
      r.frame.verdict = static_cast<AckVerdict>(p[8]);
      break;
    case FrameType::kCan:
    case FrameType::kCanIn: {
      // Exactly what encode_can writes: an 11-bit identifier, or a 29-bit one with the extended
      // flag; at most 8 data bytes; zero padding.
      const std::uint32_t id = get_u32(p + 4);
      const bool extended = (id & kExtendedFlag) != 0;
      const std::uint32_t bare = id & ~kExtendedFlag;
      if (bare > (extended ? 0x1FFFFFFFu : 0x7FFu) || p[8] > hal::CanFrame::kMaxLen || p[9] != 0 ||
          p[10] != 0 || p[11] != 0) {
        r.error = ParseError::kMalformed;
        return r;
      }
      r.frame.index = 0;
      r.frame.can.extended = extended;
      r.frame.can.id = bare;
      r.frame.can.len = p[8];
      std::memcpy(r.frame.can.data.data(), p + 12, r.frame.can.data.size());
      break;
    }
  }
  return r;
}

}  // namespace hil

namespace {

std::int64_t now_ns() { return monotonic_ns(real_os()); }

// poll(2) for `events` until `deadline_ns` (CLOCK_MONOTONIC); true when ready.
bool wait_fd(int fd, short events, std::int64_t deadline_ns) {
  for (;;) {
    const std::int64_t left = deadline_ns - now_ns();
    if (left < 0) return false;
    pollfd p{fd, events, 0};
    // Round up to the next millisecond so a short timeout still polls once.
    const int ms = static_cast<int>((left + 999999) / 1000000);
    const int n = ::poll(&p, 1, ms);
    if (n > 0) return true;
    if (n == 0) return false;
    if (errno != EINTR) return true;  // let the read report the error
  }
}

// Every write of the link: the whole buffer or failure. A socket that stays full for this long
// means the peer stopped reading (a hung host); the connection is then dropped.
constexpr std::int64_t kSendStallNs = 1000000000;

bool send_all(int fd, std::span<const std::uint8_t> b) {
  std::size_t done = 0;
  const std::int64_t deadline = now_ns() + kSendStallNs;
  while (done < b.size()) {
    const ssize_t n = ::send(fd, b.data() + done, b.size() - done, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      if (!wait_fd(fd, POLLOUT, deadline)) return false;
    } else {
      return false;
    }
  }
  return true;
}

}  // namespace

// ---- Firmware end -------------------------------------------------------------------------

class HilServer::Bus final : public hal::CanBus {
 public:
  explicit Bus(HilServer& s) : s_(s) {}

 private:
  Status do_send(const hal::CanFrame& f) override {
    if (s_.conn_fd_ < 0) {
      ++s_.counters_.can_dropped;
      ++counters_.tx_dropped;
      return Status(ErrorCode::kUnavailable, "hil: no host connected");
    }
    const hil::CanWire w = hil::encode_can(f);
    if (!s_.send_bytes(w)) {
      ++s_.counters_.can_dropped;
      ++counters_.tx_dropped;
      return Status(ErrorCode::kIoError, "hil: CAN frame not written, connection dropped");
    }
    ++s_.counters_.can_sent;
    ++counters_.tx_frames;
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t) override {
    hal::CanFrame f;
    if (!s_.take_can_in(f)) return Status(ErrorCode::kTimeout, "hil: no host frame in this cycle");
    ++counters_.rx_frames;
    return f;
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return counters_; }

  HilServer& s_;
  hal::CanCounters counters_{};
};

Result<std::unique_ptr<HilServer>> HilServer::open(const HilServerConfig& c) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(c.port);
  if (::inet_pton(AF_INET, c.address.c_str(), &addr.sin_addr) != 1) {
    return Status(ErrorCode::kInvalidArgument, "hil: listen address is not an IPv4 address");
  }
  std::unique_ptr<HilServer> s(new HilServer());
  s->listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (s->listen_fd_ < 0) return Status(ErrorCode::kIoError, "hil: socket", errno);
  const int one = 1;
  (void)::setsockopt(s->listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (::bind(s->listen_fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    return Status(ErrorCode::kUnavailable, "hil: bind", errno);
  }
  if (::listen(s->listen_fd_, 1) != 0) return Status(ErrorCode::kIoError, "hil: listen", errno);
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  if (::getsockname(s->listen_fd_, reinterpret_cast<sockaddr*>(&bound), &len) != 0) {
    return Status(ErrorCode::kIoError, "hil: getsockname", errno);
  }
  s->port_ = ntohs(bound.sin_port);
  s->rx_.resize(4096);
  s->bus_ = std::make_unique<Bus>(*s);
  return s;
}

HilServer::~HilServer() {
  if (conn_fd_ >= 0) ::close(conn_fd_);
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

hal::CanBus& HilServer::bus() { return *bus_; }

void HilServer::drop(const char* why, int os_error) {
  if (conn_fd_ >= 0) ::close(conn_fd_);
  conn_fd_ = -1;
  rx_len_ = 0;
  forget_pending_can_in();  // their sample never came
  if (!finished_) ++counters_.drops;
  // Called from the loop: formatted into a fixed buffer, no allocation.
  (void)std::snprintf(last_event_.data(), last_event_.size(),
                      "%s%s%s after %u sample(s) of this connection (%u in all)", why,
                      os_error != 0 ? ": " : "", os_error != 0 ? std::strerror(os_error) : "",
                      expected_index_, counters_.samples);
}

void HilServer::queue_can_in(const hal::CanFrame& f) {
  const std::size_t held = can_in_ready_ + can_in_pending_;
  if (held == can_in_.size()) {
    ++counters_.can_in_lost;
    return;
  }
  can_in_[(can_in_head_ + held) % can_in_.size()] = f;
  ++can_in_pending_;
}

bool HilServer::take_can_in(hal::CanFrame& out) {
  if (can_in_ready_ == 0) return false;
  out = can_in_[can_in_head_];
  can_in_head_ = (can_in_head_ + 1) % can_in_.size();
  --can_in_ready_;
  ++counters_.can_in;
  return true;
}

void HilServer::forget_pending_can_in() {
  counters_.can_in_lost += static_cast<std::uint32_t>(can_in_pending_);
  can_in_pending_ = 0;
}

bool HilServer::send_bytes(std::span<const std::uint8_t> b) {
  if (conn_fd_ < 0) return false;
  if (send_all(conn_fd_, b)) return true;
  drop("hil: host stopped reading or connection lost while writing");
  return false;
}

Result<RawSample> HilServer::read_sample(std::int64_t timeout_ns) {
  const std::int64_t deadline = now_ns() + timeout_ns;
  for (;;) {
    if (conn_fd_ < 0) {
      if (!wait_fd(listen_fd_, POLLIN, deadline)) {
        return Status(ErrorCode::kTimeout, "hil: no host connected");
      }
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) continue;  // the peer gave up between poll and accept
      const int one = 1;
      (void)::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      conn_fd_ = fd;
      rx_len_ = 0;
      expected_index_ = 0;
      finished_ = false;
      ++counters_.connections;
      continue;
    }
    const hil::ParseResult pr = hil::parse(std::span<const std::uint8_t>(rx_.data(), rx_len_));
    if (pr.error == hil::ParseError::kNone || pr.error == hil::ParseError::kBadCrc) {
      std::memmove(rx_.data(), rx_.data() + pr.used, rx_len_ - pr.used);
      rx_len_ -= pr.used;
    }
    if (pr.error == hil::ParseError::kNone) {
      const hil::FrameType t = pr.frame.type;
      if (t == hil::FrameType::kCanIn) {
        queue_can_in(pr.frame.can);
        continue;
      }
      if (t != hil::FrameType::kSample && t != hil::FrameType::kLastSample) {
        ++counters_.frame_errors;
        drop("hil: the host sent a frame of a firmware-to-host type");
        return Status(ErrorCode::kIoError, "hil: unexpected frame type from the host");
      }
      expected_index_ = pr.frame.index + 1;
      ++counters_.samples;
      // Acknowledged on arrival: the host may send the next sample of its window. The CAN frames
      // of this sample follow this ACK on the connection.
      (void)send_bytes(hil::encode_ack(pr.frame.index, hil::AckVerdict::kOk));
      if (t == hil::FrameType::kLastSample) finished_ = true;
      // The frames before this sample are the loop's in this sample's cycle.
      can_in_ready_ += can_in_pending_;
      can_in_pending_ = 0;
      return pr.frame.sample;
    }
    if (pr.error == hil::ParseError::kBadCrc && pr.frame.type == hil::FrameType::kCanIn) {
      // Not a sample: nothing to acknowledge; the frame is lost (counted), the stream goes on.
      ++counters_.can_in_lost;
      continue;
    }
    if (pr.error == hil::ParseError::kBadCrc) {
      ++counters_.crc_errors;
      (void)send_bytes(hil::encode_ack(pr.frame.index, hil::AckVerdict::kBadCrc));
      return Status(ErrorCode::kDataLoss, "hil: sample frame CRC error (skipped)");
    }
    if (pr.error != hil::ParseError::kNeedMore) {
      ++counters_.frame_errors;
      drop(pr.error == hil::ParseError::kBadMagic  ? "hil: bad frame from the host: bad magic"
           : pr.error == hil::ParseError::kBadType ? "hil: bad frame from the host: unknown type"
           : pr.error == hil::ParseError::kBadLength
               ? "hil: bad frame from the host: bad length"
               : "hil: bad frame from the host: a field the protocol does not define");
      return Status(ErrorCode::kIoError, "hil: bad frame from the host (connection closed)");
    }
    if (!wait_fd(conn_fd_, POLLIN, deadline)) {
      return Status(ErrorCode::kTimeout, "hil: no sample from the host");
    }
    const ssize_t n = ::recv(conn_fd_, rx_.data() + rx_len_, rx_.size() - rx_len_, 0);
    if (n > 0) {
      rx_len_ += static_cast<std::size_t>(n);
    } else if (n == 0) {
      const bool clean = finished_ || rx_len_ == 0;
      drop(clean && finished_ ? "hil: host closed after the last sample"
                              : "hil: connection closed by the host before its last sample");
      if (finished_) return Status(ErrorCode::kTimeout, "hil: stream complete");
      return Status(ErrorCode::kIoError, "hil: connection dropped mid-stream");
    } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      const int e = errno;
      drop("hil: receive failed", e);
      return Status(ErrorCode::kIoError, "hil: connection dropped mid-stream", e);
    }
  }
}

// ---- Host end ---------------------------------------------------------------------------------

Result<std::unique_ptr<HilClient>> HilClient::connect(const std::string& address,
                                                      std::uint16_t port) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  if (::inet_pton(AF_INET, address.c_str(), &addr.sin_addr) != 1) {
    return Status(ErrorCode::kInvalidArgument, "hil: board address is not an IPv4 address");
  }
  std::unique_ptr<HilClient> c(new HilClient());
  c->fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (c->fd_ < 0) return Status(ErrorCode::kIoError, "hil: socket", errno);
  if (::connect(c->fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    return Status(ErrorCode::kUnavailable, "hil: connect", errno);
  }
  const int one = 1;
  (void)::setsockopt(c->fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return c;
}

HilClient::~HilClient() {
  if (fd_ >= 0) ::close(fd_);
}

Status HilClient::send(std::span<const std::uint8_t> bytes) {
  if (fd_ < 0) return Status(ErrorCode::kFailedPrecondition, "hil: connection closed");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Status(ErrorCode::kIoError, "hil: send", errno);
    }
    done += static_cast<std::size_t>(n);
  }
  return Status::ok();
}

Status HilClient::receive(std::int64_t timeout_ns, std::vector<hil::Frame>& out) {
  if (fd_ < 0) return Status(ErrorCode::kFailedPrecondition, "hil: connection closed");
  if (!wait_fd(fd_, POLLIN, now_ns() + timeout_ns)) {
    return Status(ErrorCode::kTimeout, "hil: nothing from the board");
  }
  std::array<std::uint8_t, 65536> buf{};
  const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
  if (n < 0) {
    if (errno == EINTR || errno == EAGAIN) return Status::ok();
    return Status(ErrorCode::kIoError, "hil: receive", errno);
  }
  if (n == 0) return Status(ErrorCode::kUnavailable, "hil: the board closed the connection");
  rx_.insert(rx_.end(), buf.begin(), buf.begin() + n);
  std::size_t at = 0;
  Status st = Status::ok();
  for (;;) {
    const hil::ParseResult pr =
        hil::parse(std::span<const std::uint8_t>(rx_.data() + at, rx_.size() - at));
    if (pr.error == hil::ParseError::kNeedMore) break;
    if (pr.error != hil::ParseError::kNone) {
      st = Status(ErrorCode::kDataLoss, hil::to_string(pr.error));
      if (pr.error != hil::ParseError::kBadCrc) {
        rx_.clear();
        return st;  // out of step: nothing after this can be trusted
      }
      at += pr.used;
      continue;
    }
    out.push_back(pr.frame);
    at += pr.used;
  }
  rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(at));
  return st;
}

void HilClient::abort() {
  if (fd_ < 0) return;
  const linger l{1, 0};  // SO_LINGER 0: close sends RST (socket(7))
  (void)::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &l, sizeof l);
  ::close(fd_);
  fd_ = -1;
}

}  // namespace gfins::drivers::lnx
