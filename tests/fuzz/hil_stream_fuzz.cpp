// libFuzzer target: the hardware-in-the-loop stream (drivers/lnx/hil_link.hpp, docs/hil.md),
// parsed frame by frame as the firmware (samples, CAN frames to receive) and the host
// (acknowledgements, CAN frames)
// read it. When the first input byte is odd the harness writes each frame's CRC-32 first, so the
// fuzzer reaches the fields behind it. A CRC failure skips the frame, any other error ends the
// stream (the link closes the connection), as the link does.
// Invariants: a frame that parses is exactly the bytes the encoder writes for what was decoded
// (no field the protocol does not define is accepted: unknown verdicts, CAN lengths over 8,
// non-zero padding, which are refused as malformed); a framing error consumes nothing, a whole
// frame refused (CRC, malformed) is its length.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "fuzz_check.hpp"
#include "gfins/drivers/lnx/hil_link.hpp"

namespace {

constexpr const char* kTarget = "hil_stream";
namespace hil = gfins::drivers::lnx::hil;

void seal(std::span<std::uint8_t> b) {
  if (b.size() < hil::kHeaderBytes || b[0] != hil::kMagic0 || b[1] != hil::kMagic1) return;
  const std::size_t n = hil::frame_bytes(b[2]);
  if (n == 0 || b[3] != n || b.size() < n) return;
  const std::uint32_t c = hil::crc32(b.first(n - 4));
  for (std::size_t i = 0; i < 4; ++i) b[n - 4 + i] = static_cast<std::uint8_t>(c >> (8 * i));
}

bool same(std::span<const std::uint8_t> wire, std::span<const std::uint8_t> bytes) {
  return wire.size() == bytes.size() && std::memcmp(wire.data(), bytes.data(), wire.size()) == 0;
}

void check_round_trip(const hil::Frame& f, std::span<const std::uint8_t> bytes) {
  switch (f.type) {
    case hil::FrameType::kSample:
    case hil::FrameType::kLastSample: {
      const auto w = hil::encode_sample(f.index, f.sample, f.type == hil::FrameType::kLastSample);
      gfins::fuzz::check(same(w, bytes), kTarget, "a sample frame re-encodes to its bytes");
      break;
    }
    case hil::FrameType::kAck:
      gfins::fuzz::check(same(hil::encode_ack(f.index, f.verdict), bytes), kTarget,
                         "an acknowledgement re-encodes to its bytes");
      break;
    case hil::FrameType::kCan:
    case hil::FrameType::kCanIn:
      gfins::fuzz::check(same(hil::encode_can(f.can, f.type), bytes), kTarget,
                         "a CAN frame re-encodes to its bytes, with its direction");
      break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool sealed = (data[0] & 1u) != 0;
  std::vector<std::uint8_t> bytes(data + 1, data + size);
  std::size_t pos = 0;
  while (pos < bytes.size()) {
    const std::span<std::uint8_t> rest(bytes.data() + pos, bytes.size() - pos);
    if (sealed) seal(rest);
    const hil::ParseResult r = hil::parse(rest);
    if (r.error == hil::ParseError::kNone) {
      gfins::fuzz::check(r.used == hil::frame_bytes(rest[2]) && r.used <= rest.size(), kTarget,
                         "a frame uses its length");
      check_round_trip(r.frame, rest.first(r.used));
    } else if (r.error == hil::ParseError::kBadCrc || r.error == hil::ParseError::kMalformed) {
      gfins::fuzz::check(r.used == hil::frame_bytes(rest[2]) && r.used <= rest.size(), kTarget,
                         "a whole frame refused is its length");
      if (r.error == hil::ParseError::kMalformed) break;  // the link closes the connection
    } else {
      gfins::fuzz::check(r.used == 0, kTarget, "a framing error consumes nothing");
      break;
    }
    pos += r.used;
  }
  return 0;
}
