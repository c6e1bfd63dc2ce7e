// Hardware-in-the-loop replay link (docs/hil.md): the host streams raw samples to the firmware
// over one TCP connection in place of the ADC, the firmware answers with an acknowledgement per
// sample and the CAN frames it publishes, on the same connection.
//
// Wire frames, little-endian, each: 'G' 'H' type length ... CRC-32 (IEEE 802.3, reflected poly
// 0xEDB88320, init/xorout 0xFFFFFFFF) over every byte before it. Flow control is by sample index:
// the host keeps at most `window` samples unacknowledged; time never drives the replay.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "gfins/hal/can_bus.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

namespace hil {

enum class FrameType : std::uint8_t {
  kSample = 1,      // host -> fw: index, RawSample
  kLastSample = 2,  // host -> fw: the same, and the stream ends after it
  kAck = 3,         // fw -> host: index, verdict
  kCan = 4,         // fw -> host: one CAN frame the firmware published
  kCanIn = 5,       // host -> fw: one CAN frame for the loop to receive in the cycle of the
                    // next sample frame (a recording's aiding inputs, docs/hil.md)
};

enum class AckVerdict : std::uint8_t { kOk = 0, kBadCrc = 1 };

inline constexpr std::uint8_t kMagic0 = 'G';
inline constexpr std::uint8_t kMagic1 = 'H';
inline constexpr std::size_t kHeaderBytes = 4;
// header + index u32 + seq u32 + t_ns i64 + 6 × counts i32 + flags u32 + CRC u32
inline constexpr std::size_t kSampleBytes = 4 + 4 + 4 + 8 + 24 + 4 + 4;
// header + index u32 + verdict u8 + 3 pad + CRC u32
inline constexpr std::size_t kAckBytes = 4 + 4 + 4 + 4;
// header + id u32 (bit 31: extended) + len u8 + 3 pad + data 8 + CRC u32
inline constexpr std::size_t kCanBytes = 4 + 4 + 4 + 8 + 4;
inline constexpr std::size_t kMaxFrameBytes = kSampleBytes;
static_assert(kSampleBytes == 52 && kAckBytes == 16 && kCanBytes == 24);

std::uint32_t crc32(std::span<const std::uint8_t> bytes);

using SampleWire = std::array<std::uint8_t, kSampleBytes>;
using AckWire = std::array<std::uint8_t, kAckBytes>;
using CanWire = std::array<std::uint8_t, kCanBytes>;

SampleWire encode_sample(std::uint32_t index, const RawSample& s, bool last);
AckWire encode_ack(std::uint32_t index, AckVerdict v);
/// A CAN frame on the link: `type` kCan (published by the firmware) or kCanIn (for it to receive).
CanWire encode_can(const hal::CanFrame& f, FrameType type = FrameType::kCan);

/// Expected total length of a frame of this type (0: unknown type).
std::size_t frame_bytes(std::uint8_t type);

/// One decoded frame of any type.
struct Frame {
  FrameType type = FrameType::kSample;
  std::uint32_t index = 0;
  RawSample sample{};
  AckVerdict verdict = AckVerdict::kOk;
  hal::CanFrame can{};
};

// kMalformed: the CRC holds but a field has a value the encoder never writes (an unknown
// verdict, a CAN length over 8 or an identifier beyond its format, non-zero padding).
enum class ParseError : std::uint8_t {
  kNone,
  kNeedMore,
  kBadMagic,
  kBadType,
  kBadLength,
  kBadCrc,
  kMalformed,
};
const char* to_string(ParseError e);

struct ParseResult {
  ParseError error = ParseError::kNone;
  std::size_t used = 0;  // bytes consumed (the frame's length for kBadCrc and kMalformed)
  Frame frame{};
};
/// Parses the frame at the start of `bytes`.
ParseResult parse(std::span<const std::uint8_t> bytes);

}  // namespace hil

struct HilServerConfig {
  std::string address = "127.0.0.1";  // IPv4 address to listen on
  std::uint16_t port = 0;             // 0: an ephemeral port (see HilServer::port())
};

/// What the firmware side counts (cumulative).
struct HilCounters {
  std::uint32_t connections = 0;   // accepted
  std::uint32_t drops = 0;         // connections that ended before their last sample
  std::uint32_t samples = 0;       // delivered to the loop
  std::uint32_t crc_errors = 0;    // sample frames with a bad CRC (skipped, NAKed)
  std::uint32_t frame_errors = 0;  // bad magic / type / length (the connection is closed)
  std::uint32_t can_sent = 0;      // CAN frames written back
  std::uint32_t can_dropped = 0;   // CAN frames not written (no connection, socket full)
  std::uint32_t can_in = 0;        // CAN frames from the host handed to the loop's receive
  std::uint32_t can_in_lost = 0;   // CAN frames from the host never received: the queue was
                                   // full, or the connection ended before their sample
};

/// Frames from the host wait here until the sample frame after them has been read; the loop's
/// receive() then takes them in that sample's cycle (never in an earlier cycle: a data-ready
/// timeout between a frame and its sample must not hand the frame over early).
inline constexpr std::size_t kCanInQueue = 64;

/// The firmware end: listens, accepts one host at a time, hands its samples to the loop,
/// acknowledges each, and is the loop's CAN bus (frames go back on the connection).
class HilServer {
 public:
  static Result<std::unique_ptr<HilServer>> open(const HilServerConfig& c);
  ~HilServer();
  HilServer(const HilServer&) = delete;
  HilServer& operator=(const HilServer&) = delete;

  std::uint16_t port() const { return port_; }
  /// The next sample of the stream (waits at most timeout_ns for a host or for data).
  /// kTimeout: nothing arrived; kDataLoss: a sample frame with a bad CRC (skipped);
  /// kIoError: the connection dropped or sent an unparseable frame (closed; a new host may
  /// connect).
  Result<RawSample> read_sample(std::int64_t timeout_ns);
  /// A host is connected.
  bool connected() const { return conn_fd_ >= 0; }
  /// The stream's last sample was delivered.
  bool finished() const { return finished_; }
  const HilCounters& counters() const { return counters_; }
  /// Text of the last connection event (drop, bad frame) for the log; "" when none.
  const char* last_event() const { return last_event_.data(); }
  /// The loop's CAN bus: frames go to the host on the connection; receive() gives the host's
  /// kCanIn frames in the cycle of the sample they precede.
  hal::CanBus& bus();

 private:
  HilServer() = default;
  class Bus;
  void drop(const char* why, int os_error = 0);
  bool send_bytes(std::span<const std::uint8_t> b);
  void queue_can_in(const hal::CanFrame& f);
  bool take_can_in(hal::CanFrame& out);
  void forget_pending_can_in();

  int listen_fd_ = -1;
  int conn_fd_ = -1;
  std::uint16_t port_ = 0;
  bool finished_ = false;
  std::uint32_t expected_index_ = 0;
  std::vector<std::uint8_t> rx_;  // received, not yet parsed (start-up allocation)
  std::size_t rx_len_ = 0;
  HilCounters counters_{};
  std::array<char, 192> last_event_{};
  std::unique_ptr<Bus> bus_;
  // Ring of host frames: [head_, head_ + ready_) may be received, the next pending_ wait for
  // their sample frame.
  std::array<hal::CanFrame, kCanInQueue> can_in_{};
  std::size_t can_in_head_ = 0;
  std::size_t can_in_ready_ = 0;
  std::size_t can_in_pending_ = 0;
};

/// The host end: a blocking TCP client.
class HilClient {
 public:
  static Result<std::unique_ptr<HilClient>> connect(const std::string& address, std::uint16_t port);
  ~HilClient();
  HilClient(const HilClient&) = delete;
  HilClient& operator=(const HilClient&) = delete;
  Status send(std::span<const std::uint8_t> bytes);
  /// Frames received within timeout_ns (appended to `out`); kTimeout when none came,
  /// kUnavailable when the peer closed, kIoError on a socket error or an unparseable frame
  /// (ParseError in the message).
  Status receive(std::int64_t timeout_ns, std::vector<hil::Frame>& out);
  /// Closes with a reset (RST), as a killed process or a pulled cable would look to the peer.
  void abort();

 private:
  HilClient() = default;
  int fd_ = -1;
  std::vector<std::uint8_t> rx_;
};

}  // namespace gfins::drivers::lnx
