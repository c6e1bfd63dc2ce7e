#include "gfins/can/command.hpp"

#include <cmath>

#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

const MessageDef& cmd_def() { return message(MessageId::kCommand); }
const MessageDef& rsp_def() { return message(MessageId::kResponse); }

DecodedCommand fail(DecodedCommand d, ResultCode code, const char* what) {
  d.error.code = code;
  d.error.message = what;
  return d;
}

bool in_range(const SignalDef& s, double x) { return x >= s.min && x <= s.max; }

}  // namespace

const char* to_string(ResultCode r) {
  for (const ValueName& v : kResultValues) {
    if (v.raw == static_cast<std::int64_t>(r)) return v.name.data();
  }
  return "Unknown";
}

const char* to_string(Opcode op) {
  for (const ValueName& v : kOpcodeValues) {
    if (v.raw == static_cast<std::int64_t>(op)) return v.name.data();
  }
  return "Unknown";
}

DecodedCommand decode_command(const hal::CanFrame& f, std::uint8_t node_id, const IdBases& ids) {
  DecodedCommand d;
  if (f.extended || f.id != can_id(MessageId::kCommand, node_id, ids)) return d;
  d.addressed = true;
  if (f.len >= 1) d.error.opcode = f.data[0];
  if (f.len >= 2) d.error.token = f.data[1];
  if (f.len != kFrameLength) return fail(d, ResultCode::kBadLength, "command: length is not 8");
  if (!crc_ok(f)) return fail(d, ResultCode::kBadCrc, "command: CRC-8 mismatch");
  const std::uint64_t p = payload_of(f);
  const std::uint8_t op = d.error.opcode;
  bool known = false;
  for (const ValueName& v : kOpcodeValues) known = known || v.raw == op;
  if (!known) return fail(d, ResultCode::kUnknownOpcode, "command: unknown opcode");
  if ((p & ~used_bits(cmd_def(), op)) != 0) {
    return fail(d, ResultCode::kMalformed, "command: bits the opcode does not use are not zero");
  }
  Command& c = d.command;
  c.opcode = static_cast<Opcode>(op);
  c.token = d.error.token;
  // Every argument of this opcode must decode (not the N/A code) and lie within [min, max].
  for (const SignalDef& s : cmd_def().signals) {
    if (s.mux != op) continue;
    const double x = decode_signal(s, extract_bits(p, s));
    if (!std::isfinite(x) || !in_range(s, x)) {
      return fail(d, ResultCode::kOutOfRange, "command: argument out of range");
    }
    switch (s.field) {
      case Field::kCmdHeading:
        c.heading_rad = static_cast<float>(x);
        break;
      case Field::kCmdCompensator:
        c.compensator = static_cast<nav::CompensatorKind>(x);
        break;
      case Field::kCmdMessage:
        c.message = static_cast<MessageId>(x);
        break;
      case Field::kCmdDivider:
        c.divider = static_cast<std::uint16_t>(x);
        break;
      case Field::kCmdPose:
        c.pose = static_cast<std::uint8_t>(x);
        break;
      case Field::kCmdSamples:
        c.samples = static_cast<std::uint16_t>(x);
        break;
      case Field::kCmdForced:
        c.forced = x != 0.0;
        break;
      case Field::kCmdSequence:
        c.sequence = static_cast<std::uint16_t>(x);
        break;
      case Field::kCmdNodeId:
        c.node_id = static_cast<std::uint8_t>(x);
        break;
      case Field::kCmdIdGroup:
        c.id_group = static_cast<IdGroup>(x);
        break;
      case Field::kCmdIdBase:
        c.id_base = static_cast<std::uint16_t>(x);
        break;
      default:
        break;
    }
  }
  if (c.opcode == Opcode::kSetDivider && message(c.message).kind != MessageKind::kData) {
    return fail(d, ResultCode::kOutOfRange, "command: SetDivider of a non-data message");
  }
  return d;
}

hal::CanFrame encode_command(const Command& c, std::uint8_t node_id, const IdBases& ids) {
  const MessageDef& m = cmd_def();
  hal::CanFrame f;
  f.id = can_id(MessageId::kCommand, node_id, ids);
  f.len = kFrameLength;
  std::uint64_t p = 0;
  const auto op = static_cast<std::uint8_t>(c.opcode);
  p = insert_bits(p, signal_of(m, Field::kCmdOpcode), op);
  p = insert_bits(p, signal_of(m, Field::kCmdToken), c.token);
  switch (c.opcode) {
    case Opcode::kRealign: {
      const SignalDef& s = signal_of(m, Field::kCmdHeading);
      p = insert_bits(p, s, bits_of(s, raw_of_physical(s, static_cast<double>(c.heading_rad))));
      p = insert_bits(p, signal_of(m, Field::kCmdForced, 0, kOpRealign), c.forced ? 1u : 0u);
      break;
    }
    case Opcode::kResetNavigation:
      p = insert_bits(p, signal_of(m, Field::kCmdForced, 0, kOpResetNavigation),
                      c.forced ? 1u : 0u);
      break;
    case Opcode::kSetCompensator:
      p = insert_bits(p, signal_of(m, Field::kCmdCompensator),
                      static_cast<std::uint8_t>(c.compensator));
      break;
    case Opcode::kSetDivider:
      p = insert_bits(p, signal_of(m, Field::kCmdMessage), static_cast<std::uint8_t>(c.message));
      p = insert_bits(p, signal_of(m, Field::kCmdDivider), c.divider);
      break;
    case Opcode::kStartCapture:
      p = insert_bits(p, signal_of(m, Field::kCmdPose), c.pose);
      p = insert_bits(p, signal_of(m, Field::kCmdSamples), c.samples);
      break;
    case Opcode::kReloadCalibration:
      p = insert_bits(p, signal_of(m, Field::kCmdForced, 0, kOpReloadCalibration),
                      c.forced ? 1u : 0u);
      break;
    case Opcode::kSetNodeId:
      p = insert_bits(p, signal_of(m, Field::kCmdNodeId), c.node_id);
      break;
    case Opcode::kSetIdBase:
      p = insert_bits(p, signal_of(m, Field::kCmdIdGroup), static_cast<std::uint8_t>(c.id_group));
      p = insert_bits(p, signal_of(m, Field::kCmdIdBase), c.id_base);
      break;
    default:
      break;
  }
  if (carries_sequence(c.opcode)) {
    p = insert_bits(p, signal_of(m, Field::kCmdSequence, 0, static_cast<std::int16_t>(op)),
                    c.sequence);
  }
  set_payload(f, p);
  seal_frame(f);
  return f;
}

namespace {
hal::CanFrame response_frame(std::uint8_t opcode, std::uint8_t token, std::uint8_t part,
                             std::uint64_t body, std::uint8_t node_id, const IdBases& ids) {
  const MessageDef& m = rsp_def();
  hal::CanFrame f;
  f.id = can_id(MessageId::kResponse, node_id, ids);
  f.len = kFrameLength;
  std::uint64_t p = body;
  p = insert_bits(p, signal_of(m, Field::kRspOpcode), opcode);
  p = insert_bits(p, signal_of(m, Field::kRspToken), token);
  p = insert_bits(p, signal_of(m, Field::kRspPart), part);
  set_payload(f, p);
  seal_frame(f);
  return f;
}

}  // namespace

hal::CanFrame encode_response(const Response& r, std::uint8_t node_id, const IdBases& ids) {
  const MessageDef& m = rsp_def();
  std::uint64_t p = 0;
  p = insert_bits(p, signal_of(m, Field::kRspResult), static_cast<std::uint8_t>(r.result));
  p = insert_bits(p, signal_of(m, Field::kRspValue), r.value);
  return response_frame(r.opcode, r.token, kPartStatus, p, node_id, ids);
}

hal::CanFrame encode_calibration_id_response(std::uint8_t token, std::uint32_t cal_id,
                                             std::uint8_t node_id, const IdBases& ids) {
  const std::uint64_t p = insert_bits(0, signal_of(rsp_def(), Field::kRspCalId), cal_id);
  return response_frame(kOpReportCalibrationId, token, kPartCalibrationId, p, node_id, ids);
}

std::array<hal::CanFrame, kCaptureResultFrames> encode_capture_result(const CaptureResult& r,
                                                                      std::uint8_t token,
                                                                      std::uint8_t node_id,
                                                                      const IdBases& ids) {
  const MessageDef& m = rsp_def();
  std::array<hal::CanFrame, kCaptureResultFrames> out{};
  std::size_t n = 0;
  for (std::uint8_t c = 0; c < 6; ++c) {
    const ChannelCapture& ch = r.channels[c];
    out[n++] = response_frame(
        kOpStartCapture, token, static_cast<std::uint8_t>(kPartMean + c),
        put_signal(0, signal_of(m, Field::kRspMean, c), static_cast<double>(ch.mean_counts)),
        node_id, ids);
    out[n++] = response_frame(
        kOpStartCapture, token, static_cast<std::uint8_t>(kPartStd + c),
        put_signal(0, signal_of(m, Field::kRspStd, c), static_cast<double>(ch.std_counts)), node_id,
        ids);
    std::uint64_t p = put_signal(0, signal_of(m, Field::kRspCount, c), ch.count);
    p = insert_bits(p, signal_of(m, Field::kRspSaturated, c), ch.saturated ? 1u : 0u);
    p = insert_bits(p, signal_of(m, Field::kRspMotion, c), ch.motion ? 1u : 0u);
    out[n++] = response_frame(kOpStartCapture, token, static_cast<std::uint8_t>(kPartCount + c), p,
                              node_id, ids);
  }
  std::uint64_t p = insert_bits(0, signal_of(m, Field::kRspPose), r.pose);
  p = insert_bits(p, signal_of(m, Field::kRspSamples), r.samples);
  out[n] = response_frame(kOpStartCapture, token, kPartCaptureDone, p, node_id, ids);
  return out;
}

Result<ResponseFrame> decode_response(const hal::CanFrame& f, const IdBases& ids) {
  std::uint8_t node = 0;
  if (f.extended || find_message(f.id, ids, &node) != &rsp_def()) {
    return Status(ErrorCode::kInvalidArgument, "response: not a GfinsResponse identifier");
  }
  if (f.len != kFrameLength) return Status(ErrorCode::kDataLoss, "response: length is not 8");
  if (!crc_ok(f)) return Status(ErrorCode::kDataLoss, "response: CRC-8 mismatch");
  const MessageDef& m = rsp_def();
  const std::uint64_t p = payload_of(f);
  ResponseFrame r;
  r.node_id = node;
  r.opcode = static_cast<std::uint8_t>(extract_bits(p, signal_of(m, Field::kRspOpcode)));
  r.token = static_cast<std::uint8_t>(extract_bits(p, signal_of(m, Field::kRspToken)));
  r.part = static_cast<std::uint8_t>(extract_bits(p, signal_of(m, Field::kRspPart)));
  const std::uint8_t group = r.part & 0xF0u;
  const std::uint8_t ch = r.part & 0x0Fu;
  if (r.part == kPartStatus) {
    r.result = static_cast<ResultCode>(extract_bits(p, signal_of(m, Field::kRspResult)));
    r.value = static_cast<std::uint32_t>(extract_bits(p, signal_of(m, Field::kRspValue)));
  } else if (r.part == kPartCalibrationId) {
    r.cal_id = static_cast<std::uint32_t>(extract_bits(p, signal_of(m, Field::kRspCalId)));
  } else if (r.part == kPartCaptureDone) {
    r.pose = static_cast<std::uint8_t>(extract_bits(p, signal_of(m, Field::kRspPose)));
    r.samples = static_cast<std::uint16_t>(extract_bits(p, signal_of(m, Field::kRspSamples)));
  } else if ((group == kPartMean || group == kPartStd || group == kPartCount) && ch < 6) {
    r.channel = ch;
    if (group == kPartMean) {
      const SignalDef& s = signal_of(m, Field::kRspMean, ch);
      r.mean_counts = decode_signal(s, extract_bits(p, s));
    } else if (group == kPartStd) {
      const SignalDef& s = signal_of(m, Field::kRspStd, ch);
      r.std_counts = decode_signal(s, extract_bits(p, s));
    } else {
      r.count = static_cast<std::uint16_t>(extract_bits(p, signal_of(m, Field::kRspCount, ch)));
      r.saturated = extract_bits(p, signal_of(m, Field::kRspSaturated, ch)) != 0;
      r.motion = extract_bits(p, signal_of(m, Field::kRspMotion, ch)) != 0;
    }
  } else {
    return Status(ErrorCode::kOutOfRange, "response: unknown part");
  }
  return r;
}

void CaptureAssembler::add(const ResponseFrame& r) {
  const std::uint8_t group = r.part & 0xF0u;
  const std::uint8_t c = r.channel;
  if (r.part == kPartCaptureDone) {
    result_.pose = r.pose;
    result_.samples = r.samples;
    done_ = true;
  } else if (group == kPartMean) {
    result_.channels[c].mean_counts = static_cast<float>(r.mean_counts);
    seen_mask_ |= 1u << c;
  } else if (group == kPartStd) {
    result_.channels[c].std_counts = static_cast<float>(r.std_counts);
    seen_mask_ |= 1u << (6 + c);
  } else if (group == kPartCount) {
    result_.channels[c].count = r.count;
    result_.channels[c].saturated = r.saturated;
    result_.channels[c].motion = r.motion;
    seen_mask_ |= 1u << (12 + c);
  }
}

}  // namespace gfins::can
