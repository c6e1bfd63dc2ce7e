#include "gfins/can/aiding_input.hpp"

#include <cmath>

#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

/// The physical value of a signal, or NaN when it is the not-available code or beyond
/// [min, max] (an input value the board cannot trust).
double checked(const SignalDef& s, std::uint64_t p) {
  const double x = decode_signal(s, extract_bits(p, s));
  if (!std::isfinite(x) || x < s.min || x > s.max) return std::nan("");
  return x;
}

/// True when every value signal of the frame carries its not-available code: the sender states
/// that part of the fix is absent (a velocity-only fix sends its position frames so).
bool all_not_available(const MessageDef& m, std::uint64_t p) {
  for (const SignalDef& s : m.signals) {
    if (s.field == Field::kCounter || s.field == Field::kCrc) continue;
    if (!s.has_na || raw_value(s, extract_bits(p, s)) != s.na_raw) return false;
  }
  return true;
}

hal::CanFrame frame_of(MessageId id, std::uint8_t node_id, const IdBases& ids, std::uint64_t p,
                       std::uint8_t counter) {
  hal::CanFrame f;
  f.id = can_id(id, node_id, ids);
  f.len = kFrameLength;
  const MessageDef& m = message(id);
  p = insert_bits(p, signal_of(m, Field::kCounter), counter);
  set_payload(f, p);
  seal_frame(f);
  return f;
}

constexpr std::uint8_t kContentPosition = 1;
constexpr std::uint8_t kContentVelocity = 2;

}  // namespace

const char* to_string(InputReject r) {
  switch (r) {
    case InputReject::kNone:
      return "accepted";
    case InputReject::kBadLength:
      return "bad length";
    case InputReject::kBadCrc:
      return "bad CRC";
    case InputReject::kStale:
      return "stale id";
    case InputReject::kOutOfRange:
      return "out of range";
    case InputReject::kMalformed:
      return "malformed";
    case InputReject::kMixedFix:
      return "mixed fix ids";
    case InputReject::kIncomplete:
      return "incomplete fix";
    case InputReject::kCount_:
      break;
  }
  return "?";
}

std::uint32_t InputCounters::total_rejected() const {
  std::uint32_t n = 0;
  for (std::uint32_t v : rejected) n += v;
  return n;
}

Result<InputEvent> InputDecoder::reject(InputReject why, ErrorCode code, const char* what) {
  last_reject_ = why;
  ++counters_.rejected[static_cast<std::size_t>(why)];
  return Status(code, what);
}

bool is_input_frame(const hal::CanFrame& f, std::uint8_t node_id, const IdBases& ids) {
  std::uint8_t node = 0;
  const MessageDef* m = f.extended ? nullptr : find_message(f.id, ids, &node);
  return m != nullptr && m->kind == MessageKind::kInput && node == node_id;
}

Result<InputEvent> InputDecoder::add(const hal::CanFrame& f) {
  if (!is_input_frame(f, node_id_, ids_)) return InputEvent{};
  std::uint8_t node = 0;
  const MessageDef* m = find_message(f.id, ids_, &node);
  last_reject_ = InputReject::kNone;
  if (f.len != kFrameLength) {
    partial_open_ = false;
    return reject(InputReject::kBadLength, ErrorCode::kDataLoss, "input: length is not 8");
  }
  if (!crc_ok(f)) {
    // A corrupted frame of a fix spoils the fix: its FixInfo will find the frame missing.
    return reject(InputReject::kBadCrc, ErrorCode::kDataLoss, "input: CRC-8 mismatch");
  }
  const std::uint64_t p = payload_of(f);
  if ((p & ~used_bits(*m)) != 0) {
    partial_open_ = false;
    return reject(InputReject::kMalformed, ErrorCode::kInvalidArgument,
                  "input: reserved bits are not zero");
  }
  const auto counter = static_cast<std::uint8_t>(extract_bits(p, signal_of(*m, Field::kCounter)));
  if (m->id == MessageId::kHeadingInput) return add_heading(p, counter);
  return add_gnss(*m, p, counter);
}

Result<InputEvent> InputDecoder::add_heading(std::uint64_t p, std::uint8_t seq) {
  const MessageDef& m = message(MessageId::kHeadingInput);
  if (seq == last_heading_seq_) {
    return reject(InputReject::kStale, ErrorCode::kFailedPrecondition,
                  "input: heading sequence repeats the last accepted one");
  }
  InputEvent e;
  e.kind = InputEventKind::kHeadingFix;
  e.heading.sequence = seq;
  e.heading.heading_rad = checked(signal_of(m, Field::kInHeading), p);
  e.heading.sigma_rad = checked(signal_of(m, Field::kInHeadingSigma), p);
  e.heading.age_s = checked(signal_of(m, Field::kInHeadingAge), p);
  if (std::isnan(e.heading.heading_rad) || std::isnan(e.heading.sigma_rad) ||
      std::isnan(e.heading.age_s)) {
    return reject(InputReject::kOutOfRange, ErrorCode::kOutOfRange,
                  "input: heading value out of range or not available");
  }
  last_heading_seq_ = seq;
  ++counters_.headings;
  return e;
}

Result<InputEvent> InputDecoder::add_gnss(const MessageDef& m, std::uint64_t p, std::uint8_t id) {
  if (partial_open_ && id != partial_.fix_id) {
    // A frame of another fix while one is open: the open fix can no longer complete.
    partial_open_ = false;
    if (m.id != MessageId::kGnssPositionNE) {
      return reject(InputReject::kMixedFix, ErrorCode::kFailedPrecondition,
                    "input: frames of one GNSS fix carry different fix ids");
    }
  }
  if (id == last_fix_id_) {
    partial_open_ = false;
    return reject(InputReject::kStale, ErrorCode::kFailedPrecondition,
                  "input: GNSS fix id repeats the last accepted fix");
  }
  if (!partial_open_) {
    partial_ = GnssFix{};
    partial_.fix_id = id;
    partial_open_ = true;
    have_ne_ = have_d_ = have_vel_ = false;
  }
  const auto out_of_range = [this] {
    partial_open_ = false;
    return reject(InputReject::kOutOfRange, ErrorCode::kOutOfRange,
                  "input: GNSS value out of range or not available");
  };
  InputEvent pending;
  pending.kind = InputEventKind::kPending;
  // A position or velocity frame with every value not available says "this fix has no such
  // part": stored as absent, not an error (FixInfo's content then must not claim it).
  if (m.id != MessageId::kGnssFixInfo && all_not_available(m, p)) return pending;
  switch (m.id) {
    case MessageId::kGnssPositionNE:
      partial_.r_n_m[0] = checked(signal_of(m, Field::kInGnssPos, 0), p);
      partial_.r_n_m[1] = checked(signal_of(m, Field::kInGnssPos, 1), p);
      if (std::isnan(partial_.r_n_m[0]) || std::isnan(partial_.r_n_m[1])) return out_of_range();
      have_ne_ = true;
      return pending;
    case MessageId::kGnssPositionD:
      partial_.r_n_m[2] = checked(signal_of(m, Field::kInGnssPos, 2), p);
      partial_.sigma_pos_h_m = checked(signal_of(m, Field::kInGnssSigmaPosH), p);
      partial_.sigma_pos_v_m = checked(signal_of(m, Field::kInGnssSigmaPosV), p);
      if (std::isnan(partial_.r_n_m[2]) || std::isnan(partial_.sigma_pos_h_m) ||
          std::isnan(partial_.sigma_pos_v_m)) {
        return out_of_range();
      }
      have_d_ = true;
      return pending;
    case MessageId::kGnssVelocity:
      for (std::uint8_t i = 0; i < 3; ++i) {
        partial_.v_n_mps[i] = checked(signal_of(m, Field::kInGnssVel, i), p);
        if (std::isnan(partial_.v_n_mps[i])) return out_of_range();
      }
      have_vel_ = true;
      return pending;
    default:
      break;
  }
  // FixInfo: completes the fix.
  partial_open_ = false;
  const auto content =
      static_cast<std::uint8_t>(extract_bits(p, signal_of(m, Field::kInGnssContent)));
  partial_.has_position = (content & kContentPosition) != 0;
  partial_.has_velocity = (content & kContentVelocity) != 0;
  if (content == 0) {
    return reject(InputReject::kMalformed, ErrorCode::kInvalidArgument,
                  "input: GNSS fix states neither position nor velocity");
  }
  partial_.age_s = checked(signal_of(m, Field::kInGnssAge), p);
  if (std::isnan(partial_.age_s)) return out_of_range();
  if (partial_.has_velocity) {
    partial_.sigma_vel_mps = checked(signal_of(m, Field::kInGnssSigmaVel), p);
    if (std::isnan(partial_.sigma_vel_mps)) return out_of_range();
  }
  if ((partial_.has_position && !(have_ne_ && have_d_)) || (partial_.has_velocity && !have_vel_)) {
    return reject(InputReject::kIncomplete, ErrorCode::kFailedPrecondition,
                  "input: GNSS fix info without the frames its content needs");
  }
  if (!partial_.has_position) {
    partial_.r_n_m = {};
    partial_.sigma_pos_h_m = partial_.sigma_pos_v_m = 0.0;
  }
  if (!partial_.has_velocity) partial_.v_n_mps = {};
  last_fix_id_ = partial_.fix_id;
  ++counters_.gnss_fixes;
  InputEvent e;
  e.kind = InputEventKind::kGnssFix;
  e.gnss = partial_;
  return e;
}

std::array<hal::CanFrame, 4> encode_gnss_fix(const GnssFix& fix, std::uint8_t node_id,
                                             const IdBases& ids) {
  const double na = std::nan("");
  const std::uint8_t id = fix.fix_id & 0x0Fu;
  const auto pos = [&](std::size_t i) { return fix.has_position ? fix.r_n_m[i] : na; };
  const auto vel = [&](std::size_t i) { return fix.has_velocity ? fix.v_n_mps[i] : na; };

  const MessageDef& ne = message(MessageId::kGnssPositionNE);
  std::uint64_t p = put_signal(0, signal_of(ne, Field::kInGnssPos, 0), pos(0));
  p = put_signal(p, signal_of(ne, Field::kInGnssPos, 1), pos(1));
  const hal::CanFrame f_ne = frame_of(MessageId::kGnssPositionNE, node_id, ids, p, id);

  const MessageDef& d = message(MessageId::kGnssPositionD);
  p = put_signal(0, signal_of(d, Field::kInGnssPos, 2), pos(2));
  p = put_signal(p, signal_of(d, Field::kInGnssSigmaPosH),
                 fix.has_position ? fix.sigma_pos_h_m : na);
  p = put_signal(p, signal_of(d, Field::kInGnssSigmaPosV),
                 fix.has_position ? fix.sigma_pos_v_m : na);
  const hal::CanFrame f_d = frame_of(MessageId::kGnssPositionD, node_id, ids, p, id);

  const MessageDef& v = message(MessageId::kGnssVelocity);
  p = 0;
  for (std::uint8_t i = 0; i < 3; ++i)
    p = put_signal(p, signal_of(v, Field::kInGnssVel, i), vel(i));
  const hal::CanFrame f_v = frame_of(MessageId::kGnssVelocity, node_id, ids, p, id);

  const MessageDef& info = message(MessageId::kGnssFixInfo);
  p = put_signal(0, signal_of(info, Field::kInGnssSigmaVel),
                 fix.has_velocity ? fix.sigma_vel_mps : na);
  p = put_signal(p, signal_of(info, Field::kInGnssAge), fix.age_s);
  const auto content = static_cast<std::uint8_t>((fix.has_position ? kContentPosition : 0) |
                                                 (fix.has_velocity ? kContentVelocity : 0));
  p = insert_bits(p, signal_of(info, Field::kInGnssContent), content);
  const hal::CanFrame f_info = frame_of(MessageId::kGnssFixInfo, node_id, ids, p, id);
  return {f_ne, f_d, f_v, f_info};
}

hal::CanFrame encode_heading_fix(const HeadingFix& h, std::uint8_t node_id, const IdBases& ids) {
  const MessageDef& m = message(MessageId::kHeadingInput);
  std::uint64_t p = put_signal(0, signal_of(m, Field::kInHeading), h.heading_rad);
  p = put_signal(p, signal_of(m, Field::kInHeadingSigma), h.sigma_rad);
  p = put_signal(p, signal_of(m, Field::kInHeadingAge), h.age_s);
  return frame_of(MessageId::kHeadingInput, node_id, ids, p, h.sequence & 0x0Fu);
}

}  // namespace gfins::can
