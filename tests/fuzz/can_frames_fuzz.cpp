// libFuzzer target: the CAN frames the board accepts from the bus: commands (can::decode_command,
// docs/can-interface.md "Commands") and aiding inputs (can::InputDecoder: GNSS fix parts,
// heading). The input is a sequence of 11-byte records: identifier selector, length and CRC
// choice, 8 data bytes, then 1 unused byte. The selector picks the command or one of the input
// messages of node 1, or a raw 11-bit identifier; most frames get their CRC-8 (else the fuzzer
// never passes the check).
// Invariants: an accepted command, encoded again by the host's encoder, is the same 8 bytes (the
// decoder accepts exactly what the encoder writes, nothing it would not); a refusal names an
// opcode and a result code from the ICD; a GNSS fix or heading accepted has finite values and
// positive, finite σ where it has the part, and the decoder's counters add up.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz_check.hpp"
#include "gfins/can/aiding_input.hpp"
#include "gfins/can/command.hpp"
#include "gfins/can/signal_codec.hpp"

namespace {

constexpr const char* kTarget = "can_frames";
constexpr std::uint8_t kNode = 1;
namespace can = gfins::can;

constexpr can::MessageId kTargets[] = {
    can::MessageId::kCommand,      can::MessageId::kGnssPositionNE, can::MessageId::kGnssPositionD,
    can::MessageId::kGnssVelocity, can::MessageId::kGnssFixInfo,    can::MessageId::kHeadingInput,
};

void command(const gfins::hal::CanFrame& f) {
  const can::DecodedCommand d = can::decode_command(f, kNode);
  if (!d.addressed) return;
  if (!d.ok()) {
    gfins::fuzz::check(d.error.code != can::ResultCode::kOk, kTarget, "a refusal has a code");
    gfins::fuzz::check(std::string_view(can::to_string(d.error.code)) != "Unknown", kTarget,
                       "a refusal's code is one of the ICD's");
    return;
  }
  const gfins::hal::CanFrame again = can::encode_command(d.command, kNode);
  gfins::fuzz::check(again.id == f.id && again.len == f.len && again.data == f.data, kTarget,
                     "an accepted command re-encodes to the same bytes");
}

void positive_sigma(double s) {
  gfins::fuzz::check(std::isfinite(s) && s > 0.0, kTarget, "a stated σ is positive and finite");
}

void input(can::InputDecoder& dec, const gfins::hal::CanFrame& f) {
  const auto r = dec.add(f);
  if (!r.is_ok()) {
    gfins::fuzz::check(dec.last_reject() != can::InputReject::kNone, kTarget,
                       "a rejected input names its reason");
    return;
  }
  const can::InputEvent& e = r.value();
  if (e.kind == can::InputEventKind::kGnssFix) {
    const can::GnssFix& g = e.gnss;
    gfins::fuzz::check(g.has_position || g.has_velocity, kTarget, "a fix has content");
    if (g.has_position) {
      for (const double x : g.r_n_m) gfins::fuzz::check(std::isfinite(x), kTarget, "finite r");
      positive_sigma(g.sigma_pos_h_m);
      positive_sigma(g.sigma_pos_v_m);
    }
    if (g.has_velocity) {
      for (const double x : g.v_n_mps) gfins::fuzz::check(std::isfinite(x), kTarget, "finite v");
      positive_sigma(g.sigma_vel_mps);
    }
    gfins::fuzz::check(std::isfinite(g.age_s) && g.age_s >= 0.0, kTarget, "a fix's age");
  } else if (e.kind == can::InputEventKind::kHeadingFix) {
    const can::HeadingFix& h = e.heading;
    gfins::fuzz::check(std::isfinite(h.heading_rad) && std::fabs(h.heading_rad) <= M_PI + 1e-9,
                       kTarget, "a heading within ±π");
    positive_sigma(h.sigma_rad);
    gfins::fuzz::check(std::isfinite(h.age_s) && h.age_s >= 0.0, kTarget, "a heading's age");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  gfins::fuzz::Bytes in(data, size);
  can::InputDecoder dec(kNode);
  std::uint64_t frames = 0;
  while (!in.empty()) {
    const std::uint8_t selector = in.u8();
    const std::uint8_t shape = in.u8();
    gfins::hal::CanFrame f;
    constexpr std::size_t kChoices = sizeof kTargets / sizeof kTargets[0];
    f.id = selector < 0xF0 ? can::can_id(kTargets[selector % kChoices], kNode)
                           : (static_cast<std::uint32_t>(selector & 0x0F) << 7) | (shape >> 1);
    f.len = (shape & 0x80u) != 0 ? static_cast<std::uint8_t>(shape & 0x0F) : can::kFrameLength;
    if (f.len > 8) f.len = 8;
    in.fill(f.data);
    in.u8();
    if ((shape & 0x01u) == 0) can::seal_frame(f);
    command(f);
    input(dec, f);
    ++frames;
  }
  const can::InputCounters& c = dec.counters();
  gfins::fuzz::check(std::uint64_t{c.gnss_fixes} + c.headings + c.total_rejected() <= frames,
                     kTarget, "the input counters count frames");
  return 0;
}
